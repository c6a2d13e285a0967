// SPDX-License-Identifier: MIT
// What a controller commands for one driving input: world-frame velocity and yaw rate (ENU).
#pragma once

#include <Eigen/Core>

namespace wingman::follower_ctrl {

/// A velocity command in Wingman's ENU world frame, after every limit. The follower converts it to
/// the autopilot's convention (setpoint_t.frame) when it publishes it.
struct VelocityCommand {
  Eigen::Vector3d v_body_in_world = Eigen::Vector3d::Zero();  ///< ENU, m/s
  double yaw_rate_radps = 0.0;  ///< about world up (counter-clockwise seen from above), rad/s
  double yaw_rad = 0.0;         ///< heading the yaw rate turns towards (body x from east towards north), rad
  bool avoiding = false;        ///< collision avoidance was active (target within formation.avoid_radius_m)
};

}  // namespace wingman::follower_ctrl
