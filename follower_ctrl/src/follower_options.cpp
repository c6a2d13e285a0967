// SPDX-License-Identifier: MIT
// Validation of FollowerOptions.
#include "wingman/follower_ctrl/follower_options.hpp"

#include <fmt/format.h>
#include <wingman/common/config.hpp>

#include <cmath>

namespace wingman::follower_ctrl {

std::optional<ControllerMode> parse_controller_mode(const std::string& name) {
  if (name == "formation") return ControllerMode::kFormation;
  if (name == "pid_1d") return ControllerMode::kPid1d;
  return std::nullopt;
}

std::vector<std::string> FollowerOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (targets_channel.empty()) p.push_back(problem("input.targets_channel", targets_channel, "must not be empty"));
  if (own_pose_channel.empty()) p.push_back(problem("input.own_pose_channel", own_pose_channel, "must not be empty"));
  if (detections_channel.empty())
    p.push_back(problem("input.detections_channel", detections_channel, "must not be empty"));
  if (output_channel.empty()) p.push_back(problem("output.channel", output_channel, "must not be empty"));
  if (!parse_controller_mode(mode)) p.push_back(problem("controller.mode", mode, "must be formation or pid_1d"));
  if (!(hold_timeout_s > 0) || !std::isfinite(hold_timeout_s))
    p.push_back(problem("hold.timeout_s", hold_timeout_s, "must be a finite number > 0"));
  if (!(localizer_heartbeat_timeout_s > 0) || !std::isfinite(localizer_heartbeat_timeout_s))
    p.push_back(problem("localizer.heartbeat_timeout_s", localizer_heartbeat_timeout_s, "must be a finite number > 0"));
  for (const auto& part :
       {time.validate(), limits.validate(), camera_mount.validate(), formation.validate(), pid_1d.validate()})
    p.insert(p.end(), part.begin(), part.end());
  if (formation.avoid_climb_mps > limits.max_vertical_speed_mps)
    p.push_back(
        problem("formation.avoid_climb_mps", formation.avoid_climb_mps,
                fmt::format("must not exceed limits.max_vertical_speed_mps = {}", limits.max_vertical_speed_mps)));
  return p;
}

int64_t FollowerOptions::hold_timeout_us() const { return static_cast<int64_t>(std::llround(hold_timeout_s * 1e6)); }
int64_t FollowerOptions::localizer_heartbeat_timeout_us() const {
  return static_cast<int64_t>(std::llround(localizer_heartbeat_timeout_s * 1e6));
}

}  // namespace wingman::follower_ctrl
