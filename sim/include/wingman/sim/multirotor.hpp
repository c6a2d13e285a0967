// SPDX-License-Identifier: MIT
// Multirotor dynamics: a vehicle that tracks position or velocity commands within speed, acceleration and
// response-time limits, and tilts with its acceleration.
#pragma once

#include "wingman/sim/vehicle_command.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace wingman::sim {

/// Standard gravity, m/s^2.
inline constexpr double kGravity = 9.80665;

/// Limits and response of one multirotor with its autopilot (scenario keys `vehicles[i].dynamics.*`; visit() and
/// validate() name them `<prefix>key`).
///
/// The model (docs/simulation.md, "Vehicle dynamics"), world frame ENU, body FLU:
/// - a velocity command v_cmd is clamped to max_speed_xy (horizontal norm) and max_speed_z (|vertical|);
/// - the velocity follows v_cmd as a first-order system with time constant velocity_time_constant_s, its
///   acceleration clamped to max_accel_xy (horizontal norm) and max_accel_z (|vertical|);
/// - position commands close a proportional loop, v_cmd = v_ff + tau a_ff + position_gain (p_ref - p): with the
///   feed-forward terms a reference trajectory is tracked without lag (tau = velocity_time_constant_s);
/// - yaw turns at yaw_gain (yaw_ref - yaw) (position) or the commanded rate (velocity), clamped to max_yaw_rate_deg;
/// - the body's z axis is the thrust direction a + g z_world: the vehicle tilts by atan(|a_horizontal| / g)
///   towards its acceleration, about the horizontal axis perpendicular to it, and the camera tilts with it.
struct MultirotorLimits {
  double max_speed_xy = 5.0;              ///< horizontal speed limit, m/s, > 0
  double max_speed_z = 2.0;               ///< vertical speed limit (up and down), m/s, > 0
  double max_accel_xy = 4.0;              ///< horizontal acceleration limit, m/s^2, > 0 (4 m/s^2 = 22 deg tilt)
  double max_accel_z = 3.0;               ///< vertical acceleration limit, m/s^2, > 0
  double velocity_time_constant_s = 0.3;  ///< first-order velocity response time constant, s, > 0
  /// Position loop gain, 1/s, > 0. 0.8 with tau 0.3 s gives a damping ratio of 1.02 (no overshoot).
  double position_gain = 0.8;
  double yaw_gain = 2.0;           ///< yaw loop gain in position mode, 1/s, > 0
  double max_yaw_rate_deg = 90.0;  ///< yaw rate limit, degrees/s, > 0
  double step_s = 0.002;           ///< longest internal integration step, s, in (0, 0.1]

  template <class V>
  void visit(V& v, const std::string& prefix = "dynamics.") {
    v(prefix + "max_speed_xy", max_speed_xy, "horizontal speed limit, m/s");
    v(prefix + "max_speed_z", max_speed_z, "vertical speed limit (up and down), m/s");
    v(prefix + "max_accel_xy", max_accel_xy,
      "horizontal acceleration limit, m/s^2 (sets the largest tilt: atan(a / g))");
    v(prefix + "max_accel_z", max_accel_z, "vertical acceleration limit, m/s^2");
    v(prefix + "velocity_time_constant_s", velocity_time_constant_s, "first-order velocity response time constant, s");
    v(prefix + "position_gain", position_gain,
      "position loop gain, 1/s (v_cmd = gain * position error + feed-forward)");
    v(prefix + "yaw_gain", yaw_gain, "yaw loop gain in position mode, 1/s");
    v(prefix + "max_yaw_rate_deg", max_yaw_rate_deg, "yaw rate limit, degrees/s");
    v(prefix + "step_s", step_s, "longest internal integration step, s");
  }
  /// One "<prefix>key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate(const std::string& prefix = "dynamics.") const;
};

/// The state of a multirotor. World frame ENU, body frame FLU (x forward, y left, z up).
struct MultirotorState {
  Eigen::Vector3d p_body_in_world = Eigen::Vector3d::Zero();  ///< body origin, metres
  Eigen::Vector3d v_body_in_world = Eigen::Vector3d::Zero();  ///< velocity, m/s
  Eigen::Vector3d a_body_in_world = Eigen::Vector3d::Zero();  ///< acceleration over the last step, m/s^2
  double yaw_rad = 0.0;  ///< heading of body x, from world x (east) towards world y (north), in (-pi, pi]
  Eigen::Quaterniond q_body_to_world = Eigen::Quaterniond::Identity();  ///< attitude (yaw and tilt)
  Eigen::Vector3d w_body_in_body = Eigen::Vector3d::Zero();             ///< angular velocity over the last step, rad/s
};

/// The attitude of a multirotor that accelerates at `a_in_world` (m/s^2, ENU) with heading `yaw_rad`: body z along
/// a + g z_world (the thrust); body y perpendicular to the heading direction (cos yaw, sin yaw, 0), so body x lies in
/// the plane of the heading and the thrust (Mellinger and Kumar 2011). Tilt = atan(|a_horizontal| / g) for a_z = 0.
/// Precondition: a_z > -g (not in free fall); a_z is clamped to -0.9 g otherwise.
Eigen::Quaterniond attitude_from_acceleration(const Eigen::Vector3d& a_in_world, double yaw_rad);

/// One multirotor with its autopilot, integrated deterministically.
///
/// Before any command it holds its initial position and heading (hover). Commands take effect from the next
/// step; MODE_HOLD holds the position and heading the vehicle has when the hold begins (a hold that follows a
/// hold keeps the first one's position).
class Multirotor {
 public:
  /// Hovering at `p_initial_in_world` (metres, ENU) with heading `yaw_rad`. Throws std::invalid_argument listing
  /// limits.validate() problems.
  Multirotor(const MultirotorLimits& limits, const Eigen::Vector3d& p_initial_in_world, double yaw_rad);

  /// The command from now on (world frame ENU; convert setpoint_t with command_from_setpoint()).
  void set_command(const VehicleCommand& command);
  /// Integrates `dt_s` seconds (>= 0) with the current command, in equal steps no longer than limits.step_s.
  void advance(double dt_s);
  /// One integration step of `h_s` seconds (> 0) with the current command.
  void step(double h_s);
  /// Places the vehicle at rest at `p_in_world` with heading `yaw_rad`, level, and holds there (scripted jumps).
  void teleport(const Eigen::Vector3d& p_in_world, double yaw_rad);

  const MultirotorState& state() const { return state_; }
  const MultirotorLimits& limits() const { return limits_; }
  /// The command in force, with MODE_HOLD resolved to a position command at the hold point.
  const VehicleCommand& command() const { return command_; }

 private:
  MultirotorLimits limits_;
  MultirotorState state_;
  VehicleCommand command_;
  bool holding_ = false;  ///< the command in force came from a MODE_HOLD
};

}  // namespace wingman::sim
