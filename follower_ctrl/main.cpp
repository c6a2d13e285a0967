// SPDX-License-Identifier: MIT
// wingman-follower-ctrl: targets and own pose in, autopilot setpoints out (controllers arrive with the simulation
// issue).
#include "wingman/follower_ctrl/follower_options.hpp"

#include <wingman/common/runtime.hpp>

int main(int argc, char** argv) {
  using namespace wingman;
  const common::ProcessInfo info{"follower_ctrl", "wingman-follower-ctrl", "Flies in formation on localized targets"};
  return common::run_process<follower_ctrl::FollowerOptions>(
      info, argc, argv, [](common::Runtime& rt, const follower_ctrl::FollowerOptions& o) {
        rt.status().declare_output(o.output_channel);
        rt.status().set_state(status_t::STATE_DEGRADED, "no controller yet: inputs are checked and counted only");
        rt.subscribe<targets_t>(o.targets_channel, [](const targets_t&) {});
        rt.subscribe<own_pose_t>(o.own_pose_channel, [](const own_pose_t&) {});
        return rt.spin();
      });
}
