// SPDX-License-Identifier: MIT
// Tightening a loose box around a drone seen against the sky: segment it from a background fitted on the box border.
#pragma once

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace wingman::training {

/// How tighten_box() segments.
struct TightenOptions {
  double border_fraction = 0.15;  ///< the background is fitted on the box's outer band this wide (of w and h), 0..0.4
  double outside_px = 3.0;        ///< plus this many pixels outside the box, >= 0
  double k_sigma = 4.0;           ///< a pixel is foreground when |gray - background| > k_sigma * sigma, > 0
  double min_contrast = 12.0;     ///< ... and > this many grey levels (0..255), >= 0
  double max_band_foreground = 0.08;  ///< fail when more of the background band than this is foreground, 0..1
  double max_fill = 0.85;             ///< fail when the object fills more of the box than this (already tight), 0..1
  double merge_fraction = 0.15;       ///< merge blobs this close to the main one (fraction of max(w, h)), >= 0
  int min_size_px = 2;                ///< fail when the tight box is smaller than this in width or height, >= 1

  /// One "field = value: rule" line per invalid field; empty when valid.
  std::vector<std::string> validate() const;
};

/// The result of tighten_box().
struct TightenResult {
  bool tightened = false;  ///< false: `box` is the original, and `reason` says why
  cv::Rect2d box;          ///< the tight box (or the original), pixels, continuous coordinates
  std::string reason;      ///< why it failed ("" when tightened)
};

/// Tightens `loose` (pixels; x, y the top-left corner in continuous coordinates, 0 = the image's left edge)
/// around the object in it, assuming a smooth background (sky): fits a plane a + b x + c y to the grey levels
/// of the box's outer band (and a few pixels outside), marks pixels inside the box that differ from it by more
/// than k_sigma robust standard deviations (MAD) and min_contrast, closes small gaps, takes the largest blob
/// whose centre lies in the box's middle half plus blobs near it, and returns their bounding box.
/// Fails (returning the original box) when the box is too small to have a band, no blob is found, the band is
/// not background-like (too much of it is foreground: clutter, treeline), the blob touches two or more sides of
/// the box, fills it, or is smaller than min_size_px. Deterministic; bgr is CV_8UC3.
TightenResult tighten_box(const cv::Mat& bgr, const cv::Rect2d& loose, const TightenOptions& options = {});

}  // namespace wingman::training
