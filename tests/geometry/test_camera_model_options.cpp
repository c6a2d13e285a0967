// SPDX-License-Identifier: MIT
// CameraModelOptions: the camera.* keys the localizer and the simulator share (their documented defaults, the keys
// visit() names, validate()'s lines); that both processes read them alike: tests/sim/test_sim_camera_options.cpp.
#include <gtest/gtest.h>
#include <wingman/geometry/camera_model_options.hpp>

#include <limits>
#include <string>
#include <vector>

namespace {

using wingman::geometry::CameraModelOptions;

/// The keys visit() names, in order.
struct KeyList {
  std::vector<std::string> keys;
  template <class T>
  void operator()(const std::string& key, T& /*value*/, const std::string& /*description*/) {
    keys.push_back(key);
  }
};

/// Whether one of `lines` is exactly `line`.
bool has_line(const std::vector<std::string>& lines, const std::string& line) {
  for (const auto& l : lines)
    if (l == line) return true;
  return false;
}

TEST(CameraModelOptions, DefaultsAreTheDocumentedIdealPinholeAndValid) {
  const CameraModelOptions o;
  EXPECT_EQ(o.calibration, "");
  EXPECT_EQ(o.kalibr_camera, "cam0");
  EXPECT_EQ(o.camera_id, 0);
  EXPECT_EQ(o.width, 1280);
  EXPECT_EQ(o.height, 720);
  EXPECT_EQ(o.focal_px, 640.0);
  EXPECT_TRUE(o.validate().empty());
}

TEST(CameraModelOptions, VisitNamesTheSixSharedKeysInOrder) {
  CameraModelOptions o;
  KeyList list;
  o.visit(list);
  EXPECT_EQ(list.keys, (std::vector<std::string>{"camera.calibration", "camera.kalibr_camera", "camera.camera_id",
                                                 "camera.width", "camera.height", "camera.focal_px"}));
}

TEST(CameraModelOptions, EachProblemIsOneLineNamingTheKeyTheValueAndTheRule) {
  CameraModelOptions o;
  o.kalibr_camera = "";
  o.camera_id = -1;
  o.width = 0;
  o.height = 16385;
  o.focal_px = -2.5;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 5u) << ::testing::PrintToString(p);
  EXPECT_TRUE(has_line(p, "camera.kalibr_camera = '': must not be empty")) << ::testing::PrintToString(p);
  EXPECT_TRUE(has_line(p, "camera.camera_id = -1: must be >= 0")) << ::testing::PrintToString(p);
  EXPECT_TRUE(has_line(p, "camera.width = 0: must be in 1..16384")) << ::testing::PrintToString(p);
  EXPECT_TRUE(has_line(p, "camera.height = 16385: must be in 1..16384")) << ::testing::PrintToString(p);
  EXPECT_TRUE(has_line(p, "camera.focal_px = -2.5: must be finite and > 0")) << ::testing::PrintToString(p);
}

TEST(CameraModelOptions, FocalLengthMustBeFinite) {
  for (const double f : {0.0, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    CameraModelOptions o;
    o.focal_px = f;
    const auto p = o.validate();
    ASSERT_EQ(p.size(), 1u) << f;
    EXPECT_EQ(p[0].rfind("camera.focal_px = ", 0), 0u) << p[0];
  }
}

TEST(CameraModelOptions, SidesAreBoundedByTheLimitsGivenInclusive) {
  CameraModelOptions o;
  o.width = CameraModelOptions::kMaxSidePx;
  o.height = CameraModelOptions::kMaxSidePx;
  EXPECT_TRUE(o.validate().empty());
  const auto p = o.validate(8192, 4096);
  ASSERT_EQ(p.size(), 2u) << ::testing::PrintToString(p);
  EXPECT_EQ(p[0], "camera.width = 16384: must be in 1..8192");
  EXPECT_EQ(p[1], "camera.height = 16384: must be in 1..4096");
  o.width = 8192;
  o.height = 4096;
  EXPECT_TRUE(o.validate(8192, 4096).empty());
}

}  // namespace
