// SPDX-License-Identifier: MIT
// validate_message: good messages pass; each kind of bad field is named.
#include <gtest/gtest.h>
#include <wingman/common/message_validation.hpp>

#include <cmath>
#include <limits>

namespace {

using wingman::common::validate_message;

wingman::image_t gray_image(int w, int h, int stride) {
  wingman::image_t m{};
  m.utime = 1;
  m.width = w;
  m.height = h;
  m.stride = stride;
  m.pixel_format = wingman::image_t::GRAY8;
  m.data.assign(static_cast<size_t>(stride) * h, 0);
  m.size = static_cast<int32_t>(m.data.size());
  return m;
}

TEST(ValidateImage, AcceptsPaddedStride) { EXPECT_EQ(validate_message(gray_image(10, 4, 16)), ""); }

TEST(ValidateImage, RejectsZeroSizeAndNamesTheField) {
  EXPECT_NE(validate_message(gray_image(0, 4, 16)).find("image_t.width = 0"), std::string::npos);
}

TEST(ValidateImage, RejectsStrideShorterThanARow) {
  auto m = gray_image(10, 4, 16);
  m.pixel_format = wingman::image_t::BGR8;
  EXPECT_NE(validate_message(m).find("image_t.stride = 16: must be >= width * 3 = 30"), std::string::npos)
      << validate_message(m);
}

TEST(ValidateImage, RejectsSizeMismatchAndTruncatedData) {
  auto m = gray_image(10, 4, 16);
  m.data.pop_back();
  EXPECT_NE(validate_message(m).find("image_t.size"), std::string::npos);
  m.size = static_cast<int32_t>(m.data.size());
  EXPECT_NE(validate_message(m).find("must be stride * height"), std::string::npos);
}

TEST(ValidateImage, RejectsImagesAboveTheConfiguredLimit) {
  wingman::common::ImageLimits limits;
  limits.max_width = 8;
  EXPECT_NE(validate_message(gray_image(10, 4, 16), limits).find("must be in 1..8"), std::string::npos);
}

TEST(ValidateImage, RejectsUnknownFormatAndNonJpegMjpeg) {
  auto m = gray_image(10, 4, 16);
  m.pixel_format = 9;
  EXPECT_NE(validate_message(m).find("image_t.pixel_format = 9"), std::string::npos);
  m.pixel_format = wingman::image_t::MJPEG;
  EXPECT_NE(validate_message(m).find("SOI"), std::string::npos);
  m.data[0] = 0xFF;
  m.data[1] = 0xD8;
  EXPECT_EQ(validate_message(m), "");
}

TEST(ValidateDetections, RejectsCountMismatchNonFiniteAndBadConfidence) {
  wingman::detections_t d{};
  d.utime = 1;
  d.image_width = 640;
  d.image_height = 480;
  d.detections.resize(1);
  d.detections[0] = {320, 240, 10, 10, 0.5f, 0, false, 0.5f};
  d.num_detections = 2;
  EXPECT_NE(validate_message(d).find("num_detections = 2"), std::string::npos);
  d.num_detections = 1;
  EXPECT_EQ(validate_message(d), "");
  d.detections[0].cx = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(validate_message(d).find("detections[0]"), std::string::npos);
  d.detections[0].cx = 1;
  d.detections[0].confidence = 1.5f;
  EXPECT_NE(validate_message(d).find("confidence = 1.5"), std::string::npos);
}

TEST(ValidateDetections, RejectsDroneScoreOutsideZeroToOneOrNotFiniteAndNegativeClass) {
  wingman::detections_t d{};
  d.utime = 1;
  d.image_width = 640;
  d.image_height = 480;
  d.detections.resize(2);
  d.detections[0] = {320, 240, 10, 10, 0.5f, 0, false, 0.5f};  // a drone: drone_score = confidence
  d.detections[1] = {100, 100, 10, 10, 0.7f, 2, false, 0.1f};  // a bird (class 2) of a multi-class model
  d.num_detections = 2;
  EXPECT_EQ(validate_message(d), "");
  // The bounds themselves are valid.
  d.detections[1].drone_score = 0.0f;
  EXPECT_EQ(validate_message(d), "");
  d.detections[1].drone_score = 1.0f;
  EXPECT_EQ(validate_message(d), "");
  for (const float bad : {-0.01f, 1.01f, std::numeric_limits<float>::quiet_NaN(),
                          std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()}) {
    d.detections[1].drone_score = bad;
    const std::string why = validate_message(d);
    EXPECT_NE(why.find("detections_t.detections[1].drone_score = "), std::string::npos) << bad << ": " << why;
    EXPECT_NE(why.find("must be a finite number in [0, 1]"), std::string::npos) << bad << ": " << why;
  }
  d.detections[1].drone_score = 0.1f;
  d.detections[1].class_id = -1;
  EXPECT_NE(validate_message(d).find("detections_t.detections[1].class_id = -1: must be >= 0"), std::string::npos)
      << validate_message(d);
  // Any class >= 0 is valid: the consumers decide what a class they do not know means (the localizer: not a drone).
  d.detections[1].class_id = 17;
  EXPECT_EQ(validate_message(d), "");
}

TEST(ValidateOwnPose, RejectsNonUnitQuaternionAndUnknownFrame) {
  wingman::own_pose_t p{};
  p.utime = 1;
  p.q_body_to_world[0] = 1;
  EXPECT_EQ(validate_message(p), "");
  p.q_body_to_world[0] = 2;
  EXPECT_NE(validate_message(p).find("q_body_to_world: norm 2"), std::string::npos);
  p.q_body_to_world[0] = 1;
  p.frame = 5;
  EXPECT_NE(validate_message(p).find("own_pose_t.frame = 5"), std::string::npos);
}

TEST(ValidateOwnPose, ACovarianceMustBeOneOrBeAbsent) {
  wingman::own_pose_t p{};
  p.utime = 1;
  p.q_body_to_world[0] = 1;
  // Absent: both arrays zero.
  p.cov_p_body_in_world[3] = 0.1;
  EXPECT_EQ(validate_message(p), "own_pose_t.cov_p_body_in_world: must be zero when has_covariance is false");
  p.cov_p_body_in_world[3] = 0;
  p.var_rpy_body[2] = 0.1;
  EXPECT_EQ(validate_message(p), "own_pose_t.var_rpy_body: must be zero when has_covariance is false");
  // Present: xx xy xz yy yz zz.
  p.has_covariance = true;
  const double good[6] = {0.25, 0.1, 0.0, 0.16, -0.05, 1.0};
  for (int i = 0; i < 6; ++i) p.cov_p_body_in_world[i] = good[i];
  EXPECT_EQ(validate_message(p), "");
  p.cov_p_body_in_world[1] = 0.21;  // |xy| > sqrt(0.25 * 0.16) = 0.2
  EXPECT_NE(validate_message(p).find("own_pose_t.cov_p_body_in_world[1] = 0.21: a covariance must be within"),
            std::string::npos)
      << validate_message(p);
  p.cov_p_body_in_world[1] = 0.1;
  p.cov_p_body_in_world[5] = -1;
  EXPECT_NE(validate_message(p).find("own_pose_t.cov_p_body_in_world[5] = -1: a variance must be >= 0"),
            std::string::npos)
      << validate_message(p);
  p.cov_p_body_in_world[5] = NAN;
  EXPECT_EQ(validate_message(p), "own_pose_t.cov_p_body_in_world: must be finite");
  p.cov_p_body_in_world[5] = 1;
  p.var_rpy_body[0] = -1e-6;
  EXPECT_NE(validate_message(p).find("own_pose_t.var_rpy_body[0]"), std::string::npos) << validate_message(p);
  p.var_rpy_body[0] = INFINITY;
  EXPECT_EQ(validate_message(p), "own_pose_t.var_rpy_body: must be finite");
}

TEST(ValidateSetpoint, RejectsUnknownMode) {
  wingman::setpoint_t s{};
  s.mode = 7;
  EXPECT_NE(validate_message(s).find("setpoint_t.mode = 7"), std::string::npos);
}

}  // namespace

