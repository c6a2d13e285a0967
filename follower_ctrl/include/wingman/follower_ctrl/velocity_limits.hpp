// SPDX-License-Identifier: MIT
// Shaping of a world-frame velocity command: speed and acceleration limits, the no-approach rule of
// collision avoidance, and the floor height.
#pragma once

#include "wingman/follower_ctrl/world_frame.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace wingman::follower_ctrl {

/// Limits on every velocity command, both controllers (keys `limits.*`). World frame ENU.
struct LimitsOptions {
  double max_horizontal_speed_mps = 3.0;   ///< |(v_x, v_y)| <= this, m/s; > 0
  double max_vertical_speed_mps = 1.0;     ///< |v_z| <= this, m/s; > 0
  double max_horizontal_accel_mps2 = 2.0;  ///< |(dv_x, dv_y)| <= this * dt between commands, m/s^2; > 0
  double max_vertical_accel_mps2 = 1.0;    ///< |dv_z| <= this * dt between commands, m/s^2; > 0
  double max_yaw_rate_radps = 1.0;         ///< |yaw_rate| <= this, rad/s; > 0
  /// Lowest height (ENU z, metres above the autopilot's origin; -z for an NED autopilot) the
  /// follower descends to: height references are raised to it, and at or below it no command descends.
  double floor_height_m = 1.0;

  template <class V>
  void visit(V& v) {
    v("limits.max_horizontal_speed_mps", max_horizontal_speed_mps, "largest horizontal speed commanded, m/s");
    v("limits.max_vertical_speed_mps", max_vertical_speed_mps, "largest vertical speed commanded, m/s");
    v("limits.max_horizontal_accel_mps2", max_horizontal_accel_mps2,
      "largest change of the horizontal velocity command per second of message time, m/s^2");
    v("limits.max_vertical_accel_mps2", max_vertical_accel_mps2,
      "largest change of the vertical velocity command per second of message time, m/s^2");
    v("limits.max_yaw_rate_radps", max_yaw_rate_radps, "largest yaw rate commanded, rad/s");
    v("limits.floor_height_m", floor_height_m,
      "floor: never descend at or below this height (world up, m); height references are raised to it");
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
};

/// Scales the horizontal part of `v_in_world` down to max_horizontal_speed_mps (direction kept)
/// and clamps v_z to +-max_vertical_speed_mps.
Eigen::Vector3d limit_speed(const Eigen::Vector3d& v_in_world, const LimitsOptions& limits);

/// Moves from `v_previous` towards `v_wanted` by at most max_horizontal_accel_mps2 * dt_s
/// horizontally (the change vector is scaled, so its direction is kept) and
/// max_vertical_accel_mps2 * dt_s vertically. Precondition: dt_s >= 0.
Eigen::Vector3d limit_acceleration(const Eigen::Vector3d& v_wanted, const Eigen::Vector3d& v_previous, double dt_s,
                                   const LimitsOptions& limits);

/// Removes the component of `v` towards `d_to_obstacle` (any length > 0): returns v - max(0, v.u) u
/// with u = d / |d|, so the result never closes the distance.
Eigen::Vector3d remove_approach(const Eigen::Vector3d& v, const Eigen::Vector3d& d_to_obstacle);

/// The command stage every controller ends with. It remembers the previous command (message time)
/// for the acceleration limit, and applies, in this order of priority (a later rule never breaks an
/// earlier one):
///  1. the floor: at or below limits.floor_height_m, v_z >= 0;
///  2. no approach (collision avoidance, when an obstacle direction is given): no component towards it;
///  3. the speed limits;
///  4. the acceleration limits, from the previous command, or, after a reset(), from the own
///     velocity measured at own.utime (so a command never jumps away from what the vehicle does).
/// Rules 1 and 2 may therefore change the command faster than the acceleration limit allows.
class VelocityLimiter {
 public:
  /// Throws std::invalid_argument listing validate() problems.
  explicit VelocityLimiter(const LimitsOptions& limits);

  /// The command to send at `utime` (microseconds) for the wanted `v_wanted_in_world` (ENU, m/s).
  /// `own`: the own state (position for the floor, velocity and utime after a reset).
  /// `d_to_obstacle_in_world`: direction from own to an obstacle to not approach, or nullopt.
  /// Throws std::invalid_argument when utime is before the previous command's.
  Eigen::Vector3d apply(const Eigen::Vector3d& v_wanted_in_world, int64_t utime, const OwnState& own,
                        const std::optional<Eigen::Vector3d>& d_to_obstacle_in_world = std::nullopt);
  /// Clamps a yaw rate to +-max_yaw_rate_radps.
  double limit_yaw_rate(double yaw_rate_radps) const;
  /// Forgets the previous command (after a hold).
  void reset() { previous_.reset(); }
  const LimitsOptions& limits() const { return limits_; }

 private:
  struct Previous {
    Eigen::Vector3d v_in_world;
    int64_t utime;
  };
  LimitsOptions limits_;
  std::optional<Previous> previous_;
};

}  // namespace wingman::follower_ctrl
