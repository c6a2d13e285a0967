// SPDX-License-Identifier: MIT
// A detected box in image pixels and the convention that separates its coordinates from the calibration's.
#pragma once

#include <Eigen/Core>

namespace wingman::geometry {

/// A detected box in pixels of the source (distorted) image; (0, 0) is the top-left corner of the
/// top-left pixel, as in detections_t.
struct PixelBox {
  double cx = 0;  ///< centre x, pixels
  double cy = 0;  ///< centre y, pixels
  double w = 0;   ///< width, pixels
  double h = 0;   ///< height, pixels
};

/// Offset from PixelBox coordinates (origin at the top-left pixel's corner) to calibration coordinates (origin at
/// the top-left pixel's centre): u_camera = u_box - kBoxToCameraPixel.
inline constexpr double kBoxToCameraPixel = 0.5;

/// Calibration pixel coordinates of a point given in PixelBox coordinates.
inline Eigen::Vector2d pixel_from_box(double u_box, double v_box) {
  return {u_box - kBoxToCameraPixel, v_box - kBoxToCameraPixel};
}

}  // namespace wingman::geometry
