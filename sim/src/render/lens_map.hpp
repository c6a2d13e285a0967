// SPDX-License-Identifier: MIT
// The lens map: undistorted normalized coordinates of every pixel corner of a calibrated camera.
#pragma once

#include "wingman/sim/truth_box.hpp"

#include <wingman/geometry/camera_model.hpp>

#include <Eigen/Core>

#include <vector>

namespace wingman::sim::detail {

/// For every pixel corner (i, j), i in 0..width, j in 0..height (box coordinates: the corner of pixel (i, j) is at
/// calibration coordinates (i - 0.5, j - 0.5)), the undistorted normalized coordinates (x, y) of its ray, or NaN
/// where the ray is outside the field of view (TruthBoxProjector::in_field_of_view) or the lens cannot be
/// inverted there.
struct LensMap {
  int width = 0;                                  ///< camera width, pixels (the map has width + 1 columns)
  int height = 0;                                 ///< camera height, pixels (height + 1 rows)
  std::vector<Eigen::Vector2d> corners;           ///< row-major, (width + 1) * (height + 1)
  Eigen::Vector2d min = Eigen::Vector2d::Zero();  ///< smallest valid x, y
  Eigen::Vector2d max = Eigen::Vector2d::Zero();  ///< largest valid x, y
  size_t valid = 0;                               ///< number of valid corners
};

/// Computes the map: Newton's method on CameraModel::distort_normalized, warm-started from the neighbouring corner,
/// falling back to CameraModel::undistort_to_normalized; every kept corner re-projects to within 1e-6 px.
LensMap compute_lens_map(const geometry::CameraModel& camera, const TruthBoxProjector& field_of_view);

}  // namespace wingman::sim::detail
