// SPDX-License-Identifier: MIT
// The follower's own state in Wingman's ENU world / FLU body frames, and the NED <-> ENU conversions.
#pragma once

#include <wingman/geometry/angles.hpp>
#include <wingman/geometry/ned_enu.hpp>
#include <wingman/own_pose_t.hpp>

#include <Eigen/Core>

#include <cstdint>

namespace wingman::follower_ctrl {

/// Frames (as in docs/localization.md): world ENU (x east, y north, z up), body FLU (x forward,
/// y left, z up). Everything inside the follower is ENU/FLU; an own pose reported in NED with an
/// FRD body (PX4, ArduPilot) is converted on arrival and setpoints are converted back on the way
/// out (`frame` remembers which convention the autopilot speaks).
struct OwnState {
  int64_t utime = 0;                                              ///< time of the pose, microseconds
  int8_t frame = wingman::own_pose_t::FRAME_ENU;                  ///< convention of the source own_pose_t
  Eigen::Vector3d p_body_in_world = Eigen::Vector3d::Zero();      ///< body origin, ENU, metres
  Eigen::Matrix3d R_body_to_world = Eigen::Matrix3d::Identity();  ///< FLU body -> ENU world
  Eigen::Vector3d v_body_in_world = Eigen::Vector3d::Zero();      ///< body velocity, ENU, m/s

  /// The state at `to_utime`: position moved by the velocity over the time difference, orientation
  /// and velocity held (used over the few milliseconds between a pose and a command time).
  OwnState predicted_to(int64_t to_utime) const;
  /// Heading of the body's forward axis, radians from ENU east towards north, in (-pi, pi].
  double yaw() const;
};

/// Converts a decoded own_pose_t (ENU/FLU or NED/FRD) into an OwnState in ENU/FLU:
/// p_enu = (e, n, -d), R_flu_to_enu = R_ned_to_enu R_frd_to_ned R_flu_to_frd (the localizer's
/// pose_ned_frd_to_enu_flu, geometry::swap_ned_frd_enu_flu). Precondition: validate_message(pose) passed (unit
/// quaternion, known frame).
OwnState own_state_from_message(const wingman::own_pose_t& pose);

// The NED <-> ENU conversions (ned_enu.hpp) and the angle wrap (angles.hpp) live in geometry/, shared with
// wingman-mavlink and the simulator.
using geometry::swap_ned_enu;
using geometry::swap_ned_enu_yaw;
using geometry::wrap_pi;

/// Azimuth in the world (radians from ENU east towards north) of the horizontal part of
/// `v_in_world`, or false when that part is shorter than `min_horizontal` (v nearly vertical).
bool horizontal_azimuth(const Eigen::Vector3d& v_in_world, double min_horizontal, double* azimuth_rad);

}  // namespace wingman::follower_ctrl
