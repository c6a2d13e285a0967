// SPDX-License-Identifier: MIT
// Calibration files: ROS camera_info, OpenCV FileStorage and Kalibr, real examples, and errors naming file and key.
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <wingman/geometry/calibration.hpp>

#include <opencv2/core.hpp>

#include <sys/stat.h>
#include <fstream>

namespace wingman::geometry {
namespace {

using wingman::testing::TempDir;

std::string write(const TempDir& dir, const std::string& name, const std::string& text) {
  const std::string path = dir.file(name);
  std::ofstream(path) << text;
  return path;
}

/// The message of the CalibrationError that loading `path` throws ("" if none).
std::string load_error(const std::string& path, const std::string& camera = "cam0") {
  try {
    load_calibration(path, camera);
  } catch (const CalibrationError& e) {
    return e.what();
  }
  return "";
}

const char* kRosPlumbBob = R"(image_width: 640
image_height: 480
camera_name: test_cam
camera_matrix:
  rows: 3
  cols: 3
  data: [500.5, 0, 320.25, 0, 501.5, 240.75, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [0.1, -0.2, 0.001, -0.002, 0.05]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
projection_matrix:
  rows: 3
  cols: 4
  data: [510, 0, 320, 0, 0, 510, 240, 0, 0, 0, 1, 0]
)";

TEST(Calibration, ReadsRosCameraInfoPlumbBob) {
  TempDir dir;
  const std::string path = write(dir, "ros.yaml", kRosPlumbBob);
  EXPECT_EQ(detect_calibration_format(path), CalibrationFormat::kRosCameraInfo);
  const CameraModel c = load_calibration(path);
  EXPECT_EQ(c.width(), 640);
  EXPECT_EQ(c.height(), 480);
  EXPECT_EQ(c.fx(), 500.5);  // K, not the projection matrix P
  EXPECT_EQ(c.fy(), 501.5);
  EXPECT_EQ(c.cx(), 320.25);
  EXPECT_EQ(c.cy(), 240.75);
  EXPECT_EQ(c.distortion(), Distortion::kRadTan);
  EXPECT_EQ(c.coefficients(), (std::vector<double>{0.1, -0.2, 0.001, -0.002, 0.05}));
  EXPECT_EQ(c.name(), "test_cam");
}

TEST(Calibration, ReadsRosRationalPolynomialAndEquidistant) {
  TempDir dir;
  std::string rational = kRosPlumbBob;
  rational.replace(rational.find("plumb_bob"), 9, "rational_polynomial");
  rational.replace(rational.find("[0.1, -0.2, 0.001, -0.002, 0.05]"), 32, "[1, 2, 3, 4, 5, 6, 7, 8]");
  const CameraModel r = load_calibration(write(dir, "rational.yaml", rational));
  EXPECT_EQ(r.distortion(), Distortion::kRationalPolynomial);
  EXPECT_EQ(r.coefficients(), (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8}));

  std::string fisheye = kRosPlumbBob;
  fisheye.replace(fisheye.find("plumb_bob"), 9, "equidistant");
  fisheye.replace(fisheye.find("[0.1, -0.2, 0.001, -0.002, 0.05]"), 32, "[-0.02, 0.006, -0.007, 0.0016]");
  const CameraModel f = load_calibration(write(dir, "fisheye.yaml", fisheye));
  EXPECT_EQ(f.distortion(), Distortion::kEquidistant);
  EXPECT_EQ(f.coefficients().size(), 4u);
}

TEST(Calibration, ReadsOpenCvFileStorageWrittenByOpenCv) {
  TempDir dir;
  struct Case {
    std::string name;
    cv::Mat D;
    bool fisheye;
    Distortion expected;
  };
  const std::vector<Case> cases = {
      {"radtan.yaml", (cv::Mat_<double>(1, 5) << 0.1, -0.2, 0.001, 0.002, 0.01), false, Distortion::kRadTan},
      {"radtan_column.yaml", (cv::Mat_<double>(5, 1) << 0.1, -0.2, 0.001, 0.002, 0.01), false, Distortion::kRadTan},
      {"rational.yaml", (cv::Mat_<double>(1, 8) << 0.1, -0.2, 0.001, 0.002, 0.01, 0.3, 0.02, 0.001), false,
       Distortion::kRationalPolynomial},
      {"fisheye.yaml", (cv::Mat_<double>(4, 1) << -0.02, 0.006, -0.007, 0.0016), true, Distortion::kEquidistant},
  };
  for (const Case& c : cases) {
    const std::string path = dir.file(c.name);
    {
      cv::FileStorage fs(path, cv::FileStorage::WRITE);
      fs << "image_width" << 1280 << "image_height" << 720;
      fs << "camera_matrix" << cv::Mat(cv::Matx33d(900, 0, 640.5, 0, 905, 360.5, 0, 0, 1));
      fs << "distortion_coefficients" << c.D;
      if (c.fisheye) fs << "fisheye_model" << 1;
    }
    EXPECT_EQ(detect_calibration_format(path), CalibrationFormat::kOpenCvFileStorage) << c.name;
    const CameraModel m = load_calibration(path);
    EXPECT_EQ(m.width(), 1280) << c.name;
    EXPECT_EQ(m.fy(), 905) << c.name;
    EXPECT_EQ(m.cx(), 640.5) << c.name;
    EXPECT_EQ(m.distortion(), c.expected) << c.name;
    EXPECT_EQ(m.coefficients()[1], c.D.at<double>(1)) << c.name;
  }
}

TEST(Calibration, ReadsHandWrittenOpenCvFileWithImageSizeAndModelName) {
  TempDir dir;
  const std::string path = write(dir, "cv.yaml", R"(%YAML:1.0
---
image_size: [ 720, 540 ]
distortion_model: equidistant
K: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 260.2, 0., 330.1, 0., 260.0, 261.9, 0., 0., 1. ]
D: !!opencv-matrix
   rows: 1
   cols: 4
   dt: d
   data: [ -0.02, 0.006, -0.007, 0.0016 ]
)");
  const CameraModel m = load_calibration(path);
  EXPECT_EQ(m.width(), 720);
  EXPECT_EQ(m.height(), 540);
  EXPECT_EQ(m.distortion(), Distortion::kEquidistant);
  EXPECT_DOUBLE_EQ(m.fx(), 260.2);
}

