// SPDX-License-Identifier: MIT
// Options of wingman-follower-ctrl (config/follower_ctrl.yaml).
#pragma once

#include <string>
#include <vector>

namespace wingman::follower_ctrl {

/// Options of the follower process. The PID and formation controllers arrive with the simulation
/// issue; until then the process checks and counts its inputs and publishes no setpoints.
struct FollowerOptions {
  std::string targets_channel = "TARGETS";    ///< targets_t input channel
  std::string own_pose_channel = "OWN_POSE";  ///< own_pose_t input channel
  std::string output_channel = "SETPOINT";    ///< setpoint_t output channel

  template <class V>
  void visit(V& v) {
    v("input.targets_channel", targets_channel, "targets_t channel from wingman-localizer");
    v("input.own_pose_channel", own_pose_channel, "own_pose_t channel with this vehicle's pose");
    v("output.channel", output_channel, "setpoint_t channel to command the autopilot on");
  }
  std::vector<std::string> validate() const;
};

}  // namespace wingman::follower_ctrl
