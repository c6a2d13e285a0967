// SPDX-License-Identifier: MIT
// Camera rig files: the shipped surround rig, mounts by yaw/pitch against hand-worked axes, mounts from Kalibr
// camchains against the same mounts by yaw/pitch, every problem at once with its file, line and key.
#include <gtest/gtest.h>
#include <wingman/common/config.hpp>
#include <wingman/geometry/calibration.hpp>
#include <wingman/geometry/camera_rig.hpp>
#include <wingman/geometry/extrinsics.hpp>
#include "test_support.hpp"

#include <sys/stat.h>
#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using wingman::common::ConfigError;
using wingman::geometry::CameraRig;
using wingman::geometry::Extrinsics;
using wingman::geometry::load_camera_rig;

/// A fixture of tests/geometry/data (fixed camchains and rigs; their headers say how they were made), as an absolute
/// path: the rig files written in a temporary folder name it.
std::string data_path(const std::string& name) {
  return fs::absolute(wingman::testing::source_path("tests/geometry/data/" + name)).string();
}

/// Checks that two rigs mount their cameras alike, camera by camera: R_cam_to_body and p_cam_in_body to 1e-9 (the
/// camchains print 17 digits; a composed chain of four transforms rounds to ~1e-15).
void expect_same_mounts(const CameraRig& actual, const CameraRig& expected) {
  ASSERT_EQ(actual.cameras.size(), expected.cameras.size());
  for (size_t i = 0; i < actual.cameras.size(); ++i) {
    const Extrinsics a = Extrinsics::from_options(actual.cameras[i].extrinsics);
    const Extrinsics e = Extrinsics::from_options(expected.cameras[i].extrinsics);
    EXPECT_LT((a.R_cam_to_body - e.R_cam_to_body).cwiseAbs().maxCoeff(), 1e-9) << "camera " << i << ":\n"
                                                                               << a.R_cam_to_body << "\nexpected\n"
                                                                               << e.R_cam_to_body;
    EXPECT_LT((a.p_cam_in_body - e.p_cam_in_body).cwiseAbs().maxCoeff(), 1e-9)
        << "camera " << i << ": " << a.p_cam_in_body.transpose() << " expected " << e.p_cam_in_body.transpose();
  }
}

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

// --- Mounts from a Kalibr camchain (camchain.*) ---

TEST(CameraRig, AKalibrImucamChainGivesTheShippedSurroundRigsMountsAndItsIntrinsics) {
  // T_cam_imu of every entry through an IMU turned 30 degrees and upside down (FRD) against the shipped rig's yaws.
  const CameraRig rig = load_camera_rig(data_path("surround4_kalibr_imucam_rig.yaml"));
  expect_same_mounts(rig, load_camera_rig(wingman::testing::source_path("config/rigs/surround4.yaml")));
  EXPECT_EQ(fs::path(rig.camchain), fs::path(data_path("surround4_camchain_imucam.yaml")));
  for (const auto& cam : rig.cameras) {
    const wingman::geometry::CameraModel model = wingman::geometry::make_camera(cam.camera);
    EXPECT_EQ(model.width(), 1280);
    EXPECT_EQ(model.fx(), 640.0);
    EXPECT_EQ(model.name(), cam.camera.kalibr_camera);
  }
}

TEST(CameraRig, ACameraOnlyChainFollowsTcnCnm1FromItsFirstCamerasMount) {
  // Yaw 0/90/180/-90 with pitch 10/-5/20/0 and offsets up and down: the chain against the same mounts by yaw/pitch.
  expect_same_mounts(load_camera_rig(data_path("tilted4_kalibr_rig.yaml")),
                     load_camera_rig(data_path("tilted4_mount_rig.yaml")));
}

