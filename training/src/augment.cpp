// SPDX-License-Identifier: MIT
// Seeded training augmentation on OpenCV images.
#include "wingman/training/augment.hpp"

#include "wingman/training/seeded_random.hpp"

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wingman::training {

AugmentOptions AugmentOptions::none() {
  AugmentOptions o;
  o.hue = 0.0;
  o.saturation = 1.0;
  o.exposure = 1.0;
  o.jitter = 0.0;
  o.flip = 0.0;
  o.scale = 0.0;
  o.translate = 0.0;
  o.blur = 0.0;
  o.noise = 0.0;
  o.mosaic = 0.0;
  return o;
}

std::vector<std::string> AugmentOptions::validate() const {
  std::vector<std::string> p;
  auto range = [&](const char* name, double v, double lo, double hi) {
    if (!(v >= lo && v <= hi)) p.push_back(fmt::format("augment.{} = {}: must be in {}..{}", name, v, lo, hi));
  };
  range("hue", hue, 0.0, 0.5);
  if (!(saturation >= 1.0)) p.push_back(fmt::format("augment.saturation = {}: must be >= 1", saturation));
  if (!(exposure >= 1.0)) p.push_back(fmt::format("augment.exposure = {}: must be >= 1", exposure));
  range("jitter", jitter, 0.0, 0.45);
  range("flip", flip, 0.0, 1.0);
  if (!(scale >= 0.0 && scale <= 10.0)) p.push_back(fmt::format("augment.scale = {}: must be in 0..10", scale));
  range("translate", translate, 0.0, 0.5);
  range("blur", blur, 0.0, 1.0);
  range("noise", noise, 0.0, 1.0);
  range("mosaic", mosaic, 0.0, 1.0);
  range("min_visible", min_visible, 0.0, 1.0);
  return p;
}

namespace {

/// HSV jitter on an 8-bit BGR image, in place (Darknet: hue shift, saturation and value scaled).
void hsv_jitter(cv::Mat& bgr, double dhue, double dsat, double dexp) {
  if (dhue == 0.0 && dsat == 1.0 && dexp == 1.0) return;
  cv::Mat f;
  bgr.convertTo(f, CV_32FC3, 1.0 / 255.0);
  cv::cvtColor(f, f, cv::COLOR_BGR2HSV);  // H in [0, 360), S and V in [0, 1]
  const float shift = static_cast<float>(dhue * 360.0);
  for (int y = 0; y < f.rows; ++y) {
    auto* p = f.ptr<cv::Vec3f>(y);
    for (int x = 0; x < f.cols; ++x) {
      float h = p[x][0] + shift;
      if (h < 0.f) h += 360.f;
      if (h >= 360.f) h -= 360.f;
      p[x][0] = h;
      p[x][1] = std::min(1.f, p[x][1] * static_cast<float>(dsat));
      p[x][2] = std::min(1.f, p[x][2] * static_cast<float>(dexp));
    }
  }
  cv::cvtColor(f, f, cv::COLOR_HSV2BGR);
  f.convertTo(bgr, CV_8UC3, 255.0);
}

}  // namespace

AugmentedImage augment_image(const cv::Mat& bgr, const std::vector<LabeledBox>& boxes, cv::Size out_size,
                             const AugmentOptions& o, uint64_t seed) {
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw std::invalid_argument("augment_image: the image must be a non-empty 8-bit BGR image");
  if (out_size.width < 1 || out_size.height < 1)
    throw std::invalid_argument(
        fmt::format("augment_image: output size {}x{} must be positive", out_size.width, out_size.height));
  SeededRandom rng(seed);
  const double W = bgr.cols, H = bgr.rows;
  // Crop rectangle in source pixels (continuous coordinates, 0 = left edge of the first pixel).
  double x0 = 0, y0 = 0, x1 = W, y1 = H;
  const bool geometric = o.jitter > 0 || o.scale > 0 || o.translate > 0;
  if (o.jitter > 0) {
    const double dw = o.jitter * W, dh = o.jitter * H;
    x0 = rng.uniform(-dw, dw);
    x1 = W - rng.uniform(-dw, dw);
    y0 = rng.uniform(-dh, dh);
    y1 = H - rng.uniform(-dh, dh);
  }
  if (o.scale > 0) {
    const double f = std::exp(rng.uniform(-std::log1p(o.scale), std::log1p(o.scale)));
    const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
    const double hw = 0.5 * (x1 - x0) / f, hh = 0.5 * (y1 - y0) / f;
    x0 = cx - hw, x1 = cx + hw, y0 = cy - hh, y1 = cy + hh;
  }
  if (o.translate > 0) {
    const double tx = rng.uniform(-o.translate, o.translate) * (x1 - x0);
    const double ty = rng.uniform(-o.translate, o.translate) * (y1 - y0);
    x0 += tx, x1 += tx, y0 += ty, y1 += ty;
  }
  const bool flip = o.flip > 0 && rng.chance(o.flip);
  const double ax = out_size.width / (x1 - x0), ay = out_size.height / (y1 - y0);

  AugmentedImage out;
  if (!geometric) {
    cv::resize(bgr, out.bgr, out_size, 0, 0, cv::INTER_LINEAR);  // the detector's stretch
    if (flip) cv::flip(out.bgr, out.bgr, 1);
  } else {
    // Pixel centres: index i sits at continuous i + 0.5, so i' = a (i + 0.5 - x0) - 0.5 (mirrored with flip).
    cv::Matx23d m(ax, 0, ax * (0.5 - x0) - 0.5, 0, ay, ay * (0.5 - y0) - 0.5);
    if (flip) {
      m(0, 0) = -ax;
      m(0, 2) = out_size.width - 0.5 - ax * (0.5 - x0);
    }
    cv::warpAffine(bgr, out.bgr, cv::Mat(m), out_size, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                   cv::Scalar(127, 127, 127));
  }

  for (const LabeledBox& b : boxes) {
    const double bx0 = (b.cx - 0.5 * b.w) * W, bx1 = (b.cx + 0.5 * b.w) * W;
    const double by0 = (b.cy - 0.5 * b.h) * H, by1 = (b.cy + 0.5 * b.h) * H;
    double u0 = (bx0 - x0) * ax, u1 = (bx1 - x0) * ax;
    const double v0 = (by0 - y0) * ay, v1 = (by1 - y0) * ay;
    if (flip) {
      const double f0 = out_size.width - u1, f1 = out_size.width - u0;
      u0 = f0, u1 = f1;
    }
    const double cu0 = std::clamp(u0, 0.0, static_cast<double>(out_size.width));
    const double cu1 = std::clamp(u1, 0.0, static_cast<double>(out_size.width));
    const double cv0 = std::clamp(v0, 0.0, static_cast<double>(out_size.height));
    const double cv1 = std::clamp(v1, 0.0, static_cast<double>(out_size.height));
    const double full = (u1 - u0) * (v1 - v0);
    const double kept = (cu1 - cu0) * (cv1 - cv0);
    if (cu1 - cu0 < 1.0 || cv1 - cv0 < 1.0 || full <= 0 || kept < o.min_visible * full) continue;
    LabeledBox nb;
    nb.cls = b.cls;
    nb.cx = static_cast<float>(0.5 * (cu0 + cu1) / out_size.width);
    nb.cy = static_cast<float>(0.5 * (cv0 + cv1) / out_size.height);
    nb.w = static_cast<float>((cu1 - cu0) / out_size.width);
    nb.h = static_cast<float>((cv1 - cv0) / out_size.height);
    out.boxes.push_back(nb);
  }

  const double dhue = o.hue > 0 ? rng.uniform(-o.hue, o.hue) : 0.0;
  const double dsat = o.saturation > 1 ? rng.scale_factor(o.saturation) : 1.0;
  const double dexp = o.exposure > 1 ? rng.scale_factor(o.exposure) : 1.0;
  hsv_jitter(out.bgr, dhue, dsat, dexp);
  if (o.blur > 0 && rng.chance(o.blur)) {
    const double sigma = rng.uniform(0.3, 1.5);
    cv::GaussianBlur(out.bgr, out.bgr, cv::Size(0, 0), sigma);
  }
  if (o.noise > 0 && rng.chance(o.noise)) {
    const double sigma = rng.uniform(0.0, 8.0);
    for (int y = 0; y < out.bgr.rows; ++y) {
      auto* p = out.bgr.ptr<uchar>(y);
      for (int x = 0; x < out.bgr.cols * 3; ++x) p[x] = cv::saturate_cast<uchar>(p[x] + sigma * rng.normal());
    }
  }
  return out;
}

AugmentedImage augment_mosaic(const std::vector<const cv::Mat*>& images,
                              const std::vector<const std::vector<LabeledBox>*>& boxes, cv::Size out_size,
                              const AugmentOptions& options, uint64_t seed) {
  if (images.size() != 4 || boxes.size() != 4)
    throw std::invalid_argument(
        fmt::format("augment_mosaic: {} images and {} box lists, expected 4 and 4", images.size(), boxes.size()));
  SeededRandom rng(seed);
  const int sx =
      std::clamp(static_cast<int>(std::lround(rng.uniform(0.25, 0.75) * out_size.width)), 1, out_size.width - 1);
  const int sy =
      std::clamp(static_cast<int>(std::lround(rng.uniform(0.25, 0.75) * out_size.height)), 1, out_size.height - 1);
  AugmentedImage out;
  out.bgr.create(out_size, CV_8UC3);
  const cv::Rect quads[4] = {{0, 0, sx, sy},
                             {sx, 0, out_size.width - sx, sy},
                             {0, sy, sx, out_size.height - sy},
                             {sx, sy, out_size.width - sx, out_size.height - sy}};
  for (int k = 0; k < 4; ++k) {
    const cv::Rect& q = quads[k];
    const AugmentedImage part = augment_image(*images[k], *boxes[k], q.size(), options, mix_seed(seed, 1 + k));
    part.bgr.copyTo(out.bgr(q));
    for (const LabeledBox& b : part.boxes) {
      LabeledBox nb = b;
      nb.cx = static_cast<float>((q.x + b.cx * q.width) / out_size.width);
      nb.cy = static_cast<float>((q.y + b.cy * q.height) / out_size.height);
      nb.w = static_cast<float>(b.w * q.width / out_size.width);
      nb.h = static_cast<float>(b.h * q.height / out_size.height);
      out.boxes.push_back(nb);
    }
  }
  return out;
}

void bgr_to_chw(const cv::Mat& bgr, float* chw) {
  const int plane = bgr.rows * bgr.cols;
  constexpr float kScale = 1.0f / 255.0f;  // as detector::to_network_input, so the values are bit-identical
  for (int y = 0; y < bgr.rows; ++y) {
    const uchar* p = bgr.ptr<uchar>(y);
    for (int x = 0; x < bgr.cols; ++x) {
      const int i = y * bgr.cols + x;
      chw[i] = p[3 * x + 2] * kScale;              // R
      chw[plane + i] = p[3 * x + 1] * kScale;      // G
      chw[2 * plane + i] = p[3 * x + 0] * kScale;  // B
    }
  }
}

}  // namespace wingman::training
