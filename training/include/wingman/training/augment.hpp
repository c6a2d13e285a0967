// SPDX-License-Identifier: MIT
// Training-time augmentation: crop jitter, scale, translation, flip, HSV jitter, blur, noise, mosaic (seeded).
#pragma once

#include "wingman/training/yolo_dataset.hpp"

#include <opencv2/core.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace wingman::training {

/// What augment_image() does to one image. The defaults are the thesis's (Table 2: r_h 0.1, r_s 1.5,
/// r_v 1.5, r_c 0.2) and Darknet's horizontal flip; the extras (scale, translate, blur, noise, mosaic)
/// default to off. AugmentOptions::none() turns everything off: the result is then exactly the
/// detector's preprocessing (bilinear stretch to the network input).
struct AugmentOptions {
  double hue = 0.1;          ///< r_h: hue shifted by U(-hue, hue) of a full turn, 0..0.5
  double saturation = 1.5;   ///< r_s: saturation times f or 1/f, f ~ U(1, r_s) (Darknet's rand_scale), >= 1
  double exposure = 1.5;     ///< r_v: value (brightness) likewise, >= 1
  double jitter = 0.2;       ///< r_c: each crop edge moves by U(-r_c, r_c) x the image size, 0..0.45
  double flip = 0.5;         ///< probability of a horizontal flip, 0..1
  double scale = 0.0;        ///< extra zoom f, log-uniform in [1/(1+scale), 1+scale] (f < 1: smaller targets), >= 0
  double translate = 0.0;    ///< extra shift of the crop by U(-translate, translate) x its size, 0..0.5
  double blur = 0.0;         ///< probability of a Gaussian blur with sigma ~ U(0.3, 1.5) px, 0..1
  double noise = 0.0;        ///< probability of Gaussian pixel noise with sigma ~ U(0, 8) grey levels, 0..1
  double mosaic = 0.0;       ///< probability that a training sample is a 2 x 2 mosaic of four images, 0..1
  double min_visible = 0.3;  ///< a box cut by the crop is kept when this fraction of its area remains, 0..1

  /// Everything off (the detector's preprocessing).
  static AugmentOptions none();
  /// One "field = value: rule" line per invalid field; empty when valid.
  std::vector<std::string> validate() const;
};

/// One augmented image: BGR 8-bit at the requested size, boxes normalised to it.
struct AugmentedImage {
  cv::Mat bgr;
  std::vector<LabeledBox> boxes;
};

/// Augments one image: a crop (jitter, then scale and translate about its centre; parts outside the image
/// are grey 127) stretched to `out_size` (bilinear), optional flip, HSV jitter, blur, noise. Boxes follow
/// the geometry, are clipped to the output, and dropped when less than min_visible of their area or less than
/// 1 px in width or height remains. Deterministic: the same seed gives the same result.
/// Preconditions: bgr is CV_8UC3 and not empty; options are valid; out_size is positive.
AugmentedImage augment_image(const cv::Mat& bgr, const std::vector<LabeledBox>& boxes, cv::Size out_size,
                             const AugmentOptions& options, uint64_t seed);

/// A 2 x 2 mosaic at `out_size`: the split point is uniform in the middle half of each axis and quadrant k
/// is augment_image(images[k]) at its quadrant's size (so targets come out smaller, as in distant views).
/// Preconditions as augment_image; images.size() == 4 (std::invalid_argument otherwise).
AugmentedImage augment_mosaic(const std::vector<const cv::Mat*>& images,
                              const std::vector<const std::vector<LabeledBox>*>& boxes, cv::Size out_size,
                              const AugmentOptions& options, uint64_t seed);

/// Writes a BGR 8-bit image as the network input: 3 x rows x cols float32 RGB planes scaled to [0, 1]
/// (the detector's layout). chw must have room for 3 * rows * cols floats.
void bgr_to_chw(const cv::Mat& bgr, float* chw);

}  // namespace wingman::training
