// SPDX-License-Identifier: MIT
// Augmentation: no-op equals the detector's preprocessing; seeded; boxes follow the pixels through crop, scale,
// translation, flip and mosaic.
#include <wingman/detector/preprocess.hpp>
#include <wingman/training/augment.hpp>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstring>
#include <random>

namespace wingman::training {
namespace {

/// A black image with white rectangles at `boxes` (pixel-aligned), for tracking geometry.
cv::Mat boxes_image(cv::Size size, const std::vector<LabeledBox>& boxes) {
  cv::Mat m(size, CV_8UC3, cv::Scalar(0, 0, 0));
  for (const LabeledBox& b : boxes) {
    const int x0 = static_cast<int>(std::lround((b.cx - b.w / 2) * size.width));
    const int x1 = static_cast<int>(std::lround((b.cx + b.w / 2) * size.width));
    const int y0 = static_cast<int>(std::lround((b.cy - b.h / 2) * size.height));
    const int y1 = static_cast<int>(std::lround((b.cy + b.h / 2) * size.height));
    cv::rectangle(m, cv::Rect(x0, y0, x1 - x0, y1 - y0), cv::Scalar(255, 255, 255), cv::FILLED);
  }
  return m;
}

/// Bounding box (pixels, continuous) of the pixels brighter than the grey fill inside `roi`.
cv::Rect2d bright_box(const cv::Mat& bgr, cv::Rect roi) {
  int x0 = roi.x + roi.width, y0 = roi.y + roi.height, x1 = -1, y1 = -1;
  for (int y = roi.y; y < roi.y + roi.height; ++y)
    for (int x = roi.x; x < roi.x + roi.width; ++x)
      if (bgr.at<cv::Vec3b>(y, x)[0] > 191)
        x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
  if (x1 < 0) return {};
  return {static_cast<double>(x0), static_cast<double>(y0), static_cast<double>(x1 + 1 - x0),
          static_cast<double>(y1 + 1 - y0)};
}

AugmentOptions geometric_only() {
  AugmentOptions o = AugmentOptions::none();
  o.jitter = 0.2;
  o.flip = 0.5;
  o.scale = 0.5;
  o.translate = 0.2;
  return o;
}

TEST(Augment, DefaultsAreTheThesisValuesAndValid) {
  const AugmentOptions o;
  EXPECT_TRUE(o.validate().empty());
  EXPECT_DOUBLE_EQ(o.hue, 0.1);
  EXPECT_DOUBLE_EQ(o.saturation, 1.5);
  EXPECT_DOUBLE_EQ(o.exposure, 1.5);
  EXPECT_DOUBLE_EQ(o.jitter, 0.2);
  EXPECT_DOUBLE_EQ(o.flip, 0.5);
  AugmentOptions bad;
  bad.jitter = 0.6;
  bad.saturation = 0.5;
  const auto p = bad.validate();
  ASSERT_EQ(p.size(), 2u);
  EXPECT_NE(p[0].find("augment.saturation = 0.5"), std::string::npos) << p[0];
  EXPECT_NE(p[1].find("augment.jitter = 0.6"), std::string::npos) << p[1];
}

TEST(Augment, NoneIsExactlyTheDetectorPreprocessing) {
  cv::Mat img(97, 131, CV_8UC3);
  cv::randu(img, cv::Scalar::all(0), cv::Scalar::all(256));
  const cv::Size net(64, 48);
  const std::vector<LabeledBox> boxes = {{0, 0.4f, 0.6f, 0.2f, 0.1f}};
  const AugmentedImage a = augment_image(img, boxes, net, AugmentOptions::none(), 123);
  std::vector<float> ours(3 * net.area()), detector_input(3 * net.area());
  bgr_to_chw(a.bgr, ours.data());
  cv::Mat scratch;
  detector::to_network_input(img, cv::Rect(0, 0, img.cols, img.rows), net, scratch, detector_input.data());
  EXPECT_EQ(std::memcmp(ours.data(), detector_input.data(), ours.size() * sizeof(float)), 0);
  ASSERT_EQ(a.boxes.size(), 1u);
  EXPECT_NEAR(a.boxes[0].cx, 0.4f, 1e-6);
  EXPECT_NEAR(a.boxes[0].h, 0.1f, 1e-6);
}

TEST(Augment, SameSeedSameResultOtherSeedOtherResult) {
  cv::Mat img(60, 80, CV_8UC3);
  cv::randu(img, cv::Scalar::all(0), cv::Scalar::all(256));
  AugmentOptions o;
  o.blur = 0.5;
  o.noise = 0.5;
  o.scale = 0.3;
  const std::vector<LabeledBox> boxes = {{0, 0.5f, 0.5f, 0.3f, 0.3f}};
  const AugmentedImage a = augment_image(img, boxes, {48, 40}, o, 7);
  const AugmentedImage b = augment_image(img, boxes, {48, 40}, o, 7);
  const AugmentedImage c = augment_image(img, boxes, {48, 40}, o, 8);
  EXPECT_EQ(cv::norm(a.bgr, b.bgr, cv::NORM_INF), 0.0);
  ASSERT_EQ(a.boxes.size(), b.boxes.size());
  for (size_t i = 0; i < a.boxes.size(); ++i) EXPECT_EQ(a.boxes[i].cx, b.boxes[i].cx);
  EXPECT_GT(cv::norm(a.bgr, c.bgr, cv::NORM_L1), 0.0);
}

TEST(Augment, BoxesFollowThePixelsOverManySeeds) {
  const cv::Size src(160, 120), out(96, 80);
  int kept = 0, flipped_seen = 0;
  for (uint64_t seed = 1; seed <= 60; ++seed) {
    std::mt19937 rng(static_cast<uint32_t>(seed));
    // One box of 12-40 px somewhere inside the image.
    const float w = (12 + rng() % 29) / static_cast<float>(src.width),
                h = (12 + rng() % 29) / static_cast<float>(src.height);
    const float cx = w / 2 + (rng() % 1000) / 1000.f * (1 - w), cy = h / 2 + (rng() % 1000) / 1000.f * (1 - h);
    const std::vector<LabeledBox> truth = {{0, cx, cy, w, h}};
    const cv::Mat img = boxes_image(src, truth);
    const AugmentedImage a = augment_image(img, truth, out, geometric_only(), seed);
    const cv::Rect2d seen = bright_box(a.bgr, cv::Rect(0, 0, out.width, out.height));
    if (a.boxes.empty()) {
      // Dropped: little of it can be visible (min_visible 0.3 of its area).
      continue;
    }
    ++kept;
    ASSERT_EQ(a.boxes.size(), 1u);
    const LabeledBox& b = a.boxes[0];
    const double bx0 = (b.cx - b.w / 2) * out.width, bx1 = (b.cx + b.w / 2) * out.width;
    const double by0 = (b.cy - b.h / 2) * out.height, by1 = (b.cy + b.h / 2) * out.height;
    EXPECT_NEAR(seen.x, bx0, 1.5) << "seed " << seed;
    EXPECT_NEAR(seen.x + seen.width, bx1, 1.5) << "seed " << seed;
    EXPECT_NEAR(seen.y, by0, 1.5) << "seed " << seed;
    EXPECT_NEAR(seen.y + seen.height, by1, 1.5) << "seed " << seed;
    flipped_seen += std::fabs(b.cx - cx) > 0.2 ? 1 : 0;
  }
  EXPECT_GT(kept, 45);
  EXPECT_GT(flipped_seen, 0);
}

TEST(Augment, MosaicBoxesFollowThePixels) {
  const cv::Size src(100, 80), out(128, 96);
  std::vector<cv::Mat> imgs;
  std::vector<std::vector<LabeledBox>> boxes;
  for (int k = 0; k < 4; ++k) {
    boxes.push_back({{0, 0.3f + 0.1f * k, 0.5f, 0.3f, 0.35f}});
    imgs.push_back(boxes_image(src, boxes.back()));
  }
  std::vector<const cv::Mat*> ip;
  std::vector<const std::vector<LabeledBox>*> bp;
  for (int k = 0; k < 4; ++k) ip.push_back(&imgs[k]), bp.push_back(&boxes[k]);
  AugmentOptions o = AugmentOptions::none();
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    const AugmentedImage a = augment_mosaic(ip, bp, out, o, seed);
    ASSERT_EQ(a.boxes.size(), 4u) << "seed " << seed;
    for (const LabeledBox& b : a.boxes) {
      // The pixels inside each box are bright, around it (a 2 px margin) dark.
      const cv::Rect inner(static_cast<int>(std::ceil((b.cx - b.w / 2) * out.width + 1)),
                           static_cast<int>(std::ceil((b.cy - b.h / 2) * out.height + 1)),
                           static_cast<int>(b.w * out.width) - 3, static_cast<int>(b.h * out.height) - 3);
      ASSERT_GT(inner.area(), 0);
      EXPECT_GT(cv::mean(a.bgr(inner))[0], 250.0) << "seed " << seed;
    }
  }
  EXPECT_THROW(augment_mosaic({ip[0]}, {bp[0]}, out, o, 1), std::invalid_argument);
}

TEST(Augment, PhotometricChangesKeepGeometry) {
  cv::Mat img(50, 70, CV_8UC3, cv::Scalar(200, 120, 40));
  AugmentOptions o = AugmentOptions::none();
  o.hue = 0.1;
  o.saturation = 1.5;
  o.exposure = 1.5;
  const std::vector<LabeledBox> boxes = {{0, 0.5f, 0.5f, 0.2f, 0.2f}};
  int changed = 0;
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    const AugmentedImage a = augment_image(img, boxes, {70, 50}, o, seed);
    ASSERT_EQ(a.boxes.size(), 1u);
    EXPECT_FLOAT_EQ(a.boxes[0].cx, 0.5f);
    changed += cv::norm(a.bgr, img, cv::NORM_INF) > 2 ? 1 : 0;
  }
  EXPECT_EQ(changed, 5);
}

}  // namespace
}  // namespace wingman::training