const char* kKalibr = R"(cam0:
  camera_model: pinhole
  intrinsics: [458.654, 457.296, 367.215, 248.375]
  distortion_model: radtan
  distortion_coeffs: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]
  resolution: [752, 480]
  rostopic: /cam0/image_raw
cam1:
  T_cn_cnm1:
  - [1, 0, 0, 0.11]
  - [0, 1, 0, 0]
  - [0, 0, 1, 0]
  - [0, 0, 0, 1]
  camera_model: pinhole
  intrinsics: [260.3, 260.0, 330.1, 261.9]
  distortion_model: equidistant
  distortion_coeffs: [-0.02, 0.006, -0.007, 0.0016]
  resolution: [720, 540]
)";

TEST(Calibration, ReadsKalibrCamchainByCameraName) {
  TempDir dir;
  const std::string path = write(dir, "camchain.yaml", kKalibr);
  EXPECT_EQ(detect_calibration_format(path), CalibrationFormat::kKalibr);
  const CameraModel c0 = load_calibration(path);
  EXPECT_EQ(c0.width(), 752);
  EXPECT_EQ(c0.distortion(), Distortion::kRadTan);
  EXPECT_EQ(c0.coefficients().size(), 5u);
  EXPECT_EQ(c0.coefficients()[4], 0.0);
  EXPECT_DOUBLE_EQ(c0.cx(), 367.215);
  const CameraModel c1 = load_calibration(path, "cam1");
  EXPECT_EQ(c1.distortion(), Distortion::kEquidistant);
  EXPECT_EQ(c1.height(), 540);
  EXPECT_EQ(c1.name(), "cam1");
}

/// camera.* keys with `calibration` or, when it is "", the ideal pinhole of the other arguments.
CameraModelOptions camera_keys(const std::string& calibration, const std::string& kalibr_camera, int width, int height,
                               double focal_px) {
  CameraModelOptions o;
  o.calibration = calibration;
  o.kalibr_camera = kalibr_camera;
  o.width = width;
  o.height = height;
  o.focal_px = focal_px;
  return o;
}

TEST(MakeCamera, WithoutCalibrationIsTheCentredIdealPinhole) {
  const CameraModel c = make_camera(camera_keys("", "cam0", 1280, 720, 640.0));
  EXPECT_EQ(c.width(), 1280);
  EXPECT_EQ(c.height(), 720);
  EXPECT_EQ(c.fx(), 640.0);
  EXPECT_EQ(c.fy(), 640.0);
  EXPECT_EQ(c.cx(), 639.5);  // pixel centres at integers: the image spans [-0.5, 1279.5]
  EXPECT_EQ(c.cy(), 359.5);
  EXPECT_EQ(c.distortion(), Distortion::kNone);
  EXPECT_EQ(make_camera(CameraModelOptions{}).describe(), c.describe()) << "the defaults are this camera";
  const CameraModel odd = make_camera(camera_keys("", "cam0", 641, 481, 300.0));
  EXPECT_EQ(odd.cx(), 320.0);
  EXPECT_EQ(odd.cy(), 240.0);
  EXPECT_THROW(make_camera(camera_keys("", "cam0", 0, 720, 640.0)), std::invalid_argument);
}