namespace {

TEST(ValidateSourceFlags, UnknownDetectionSourceIsRejectedInEveryMessageThatCarriesIt) {
  wingman::detections_t d{};
  d.utime = 1;
  d.image_width = 640;
  d.image_height = 480;
  d.source = wingman::detections_t::SOURCE_GROUND_TRUTH;
  EXPECT_EQ(validate_message(d), "");
  d.source = 3;
  EXPECT_NE(validate_message(d).find("detections_t.source = 3"), std::string::npos) << validate_message(d);

  wingman::targets_t t{};
  t.utime = 1;
  t.targets.resize(1);
  t.num_targets = 1;
  EXPECT_EQ(validate_message(t), "");
  t.targets[0].detection_source = -1;
  EXPECT_NE(validate_message(t).find("targets[0].detection_source = -1"), std::string::npos) << validate_message(t);

  wingman::setpoint_t s{};
  s.detection_source = 2;
  EXPECT_NE(validate_message(s).find("setpoint_t.detection_source = 2"), std::string::npos) << validate_message(s);
}

}  // namespace

namespace {

wingman::track_windows_t good_windows() {
  wingman::track_windows_t m{};
  m.utime = 1000;
  m.utime_predicted = 34333;
  m.image_width = 1280;
  m.image_height = 720;
  wingman::track_window_t w{};
  w.cx = 600;
  w.cy = 300;
  w.w = 12;
  w.h = 8;
  w.sigma_px = 3;
  w.range_m = 25;
  w.confidence = 0.7f;
  m.windows = {w};
  m.num_windows = 1;
  return m;
}

}  // namespace

TEST(ValidateTrackWindows, NamesTheFieldOfEveryBadValue) {
  using wingman::common::validate_message;
  EXPECT_EQ(validate_message(good_windows()), "");
  auto m = good_windows();
  m.utime_predicted = 999;
  EXPECT_NE(validate_message(m).find("track_windows_t.utime_predicted = 999"), std::string::npos);
  m = good_windows();
  m.image_width = 0;
  EXPECT_NE(validate_message(m).find("track_windows_t.image_width x image_height = 0x720"), std::string::npos);
  m = good_windows();
  m.num_windows = 2;
  EXPECT_NE(validate_message(m).find("track_windows_t.num_windows = 2"), std::string::npos);
  m = good_windows();
  m.windows[0].vx = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(validate_message(m).find("track_windows_t.windows[0]: every number must be finite"), std::string::npos);
  m = good_windows();
  m.windows[0].w = 0;
  EXPECT_NE(validate_message(m).find("track_windows_t.windows[0]: w = 0"), std::string::npos);
  m = good_windows();
  m.windows[0].sigma_px = -1;
  EXPECT_NE(validate_message(m).find("track_windows_t.windows[0].sigma_px = -1"), std::string::npos);
  m = good_windows();
  m.windows[0].confidence = 1.5f;
  EXPECT_NE(validate_message(m).find("track_windows_t.windows[0].confidence = 1.5"), std::string::npos);
}