TEST_F(CameraRigFile, AnImucamChainReadAlongTcnCnm1GivesTheSameMounts) {
  // The same imucam file, its T_cn_cnm1 this time: cam0's mount given, the IMU's not.
  const std::string chain = data_path("surround4_camchain_imucam.yaml");
  std::string text =
      "camchain:\n  file: " + chain + "\n  mount: {yaw_deg: 0}\n  extrinsics: {p_cam_in_body: [0.1, 0, 0]}\ncameras:\n";
  for (int i = 0; i < 4; ++i)
    text += "  - camera: {camera_id: " + std::to_string(i) + ", calibration: " + chain + ", kalibr_camera: cam" +
            std::to_string(i) + "}\n";
  expect_same_mounts(load_camera_rig(write("rig.yaml", text)),
                     load_camera_rig(wingman::testing::source_path("config/rigs/surround4.yaml")));
}

TEST_F(CameraRigFile, EveryBadTransformOfAnImucamChainIsNamedWithItsFileLineAndKey) {
  write("chain.yaml",
        "cam0:\n"  // 1
        "  T_cam_imu: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n"
        "  rostopic: /cam0/image_raw\n"
        "cam1:\n"                                                                      // 4
        "  T_cam_imu: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]\n"                    // 5: 3 rows
        "cam2:\n"                                                                      // 6
        "  T_cam_imu: [[1, 0, 0, 0], [0, 1, 0, .nan], [0, 0, 1, 0], [0, 0, 0, 1]]\n"   // 7
        "cam3:\n"                                                                      // 8
        "  T_cam_imu: [[1, 0, 0, 0], [0, 1.001, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n"  // 9: not orthonormal
        "cam4:\n"                                                                      // 10
        "  T_cam_imu: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1, 0], [0, 0, 0, 1]]\n"     // 11: a reflection
        "cam5:\n"                                                                      // 12
        "  T_cam_imu: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0.5, 1]]\n"    // 13: last row
        "cam6:\n"                                                                      // 14: no T_cam_imu
        "  T_imu_cam: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n");    // 15: not Kalibr's
  std::string rig = "camchain: {file: chain.yaml}\ncameras:\n";                        // lines 1, 2
  for (int i = 0; i < 8; ++i) {
    // Lines 3, 5, 6, ..., 11; cameras[0] also gives its own mount (line 4); cameras[7] names an absent entry.
    rig += "  - camera: {camera_id: " + std::to_string(i) + ", calibration: chain.yaml, kalibr_camera: cam" +
           std::to_string(i == 7 ? 9 : i) + "}\n";
    if (i == 0) rig += "    mount: {yaw_deg: 90}\n";
  }
  const std::string m = error_of(write("rig.yaml", rig));
  const std::string expected[] = {
      "rig.yaml:4: cameras[0].mount.yaw_deg: this camera's mount comes from the camchain",
      "chain.yaml:5: cam1.T_cam_imu: expected a 4x4 transform: a list of 4 rows, each a list of 4 numbers, got 3 rows",
      "chain.yaml:7: cam2.T_cam_imu: row 1, column 3: expected a finite number, got '.nan'",
      "chain.yaml:9: cam3.T_cam_imu (its rotation block) = '[1, 0, 0, 0, 1.001, 0, 0, 0, 1]': must be orthonormal",
      "chain.yaml:11: cam4.T_cam_imu (its rotation block) = '[1, 0, 0, 0, 1, 0, 0, 0, -1]': must be a rotation "
      "(determinant +1",
      "chain.yaml:13: cam5.T_cam_imu: the last row must be [0, 0, 0, 1] (a rigid transform), got [0, 0, 0.5, 1]",
      "chain.yaml:14: cam6.T_cam_imu: missing: cameras[6] takes its mount from the IMU's",
      "chain.yaml:15: cam6.T_imu_cam: unknown key (Kalibr's camchain keys:",
      "rig.yaml:11: cameras[7].camera.kalibr_camera: 'cam9' is not in the camchain " + (dir_ / "chain.yaml").string() +
          " (its cameras: cam0, cam1, cam2, cam3, cam4, cam5, cam6)",
  };
  for (const std::string& e : expected) EXPECT_NE(m.find(e), std::string::npos) << "expected: " << e << "\nin:\n" << m;
  EXPECT_NE(m.find("rig.yaml: 9 problems in the camera rig:"), std::string::npos) << m;
}