TEST(MakeCamera, WithCalibrationReadsItAndIgnoresThePinholeKeys) {
  TempDir dir;
  const std::string path = write(dir, "camchain.yaml", kKalibr);
  const CameraModel c1 = make_camera(camera_keys(path, "cam1", 1, 1, 1.0));
  EXPECT_EQ(c1.describe(), load_calibration(path, "cam1").describe());
  EXPECT_EQ(c1.name(), "cam1");
  EXPECT_THROW(make_camera(camera_keys(path, "cam7", 1280, 720, 640.0)), CalibrationError);
}

TEST(Calibration, ErrorsNameTheFileTheKeyAndWhatWasExpected) {
  TempDir dir;
  auto ros_with = [&](const std::string& name, const std::string& from, const std::string& to) {
    std::string text = kRosPlumbBob;
    text.replace(text.find(from), from.size(), to);
    return write(dir, name, text);
  };
  struct Expect {
    std::string path, camera, key, expected;
  };
  const std::vector<Expect> cases = {
      {ros_with("short_k.yaml", "0, 0, 1]\ndistortion_model", "0]\ndistortion_model"), "cam0", "'camera_matrix.data'",
       "expected 9 numbers"},
      {ros_with("model.yaml", "plumb_bob", "fov"), "cam0", "'distortion_model'",
       "expected plumb_bob, rational_polynomial or equidistant, got 'fov'"},
      {ros_with("no_width.yaml", "image_width: 640\n", ""), "cam0", "'image_width'", "missing"},
      {ros_with("bad_number.yaml", "500.5", "five hundred"), "cam0", "'camera_matrix.data[0]'", "expected a number"},
      {ros_with("d_count.yaml", "[0.1, -0.2, 0.001, -0.002, 0.05]", "[0.1, -0.2]"), "cam0",
       "'distortion_coefficients.data'", "4 or 5 coefficients"},
      {ros_with("skew.yaml", "[500.5, 0, 320.25", "[500.5, 2, 320.25"), "cam0", "'camera_matrix.data'",
       "expected zero skew"},
      {write(dir, "kalibr.yaml", kKalibr), "camera_front", "'camera_front'", "cameras: cam0, cam1"},
      {write(dir, "kalibr_omni.yaml", std::string(kKalibr).replace(std::string(kKalibr).find("pinhole"), 7, "omni")),
       "cam0", "'cam0.camera_model'", "expected pinhole"},
      {write(dir, "other.yaml", "fps: 30\n"), "cam0", "'(top level)'", "not a calibration file"},
      {write(dir, "broken.yaml", "image_width: [1, 2\n"), "cam0", "not valid YAML", ""},
      {dir.file("absent.yaml"), "cam0", "cannot open", ""},
      // OpenCV FileStorage files (read with yaml-cpp: OpenCV's own parser hung on a fuzzed file).
      {write(dir, "cv_count.yaml",
             "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\nK: !!opencv-matrix\n  rows: 3\n  cols: 3\n"
             "  dt: d\n  data: [500, 0, 320, 0, 500, 240, 0, 0]\nD: [0.1, 0, 0, 0, 0]\n"),
       "cam0", "'K.data'", "expected 3x3 = 9 numbers, got 8"},
      {write(dir, "cv_rows.yaml",
             "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\nK: !!opencv-matrix\n  rows: 100000\n  cols: 3\n"
             "  dt: d\n  data: [500, 0, 320, 0, 500, 240, 0, 0, 1]\nD: [0.1, 0, 0, 0, 0]\n"),
       "cam0", "'K'", "rows and cols in 1..64, got 100000x3"},
      {write(dir, "cv_dt.yaml",
             "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\nK: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n"
             "D: !!opencv-matrix\n  rows: 1\n  cols: 2\n  dt: 2d\n  data: [0.1, 0, 0, 0]\n"),
       "cam0", "'D.dt'", "expected a one-channel element type"},
      {write(dir, "cv_width.yaml",
             "%YAML:1.0\n---\nimage_width: wide\nimage_height: 480\nK: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n"
             "D: [0.1, 0, 0, 0, 0]\n"),
       "cam0", "'image_width'", "expected an integer"},
      {write(dir, "cv_list.yaml", "%YAML:1.0\n---\n- K\n"), "cam0", "'(top level)'", "expected a mapping"},
  };
  for (const Expect& e : cases) {
    const std::string message = load_error(e.path, e.camera);
    EXPECT_NE(message.find(e.path), std::string::npos) << "file not named: " << message;
    EXPECT_NE(message.find(e.key), std::string::npos) << "key not named: " << message;
    EXPECT_NE(message.find(e.expected), std::string::npos) << "expectation not said: " << message;
  }
}

// --- Real calibrations from ../shared/calibrations (skipped when that folder is absent) ---

