// SPDX-License-Identifier: MIT
// Camera rig files: the shipped surround rig, mounts by yaw/pitch against hand-worked axes, every problem at once.
#include <gtest/gtest.h>
#include <wingman/common/config.hpp>
#include <wingman/geometry/camera_rig.hpp>
#include <wingman/geometry/extrinsics.hpp>
#include "test_support.hpp"

#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using wingman::common::ConfigError;
using wingman::geometry::CameraRig;
using wingman::geometry::Extrinsics;
using wingman::geometry::load_camera_rig;

class CameraRigFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("wingman_rig_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  /// The message of the ConfigError load_camera_rig(path) throws ("" when it throws none).
  static std::string error_of(const std::string& path) {
    try {
      load_camera_rig(path);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST(CameraRig, TheShippedSurroundRigLooksAllAround) {
  const CameraRig rig = load_camera_rig(wingman::testing::source_path("config/rigs/surround4.yaml"));
  ASSERT_EQ(rig.cameras.size(), 4u);
  // Optical axes (camera z in body FLU): forward, left, back, right; image down (camera y) is body -z for all.
  const Eigen::Vector3d axes[] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitX(),
                                  -Eigen::Vector3d::UnitY()};
  for (int i = 0; i < 4; ++i) {
    const auto& cam = rig.cameras[static_cast<size_t>(i)];
    EXPECT_EQ(cam.camera.camera_id, i);
    EXPECT_EQ(cam.image_channel, "IMAGE_CAM" + std::to_string(i));
    EXPECT_EQ(cam.detections_channel, "DETECTIONS_CAM" + std::to_string(i));
    EXPECT_EQ(cam.windows_channel, "WINDOWS_CAM" + std::to_string(i));
    const Extrinsics e = Extrinsics::from_options(cam.extrinsics);
    EXPECT_LT((e.R_cam_to_body.col(2) - axes[i]).norm(), 1e-12) << "camera " << i;
    EXPECT_LT((e.R_cam_to_body.col(1) + Eigen::Vector3d::UnitZ()).norm(), 1e-12) << "camera " << i;
    // Each sits 0.1 m out along its axis.
    EXPECT_LT((e.p_cam_in_body - 0.1 * axes[i]).norm(), 1e-12) << "camera " << i;
  }
  EXPECT_EQ(rig.find(2), &rig.cameras[2]);
  EXPECT_EQ(rig.find(7), nullptr);
}

TEST_F(CameraRigFile, PitchTiltsTheOpticalAxisUpAndChannelsAndCalibrationPathsAreRead) {
  write("cam.yaml", "image_width: 640\n");  // only checked to exist here
  const std::string path = write("rig.yaml",
                                 "cameras:\n"
                                 "  - camera: {camera_id: 5, calibration: cam.yaml}\n"
                                 "    mount: {pitch_deg: 30}\n"
                                 "    channels: {image: A, detections: B, windows: C}\n");
  const CameraRig rig = load_camera_rig(path);
  ASSERT_EQ(rig.cameras.size(), 1u);
  const auto& cam = rig.cameras[0];
  EXPECT_EQ(cam.image_channel, "A");
  EXPECT_EQ(cam.detections_channel, "B");
  EXPECT_EQ(cam.windows_channel, "C");
  EXPECT_EQ(fs::path(cam.camera.calibration), dir_ / "cam.yaml");
  const Extrinsics e = Extrinsics::from_options(cam.extrinsics);
  // 30 degrees up from forward: optical axis (cos 30, 0, sin 30) in FLU.
  EXPECT_NEAR(e.R_cam_to_body(0, 2), std::cos(M_PI / 6), 1e-12);
  EXPECT_NEAR(e.R_cam_to_body(1, 2), 0.0, 1e-12);
  EXPECT_NEAR(e.R_cam_to_body(2, 2), std::sin(M_PI / 6), 1e-12);
}

TEST_F(CameraRigFile, EveryProblemIsNamedAtOnceWithItsLineAndKey) {
  const std::string path = write("rig.yaml",
                                 "cameras:\n"
                                 "  - camera: {camera_id: 0, focal_px: -1}\n"  // line 2
                                 "    mount: {yaw_deg: 90}\n"
                                 "    extrinsics: {R_cam_to_body: [1, 0, 0, 0, 1, 0, 0, 0, 1]}\n"  // both
                                 "  - camera: {camera_id: 0, calibration: missing.yaml}\n"  // line 5: dup, missing
                                 "    colour: red\n");                                      // line 6
  const std::string m = error_of(path);
  EXPECT_NE(m.find("rig.yaml:2: cameras[0].camera.focal_px"), std::string::npos) << m;
  EXPECT_NE(m.find("cameras[0].mount.yaw_deg: give the mount either"), std::string::npos) << m;
  EXPECT_NE(m.find("rig.yaml:5: cameras[1].camera.camera_id: 0 is also cameras[0]'s"), std::string::npos) << m;
  EXPECT_NE(m.find("cameras[1].camera.calibration"), std::string::npos) << m;
  EXPECT_NE(m.find("rig.yaml:6: cameras[1].colour: unknown key"), std::string::npos) << m;
  EXPECT_NE(m.find("cameras[1].channels.image: 'IMAGE_CAM0' is also cameras[0].channels.image"), std::string::npos)
      << m;
}

TEST_F(CameraRigFile, AMissingEmptyOrNonListFileIsOneClearError) {
  EXPECT_NE(error_of((dir_ / "nope.yaml").string()).find("nope.yaml: cannot read the camera rig file"),
            std::string::npos);
  EXPECT_NE(error_of(write("a.yaml", "cameras: []\n")).find("cameras: the list is empty"), std::string::npos);
  EXPECT_NE(error_of(write("b.yaml", "cameras: 3\n")).find("cameras: expected a list of mappings"), std::string::npos);
  EXPECT_NE(error_of(write("c.yaml", "other: 1\n")).find("cameras: missing"), std::string::npos);
  EXPECT_NE(error_of(write("d.yaml", "cameras: [\n")).find("not valid YAML"), std::string::npos);
  std::string nine = "cameras:\n";
  for (int i = 0; i < 9; ++i) nine += "  - camera: {camera_id: " + std::to_string(i) + "}\n";
  EXPECT_NE(error_of(write("e.yaml", nine)).find("9 cameras, at most 8"), std::string::npos);
}

}  // namespace