TEST_F(CameraRigFile, ACameraChainMissingATcnCnm1OrOutOfOrderIsNamed) {
  write("chain.yaml",
        "cam0:\n"                                                                     // 1
        "  rostopic: /cam0/image_raw\n"                                               // 2
        "cam1:\n"                                                                     // 3
        "  T_cn_cnm1: [[1, 0, 0, -0.1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n"  // 4
        "cam2:\n"                                                                     // 5: no T_cn_cnm1
        "  rostopic: /cam2/image_raw\n");
  std::string rig = "camchain: {file: chain.yaml, mount: {yaw_deg: 0}}\ncameras:\n";
  for (int i = 0; i < 3; ++i)
    rig += "  - camera: {camera_id: " + std::to_string(i) + ", calibration: chain.yaml, kalibr_camera: cam" +
           std::to_string(i) + "}\n";
  std::string m = error_of(write("rig.yaml", rig));
  EXPECT_NE(m.find("rig.yaml: 1 problem in the camera rig:"), std::string::npos) << m;
  EXPECT_NE(m.find("chain.yaml:5: cam2.T_cn_cnm1: missing: cameras[2] (cam2) takes its mount along the chain from "
                   "cam0 (camchain.mount/extrinsics), each entry's T_cn_cnm1 from the entry before it"),
            std::string::npos)
      << m;

  // The entries out of Kalibr's order: cam<n> must be entry n.
  write("swapped.yaml",
        "cam1:\n  T_cn_cnm1: [[1, 0, 0, -0.1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n"  // 1
        "cam0:\n  rostopic: /cam0/image_raw\n");                                             // 3
  m = error_of(write("swapped_rig.yaml",
                     "camchain: {file: swapped.yaml, mount: {yaw_deg: 0}}\ncameras:\n"
                     "  - camera: {camera_id: 0, calibration: swapped.yaml, kalibr_camera: cam1}\n"));
  EXPECT_NE(m.find("swapped.yaml:1: cam1: is entry 0 of the file (from 0)"), std::string::npos) << m;
  EXPECT_NE(m.find("swapped.yaml:3: cam0: is entry 1 of the file (from 0)"), std::string::npos) << m;
}

TEST_F(CameraRigFile, TheCamchainKeysOwnMistakesAreNamed) {
  // A missing chain file (and so a missing calibration).
  std::string m = error_of(write("a.yaml",
                                 "camchain: {file: nope.yaml}\n"
                                 "cameras:\n"
                                 "  - camera: {camera_id: 0, calibration: nope.yaml}\n"));
  EXPECT_NE(m.find("a.yaml:1: camchain.file: '" + (dir_ / "nope.yaml").string() + "' is not a file"), std::string::npos)
      << m;
  EXPECT_NE(m.find("a.yaml:3: cameras[0].camera.calibration"), std::string::npos) << m;

  write("chain.yaml", "cam0:\n  T_cam_imu: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n");
  // The IMU's mount and the first camera's both; the IMU's rotation not one.
  m = error_of(write("b.yaml",
                     "camchain:\n"
                     "  file: chain.yaml\n"
                     "  R_imu_to_body: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
                     "  mount: {yaw_deg: 10}\n"  // 4
                     "cameras:\n"
                     "  - camera: {camera_id: 0, calibration: chain.yaml}\n"));
  EXPECT_NE(m.find("b.yaml:4: camchain.mount.yaw_deg: give the chain's place on the body either as the IMU's"),
            std::string::npos)
      << m;
  m = error_of(write("c.yaml",
                     "camchain:\n"
                     "  file: chain.yaml\n"
                     "  R_imu_to_body: [1, 0, 0, 0, 1, 0, 0, 0, 2]\n"  // 3
                     "  p_imu_in_body: [0, 0]\n"                       // 4
                     "cameras:\n"
                     "  - camera: {camera_id: 0, calibration: chain.yaml}\n"));
  EXPECT_NE(m.find("c.yaml:3: camchain.R_imu_to_body = '[1, 0, 0, 0, 1, 0, 0, 0, 2]': must be orthonormal"),
            std::string::npos)
      << m;
  EXPECT_NE(m.find("c.yaml:4: camchain.p_imu_in_body = '[0, 0]': must be 3 finite numbers"), std::string::npos) << m;
  // A chain no camera is calibrated by, a camchain that is not a mapping, a Kalibr camera with no calibration.
  m = error_of(write("d.yaml",
                     "camchain: {file: chain.yaml}\n"
                     "cameras:\n"
                     "  - camera: {camera_id: 0, kalibr_camera: cam0}\n"));
  EXPECT_NE(m.find("d.yaml:1: camchain.file: no camera's camera.calibration is this file"), std::string::npos) << m;
  EXPECT_NE(m.find("d.yaml:3: cameras[0].camera.kalibr_camera: names a Kalibr camera, but camera.calibration is "
                   "empty"),
            std::string::npos)
      << m;
  m = error_of(write("e.yaml", "camchain: chain.yaml\ncameras:\n  - camera: {camera_id: 0}\n"));
  EXPECT_NE(m.find("e.yaml:1: camchain: expected a mapping"), std::string::npos) << m;
}

