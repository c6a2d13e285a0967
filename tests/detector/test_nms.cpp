// SPDX-License-Identifier: MIT
// IoU, clipping to the image and non-maximum suppression (Algorithm 1) on hand-computed cases.
#include <wingman/detector/nms.hpp>

#include <gtest/gtest.h>

namespace wingman::detector {
namespace {

Box nms_box(float cx, float cy, float w, float h, float conf) { return Box{cx, cy, w, h, conf, Pass::kSingle}; }

TEST(Iou, HandCases) {
  EXPECT_FLOAT_EQ(iou(nms_box(5, 5, 10, 10, 1), nms_box(5, 5, 10, 10, 1)), 1.0f);
  // Shifted by half a width: intersection 5 x 10 = 50, union 150.
  EXPECT_FLOAT_EQ(iou(nms_box(5, 5, 10, 10, 1), nms_box(10, 5, 10, 10, 1)), 50.0f / 150.0f);
  EXPECT_FLOAT_EQ(iou(nms_box(0, 0, 2, 2, 1), nms_box(2, 0, 2, 2, 1)), 0.0f);  // touching edges
  EXPECT_FLOAT_EQ(iou(nms_box(0, 0, 0, 0, 1), nms_box(0, 0, 0, 0, 1)), 0.0f);  // empty
}

/// Expects `b` to be (cx, cy, w, h) with confidence `conf`.
void expect_box(const Box& b, float cx, float cy, float w, float h, float conf) {
  EXPECT_FLOAT_EQ(b.cx, cx);
  EXPECT_FLOAT_EQ(b.cy, cy);
  EXPECT_FLOAT_EQ(b.w, w);
  EXPECT_FLOAT_EQ(b.h, h);
  EXPECT_FLOAT_EQ(b.confidence, conf);
}

TEST(ClipToImage, KeepsTheVisiblePart) {
  // Inside: unchanged.
  expect_box(clip_to_image(nms_box(50, 40, 20, 10, 0.7f), 100, 80), 50, 40, 20, 10, 0.7f);
  // Past the left and bottom edges: x -10..30 -> 0..30, y 60..100 -> 60..80.
  expect_box(clip_to_image(nms_box(10, 80, 40, 40, 0.5f), 100, 80), 15, 70, 30, 20, 0.5f);
  // Taller than the image on both sides.
  expect_box(clip_to_image(nms_box(50, 40, 10, 200, 1), 100, 80), 50, 40, 10, 80, 1);
  // Wholly outside: empty.
  EXPECT_FLOAT_EQ(clip_to_image(nms_box(150, 40, 10, 10, 1), 100, 80).w, 0.0f);
  // A list: each clipped, in order, the one outside left out.
  const std::vector<Box> list = clip_to_image(
      {nms_box(10, 80, 40, 40, 0.5f), nms_box(150, 40, 10, 10, 0.9f), nms_box(50, 40, 20, 10, 0.7f)}, 100, 80);
  ASSERT_EQ(list.size(), 2u);
  expect_box(list[0], 15, 70, 30, 20, 0.5f);
  expect_box(list[1], 50, 40, 20, 10, 0.7f);
}

TEST(Nms, KeepsMostConfidentAndSortsDescending) {
  std::vector<Box> b = {nms_box(10, 10, 10, 10, 0.5f), nms_box(12, 10, 10, 10, 0.9f), nms_box(100, 100, 8, 8, 0.7f),
                        nms_box(11, 11, 10, 10, 0.3f)};
  non_max_suppression(b, 0.2f);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_FLOAT_EQ(b[0].confidence, 0.9f);
  EXPECT_FLOAT_EQ(b[1].confidence, 0.7f);
}

TEST(Nms, SuppressesOnlyAboveThreshold) {
  // IoU of these two is exactly 1/3.
  std::vector<Box> b = {nms_box(5, 5, 10, 10, 0.4f), nms_box(10, 5, 10, 10, 0.6f)};
  non_max_suppression(b, 1.0f / 3.0f + 1e-4f);
  EXPECT_EQ(b.size(), 2u);
  non_max_suppression(b, 0.3f);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_FLOAT_EQ(b[0].confidence, 0.6f);
}

TEST(Nms, ASuppressedBoxDoesNotSuppressOthers) {
  // A (0.9) suppresses B (0.8); B would suppress C (0.7), but B is gone, and C does not overlap A enough.
  std::vector<Box> b = {nms_box(0, 0, 10, 10, 0.9f), nms_box(6, 0, 10, 10, 0.8f), nms_box(12, 0, 10, 10, 0.7f)};
  non_max_suppression(b, 0.2f);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_FLOAT_EQ(b[0].confidence, 0.9f);
  EXPECT_FLOAT_EQ(b[1].confidence, 0.7f);
}

TEST(Nms, EmptyInput) {
  std::vector<Box> b;
  non_max_suppression(b, 0.2f);
  EXPECT_TRUE(b.empty());
}

}  // namespace
}  // namespace wingman::detector
