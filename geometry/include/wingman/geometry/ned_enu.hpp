// SPDX-License-Identifier: MIT
// The one place of the NED/FRD <-> ENU/FLU conversions (autopilots speak NED with an FRD body; Wingman computes in ENU
// with an FLU body: docs/localization.md).
#pragma once

#include "wingman/geometry/angles.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>

namespace wingman::geometry {

/// NED <-> ENU for a vector or point: (x, y, z) -> (y, x, -z). The map is its own inverse.
inline Eigen::Vector3d swap_ned_enu(const Eigen::Vector3d& v) { return {v.y(), v.x(), -v.z()}; }

/// A 3x3 covariance of a world-frame vector between the conventions: S C S^T with S the NED<->ENU axis swap
/// (x and y exchanged, z negated), so the variances of x and y exchange and the covariances with z change sign.
inline Eigen::Matrix3d swap_ned_enu_covariance(const Eigen::Matrix3d& C) {
  Eigen::Matrix3d S;
  S << 0, 1, 0,  //
      1, 0, 0,   //
      0, 0, -1;
  return S * C * S.transpose();
}

/// Heading in NED (from north, clockwise) of an ENU heading (from east, counter-clockwise), and back:
/// yaw_ned = pi/2 - yaw_enu, wrapped (wrap_pi, angles.hpp). Its own inverse. A yaw *rate* changes sign only.
inline double swap_ned_enu_yaw(double yaw_rad) { return wrap_pi(0.5 * M_PI - yaw_rad); }

/// A body-to-world rotation between the conventions: R_flu_to_enu = R_ned_to_enu R_frd_to_ned R_flu_to_frd from an
/// FRD-body-to-NED rotation, and the same formula back (both outer factors are their own inverses).
inline Eigen::Matrix3d swap_ned_frd_enu_flu(const Eigen::Matrix3d& R_body_to_world) {
  Eigen::Matrix3d R_ned_to_enu;
  R_ned_to_enu << 0, 1, 0,  //
      1, 0, 0,              //
      0, 0, -1;
  const Eigen::Matrix3d R_flu_to_frd = Eigen::Vector3d(1, -1, -1).asDiagonal();
  return R_ned_to_enu * R_body_to_world * R_flu_to_frd;
}

/// The same for a unit quaternion (w, x, y, z); the result is normalized.
inline Eigen::Quaterniond swap_ned_frd_enu_flu(const Eigen::Quaterniond& q_body_to_world) {
  return Eigen::Quaterniond(swap_ned_frd_enu_flu(q_body_to_world.normalized().toRotationMatrix())).normalized();
}

}  // namespace wingman::geometry