// --- The real Kalibr file of ../shared/calibrations (skipped when that folder is absent) ---

TEST_F(CameraRigFile, TheVswarmKalibrFileGivesIntrinsicsButIsNoCameraChain) {
  const std::string kalibr =
      fs::absolute(wingman::testing::source_path("../shared/calibrations/vswarm_firefly_s_720x540_kalibr.yaml"))
          .lexically_normal()
          .string();
  struct stat st {};
  if (stat(kalibr.c_str(), &st) != 0)
    GTEST_SKIP() << "real calibrations not available: " << kalibr
                 << " is absent (they live in ../shared next to the repository)";
  // In the file's order, mounted as config/rigs/surround4.yaml's cameras look.
  const char* names[] = {"camera_front", "camera_right", "camera_back", "camera_left"};
  const int yaws[] = {0, -90, 180, 90};
  std::string cameras = "cameras:\n";
  for (int i = 0; i < 4; ++i)
    cameras += "  - camera: {camera_id: " + std::to_string(i) + ", calibration: " + kalibr +
               ", kalibr_camera: " + names[i] + "}\n    mount: {yaw_deg: " + std::to_string(yaws[i]) + "}\n";
  // Its four cameras' intrinsics, with mounts by yaw: loads as before.
  const CameraRig rig = load_camera_rig(write("intrinsics.yaml", cameras));
  ASSERT_EQ(rig.cameras.size(), 4u);
  for (const auto& cam : rig.cameras) {
    const wingman::geometry::CameraModel model = wingman::geometry::make_camera(cam.camera);
    EXPECT_EQ(model.width(), 720);
    EXPECT_DOUBLE_EQ(model.fx(), 260.2658763809593);
  }
  // As a camera chain (its first entry, camera_front, mounted): no extrinsics in it.
  std::string chained = "camchain:\n  file: " + kalibr + "\n  mount: {yaw_deg: 0}\ncameras:\n";
  for (int i = 0; i < 4; ++i)
    chained += "  - camera: {camera_id: " + std::to_string(i) + ", calibration: " + kalibr +
               ", kalibr_camera: " + names[i] + "}\n";
  std::string m = error_of(write("chained.yaml", chained));
  EXPECT_NE(m.find(kalibr + ":20: camera_right.T_cn_cnm1: missing: cameras[1] (camera_right) takes its mount along "
                            "the chain from camera_front"),
            std::string::npos)
      << m;
  // As an imucam chain (no first camera's mount): no T_cam_imu either.
  m = error_of(write("imu.yaml", "camchain: {file: " + kalibr +
                                     "}\ncameras:\n  - camera: {camera_id: 0, calibration: " + kalibr +
                                     ", kalibr_camera: camera_front}\n"));
  EXPECT_NE(m.find(kalibr + ":3: camera_front.T_cam_imu: missing: cameras[0] takes its mount from the IMU's"),
            std::string::npos)
      << m;
}

}  // namespace
