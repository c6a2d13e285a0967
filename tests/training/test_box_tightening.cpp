// SPDX-License-Identifier: MIT
// Box tightening: a small dark drone on a sky gradient inside a loose box; clutter keeps the original.
#include <wingman/training/box_tightening.hpp>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <random>

namespace wingman::training {
namespace {

/// A 200 x 160 sky: a vertical and horizontal brightness gradient with seeded noise (sigma ~2 grey levels).
cv::Mat sky(uint32_t seed) {
  cv::Mat m(160, 200, CV_8UC3);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 2.0);
  for (int y = 0; y < m.rows; ++y)
    for (int x = 0; x < m.cols; ++x) {
      const double v = 150 + 0.3 * y + 0.1 * x + noise(rng);
      m.at<cv::Vec3b>(y, x) =
          cv::Vec3b(cv::saturate_cast<uchar>(v + 30), cv::saturate_cast<uchar>(v + 10), cv::saturate_cast<uchar>(v));
    }
  return m;
}

/// A quadcopter-like dark shape: a body and four arms with rotor blobs, inside `r`.
void draw_drone(cv::Mat& m, cv::Rect r) {
  const cv::Scalar dark(40, 40, 45);
  const cv::Point c(r.x + r.width / 2, r.y + r.height / 2);
  cv::rectangle(m, cv::Rect(c.x - r.width / 6, c.y - r.height / 6, r.width / 3, r.height / 3), dark, cv::FILLED);
  cv::line(m, {r.x + 1, r.y + 1}, {r.x + r.width - 2, r.y + r.height - 2}, dark, 1);
  cv::line(m, {r.x + r.width - 2, r.y + 1}, {r.x + 1, r.y + r.height - 2}, dark, 1);
  for (const cv::Point p : {cv::Point(r.x + 1, r.y + 1), cv::Point(r.x + r.width - 2, r.y + 1),
                            cv::Point(r.x + 1, r.y + r.height - 2), cv::Point(r.x + r.width - 2, r.y + r.height - 2)})
    cv::circle(m, p, 1, dark, cv::FILLED);
}

TEST(TightenBox, DefaultsAreValid) { EXPECT_TRUE(TightenOptions{}.validate().empty()); }

TEST(TightenBox, FindsASmallDroneInALooseBox) {
  for (uint32_t seed = 1; seed <= 5; ++seed) {
    cv::Mat img = sky(seed);
    const cv::Rect drone(90 + static_cast<int>(seed), 70, 14, 8);
    draw_drone(img, drone);
    // The labelled box: ~2.5x the drone, off-centre by a few pixels (as the Halmstad labels).
    const cv::Rect2d loose(drone.x - 10.5, drone.y - 5.5, 36, 20);
    const TightenResult r = tighten_box(img, loose);
    ASSERT_TRUE(r.tightened) << "seed " << seed << ": " << r.reason;
    EXPECT_NEAR(r.box.x, drone.x, 1.0) << "seed " << seed;
    EXPECT_NEAR(r.box.y, drone.y, 1.0) << "seed " << seed;
    EXPECT_NEAR(r.box.width, drone.width, 2.0) << "seed " << seed;
    EXPECT_NEAR(r.box.height, drone.height, 2.0) << "seed " << seed;
    EXPECT_TRUE(r.reason.empty());
  }
}

TEST(TightenBox, ClutterAtTheEdgeKeepsTheOriginal) {
  cv::Mat img = sky(3);
  // A treeline crossing the box's lower part.
  for (int x = 0; x < img.cols; x += 3) cv::line(img, {x, 95}, {x + 2, 80 + (x * 7) % 12}, cv::Scalar(20, 60, 30), 2);
  draw_drone(img, cv::Rect(95, 70, 14, 8));
  const cv::Rect2d loose(85, 62, 34, 24);
  const TightenResult r = tighten_box(img, loose);
  EXPECT_FALSE(r.tightened);
  EXPECT_EQ(r.box, loose);
  EXPECT_FALSE(r.reason.empty());
}

TEST(TightenBox, EmptySkyOrTinyBoxKeepsTheOriginal) {
  const cv::Mat img = sky(4);
  const TightenResult empty = tighten_box(img, cv::Rect2d(50, 50, 30, 20));
  EXPECT_FALSE(empty.tightened);
  EXPECT_NE(empty.reason.find("no object"), std::string::npos) << empty.reason;
  const TightenResult tiny = tighten_box(img, cv::Rect2d(50, 50, 4, 4));
  EXPECT_FALSE(tiny.tightened);
  EXPECT_NE(tiny.reason.find("too small"), std::string::npos) << tiny.reason;
}

TEST(TightenBox, AlreadyTightBoxIsKept) {
  cv::Mat img = sky(5);
  cv::rectangle(img, cv::Rect(60, 60, 20, 14), cv::Scalar(30, 30, 30), cv::FILLED);
  const TightenResult r = tighten_box(img, cv::Rect2d(59, 59, 22, 16));
  EXPECT_FALSE(r.tightened);
}

}  // namespace
}  // namespace wingman::training
