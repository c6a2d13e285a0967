// SPDX-License-Identifier: MIT
// The lens map: undistorted normalized coordinates of every pixel corner of a calibrated camera.
#include "lens_map.hpp"

#include <Eigen/LU>

#include <cmath>
#include <limits>

namespace wingman::sim::detail {
namespace {

constexpr double kToleranceNormalized = 1e-11;  // Newton's stopping residual, normalized units (~1e-8 px)
constexpr double kMaxReprojectionPx = 1e-6;

// Solves distort_normalized(xy) = target from `xy`; true on convergence.
bool newton(const geometry::CameraModel& camera, const Eigen::Vector2d& target, Eigen::Vector2d& xy) {
  constexpr double h = 1e-7;
  for (int iteration = 0; iteration < 20; ++iteration) {
    const Eigen::Vector2d f = camera.distort_normalized(xy);
    const Eigen::Vector2d r = f - target;
    if (!r.allFinite()) return false;
    if (r.norm() < kToleranceNormalized) return true;
    Eigen::Matrix2d J;
    J.col(0) = (camera.distort_normalized(xy + Eigen::Vector2d(h, 0.0)) - f) / h;
    J.col(1) = (camera.distort_normalized(xy + Eigen::Vector2d(0.0, h)) - f) / h;
    const double det = J.determinant();
    if (!(std::abs(det) > 1e-12)) return false;
    xy -= J.inverse() * r;
  }
  return false;
}

}  // namespace

LensMap compute_lens_map(const geometry::CameraModel& camera, const TruthBoxProjector& field_of_view) {
  LensMap map;
  map.width = camera.width();
  map.height = camera.height();
  const int cols = map.width + 1, rows = map.height + 1;
  const Eigen::Vector2d nan = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  map.corners.assign(static_cast<size_t>(cols) * rows, nan);
  map.min = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  map.max = -map.min;

  const bool distorted = camera.distortion() != geometry::Distortion::kNone;
  Eigen::Vector2d row_start = Eigen::Vector2d::Zero();
  bool have_row_start = false;
  for (int j = 0; j < rows; ++j) {
    Eigen::Vector2d guess = row_start;
    bool have_guess = have_row_start;
    bool first_in_row = true;
    for (int i = 0; i < cols; ++i) {
      const Eigen::Vector2d uv(i - geometry::kBoxToCameraPixel, j - geometry::kBoxToCameraPixel);
      const Eigen::Vector2d target((uv.x() - camera.cx()) / camera.fx(), (uv.y() - camera.cy()) / camera.fy());
      Eigen::Vector2d xy = target;
      bool ok = true;
      if (distorted) {
        xy = have_guess ? guess : target;
        ok = newton(camera, target, xy) && field_of_view.in_field_of_view(Eigen::Vector3d(xy.x(), xy.y(), 1.0));
        if (!ok) {  // no convergence, or a root where the lens folds: ask OpenCV (plus its polish)
          xy = camera.undistort_to_normalized(uv);
          ok = xy.allFinite() && field_of_view.in_field_of_view(Eigen::Vector3d(xy.x(), xy.y(), 1.0)) &&
               (camera.project(Eigen::Vector3d(xy.x(), xy.y(), 1.0)) - uv).norm() < kMaxReprojectionPx;
        }
      } else {
        ok = field_of_view.in_field_of_view(Eigen::Vector3d(xy.x(), xy.y(), 1.0));
      }
      if (!ok) {
        have_guess = false;
        continue;
      }
      map.corners[static_cast<size_t>(j) * cols + i] = xy;
      map.min = map.min.cwiseMin(xy);
      map.max = map.max.cwiseMax(xy);
      ++map.valid;
      guess = xy;
      have_guess = true;
      if (first_in_row) {  // the next row starts from here
        row_start = xy;
        have_row_start = true;
        first_in_row = false;
      }
    }
  }
  return map;
}

}  // namespace wingman::sim::detail
