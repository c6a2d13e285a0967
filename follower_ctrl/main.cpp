// SPDX-License-Identifier: MIT
// wingman-follower-ctrl: own pose and targets (formation) or detections (pid_1d) in, autopilot setpoints out.
#include "wingman/follower_ctrl/follower.hpp"

#include <wingman/common/runtime.hpp>

#include <spdlog/spdlog.h>

namespace {

using namespace wingman;

int run(common::Runtime& rt, const follower_ctrl::FollowerOptions& o) {
  follower_ctrl::Follower follower(o);
  rt.status().declare_output(o.output_channel);
  rt.status().set_state(status_t::STATE_DEGRADED, follower.status().detail);
  // Publishes what an input gave, counts the parts it could not use, and reports the state.
  auto handle = [&](const std::string& channel, const follower_ctrl::FollowerOutput& out) {
    for (const auto& why : out.rejections) rt.status().item_dropped(channel, why);
    for (const auto& note : out.notes) spdlog::warn("{}", note);  // a time resync
    if (out.setpoint) rt.publish(o.output_channel, *out.setpoint);
    rt.status().set_state(follower.status().flying ? status_t::STATE_OK : status_t::STATE_DEGRADED,
                          follower.status().detail);
  };
  rt.subscribe<own_pose_t>(o.own_pose_channel,
                           [&](const own_pose_t& p) { handle(o.own_pose_channel, follower.on_own_pose(p)); });
  if (follower.mode() == follower_ctrl::ControllerMode::kFormation) {
    rt.subscribe<targets_t>(o.targets_channel,
                            [&](const targets_t& t) { handle(o.targets_channel, follower.on_targets(t)); });
    if (!o.localizer_instance.empty())
      rt.subscribe<status_t>(common::status_channel(o.localizer_instance),
                             [&](const status_t& s) { follower.on_localizer_status(s); });
  } else {
    rt.subscribe<detections_t>(o.detections_channel, [&](const detections_t& d) {
      rt.status().set_last_processed_seq(d.seq);
      handle(o.detections_channel, follower.on_detections(d));
    });
  }
  return rt.spin();
}

}  // namespace

int main(int argc, char** argv) {
  const common::ProcessInfo info{"follower_ctrl", "wingman-follower-ctrl",
                                 "Flies the follower: formation on tracked targets, or the thesis's 1-D PID"};
  return common::run_process<follower_ctrl::FollowerOptions>(info, argc, argv, run);
}
