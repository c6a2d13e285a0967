// SPDX-License-Identifier: MIT
// What an autopilot is told to do: hold, fly to a position, or fly with a velocity (from setpoint_t or a script).
#pragma once

#include <wingman/setpoint_t.hpp>

#include <Eigen/Core>

namespace wingman::sim {

/// A command for one multirotor, in the world frame ENU (x east, y north, z up).
struct VehicleCommand {
  enum class Mode {
    kHold,      ///< hold the position and heading the vehicle has when the hold begins
    kPosition,  ///< fly to p_ref_in_world (with feed-forward v_ref and a_ref), turn to yaw_ref_rad
    kVelocity,  ///< fly with v_ref_in_world, turn at yaw_rate_ref
  };
  Mode mode = Mode::kHold;
  Eigen::Vector3d p_ref_in_world = Eigen::Vector3d::Zero();  ///< kPosition: target position, metres
  /// kPosition: feed-forward velocity of a moving reference (0 for a fixed point); kVelocity: the velocity. m/s.
  Eigen::Vector3d v_ref_in_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_ref_in_world = Eigen::Vector3d::Zero();  ///< kPosition: feed-forward acceleration, m/s^2
  double yaw_ref_rad = 0.0;                                  ///< kPosition: heading, from east towards north, radians
  double yaw_rate_ref = 0.0;  ///< kVelocity: heading rate (counter-clockwise seen from above), rad/s
};

/// Converts a setpoint_t (ENU or NED, as its `frame` says) into a command in ENU:
/// - FRAME_NED: position and velocity (n, e, d) -> (e, n, -d); the heading (from north, clockwise) becomes
///   yaw_enu = pi/2 - yaw_ned, and yaw_rate_enu = -yaw_rate_ned (body FRD and FLU share the forward axis);
/// - MODE_HOLD, MODE_POSITION (position, yaw) and MODE_VELOCITY (velocity, yaw_rate) map to the modes above.
/// Precondition: the message passed validate_message() (known mode and frame, finite numbers); throws
/// std::invalid_argument naming the field otherwise.
VehicleCommand command_from_setpoint(const wingman::setpoint_t& setpoint);

}  // namespace wingman::sim