std::string shared_calibration(const std::string& name) {
  return wingman::testing::source_path("../shared/calibrations/" + name);
}

bool shared_present() {
  struct stat st {};
  return stat(shared_calibration("").c_str(), &st) == 0;
}

#define SKIP_WITHOUT_SHARED()                                                   \
  if (!shared_present())                                                        \
  GTEST_SKIP() << "real calibrations not available: " << shared_calibration("") \
               << " is absent (they live in ../shared next to the repository)"

TEST(RealCalibrations, RaspicamV2BothModesAreReadAndAreDifferentCalibrations) {
  SKIP_WITHOUT_SHARED();
  const CameraModel c720 = load_calibration(shared_calibration("raspicam_v2_1280x720.yaml"));
  const CameraModel c960 = load_calibration(shared_calibration("raspicam_v2_1280x960.yaml"));
  EXPECT_EQ(c720.width(), 1280);
  EXPECT_EQ(c720.height(), 720);
  EXPECT_EQ(c720.distortion(), Distortion::kRadTan);
  EXPECT_DOUBLE_EQ(c720.fx(), 1276.704618338571);
  EXPECT_DOUBLE_EQ(c720.cy(), 379.8318028940378);
  EXPECT_DOUBLE_EQ(c720.coefficients()[0], 0.1465167016954302);
  EXPECT_EQ(c720.name(), "camerav2_1280x720");
  EXPECT_EQ(c960.height(), 960);
  EXPECT_DOUBLE_EQ(c960.fx(), 999.461170663331);
  // Images of the other mode are an error naming both sizes.
  const std::string message = c720.check_image_size(1280, 960);
  EXPECT_NE(message.find("1280x720"), std::string::npos) << message;
  EXPECT_NE(message.find("1280x960"), std::string::npos) << message;
}

TEST(RealCalibrations, FireflyCameraInfoAndKalibrGiveTheSameCamera) {
  SKIP_WITHOUT_SHARED();
  const CameraModel info = load_calibration(shared_calibration("vswarm_firefly_s_720x540_camera_info.yaml"));
  EXPECT_EQ(detect_calibration_format(shared_calibration("vswarm_firefly_s_720x540_kalibr.yaml")),
            CalibrationFormat::kKalibr);
  for (const char* name : {"camera_front", "camera_right", "camera_back", "camera_left"}) {
    const CameraModel kalibr = load_calibration(shared_calibration("vswarm_firefly_s_720x540_kalibr.yaml"), name);
    EXPECT_EQ(kalibr.distortion(), Distortion::kEquidistant) << name;
    EXPECT_EQ(kalibr.width(), info.width()) << name;
    EXPECT_EQ(kalibr.height(), info.height()) << name;
    EXPECT_EQ(kalibr.fx(), info.fx()) << name;
    EXPECT_EQ(kalibr.fy(), info.fy()) << name;
    EXPECT_EQ(kalibr.cx(), info.cx()) << name;
    EXPECT_EQ(kalibr.cy(), info.cy()) << name;
    EXPECT_EQ(kalibr.coefficients(), info.coefficients()) << name;
  }
  EXPECT_EQ(info.distortion(), Distortion::kEquidistant);
  EXPECT_DOUBLE_EQ(info.fx(), 260.2658763809593);
  // The Kalibr file has no cam0: the error lists its cameras.
  const std::string message = load_error(shared_calibration("vswarm_firefly_s_720x540_kalibr.yaml"));
  EXPECT_NE(message.find("camera_front, camera_right, camera_back, camera_left"), std::string::npos) << message;
}

TEST(RealCalibrations, RoundTripAtTheCornersOfEveryRealCalibration) {
  SKIP_WITHOUT_SHARED();
  for (const char* name :
       {"raspicam_v2_1280x720.yaml", "raspicam_v2_1280x960.yaml", "vswarm_firefly_s_720x540_camera_info.yaml"}) {
    const CameraModel c = load_calibration(shared_calibration(name));
    for (double fu : {0.0, 0.25, 0.5, 0.75, 1.0})
      for (double fv : {0.0, 0.25, 0.5, 0.75, 1.0}) {
        const Eigen::Vector2d uv(-0.5 + fu * c.width(), -0.5 + fv * c.height());
        const Eigen::Vector2d xy_d((uv.x() - c.cx()) / c.fx(), (uv.y() - c.cy()) / c.fy());
        if (c.distortion() == Distortion::kEquidistant && xy_d.norm() > 80 * M_PI / 180) continue;  // > 90 degrees
        const Eigen::Vector2d back = c.project(c.unproject(uv));
        EXPECT_NEAR((back - uv).norm(), 0, 1e-7) << name << " at " << uv.transpose();
      }
  }
}

}  // namespace
}  // namespace wingman::geometry
