// SPDX-License-Identifier: MIT
// The thesis's sphere-model formulas: the direction of eq. 24 and the distances of eq. 27-32 and eq. 33.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>

namespace wingman::localizer {

/// Eq. 24: the unit direction [x, y, 1] / |[x, y, 1]| in the camera optical frame (x right, y down, z forward) of
/// undistorted normalized coordinates (x, y) = ((u - c_x) / f_x, (v - c_y) / f_y) of the rectified box centre.
/// Exact for the sphere's centre only when the sphere is on the optical axis (off-axis the box centre is not the
/// image of the sphere's centre).
inline Eigen::Vector3d thesis_direction(const Eigen::Vector2d& xy_normalized) {
  return Eigen::Vector3d(xy_normalized.x(), xy_normalized.y(), 1.0).normalized();
}

/// Eq. 27-31: half the angle between the unit rays a_l and a_r through the rectified midpoints of the box's left
/// and right edges (or top and bottom): alpha = 1/2 arccos(a_l . a_r), radians. Preconditions: unit vectors.
inline double thesis_half_angle(const Eigen::Vector3d& a_l, const Eigen::Vector3d& a_r) {
  return 0.5 * std::acos(std::clamp(a_l.dot(a_r), -1.0, 1.0));
}

/// Eq. 32: distance in metres from the camera centre to the centre of a sphere of radius `radius_m` whose image
/// spans the half-angle alpha: l = r sin(pi/2 - alpha) (tan alpha + cot alpha), which equals r / sin(alpha).
/// Exact on the optical axis. Precondition: 0 < alpha < pi/2.
inline double thesis_range_eq32(double radius_m, double alpha) {
  return radius_m * std::sin(M_PI / 2 - alpha) * (std::tan(alpha) + 1.0 / std::tan(alpha));
}

/// Eq. 33: the simplified l = r / tan(alpha) that the thesis used by mistake; short by the factor cos(alpha)
/// (under 2% beyond about 3 m for r = 0.29 m). For comparison only. Precondition: 0 < alpha < pi/2.
inline double thesis_range_eq33(double radius_m, double alpha) { return radius_m / std::tan(alpha); }

}  // namespace wingman::localizer
