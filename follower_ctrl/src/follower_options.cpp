// SPDX-License-Identifier: MIT
// Validation of FollowerOptions.
#include "wingman/follower_ctrl/follower_options.hpp"

#include <wingman/common/config.hpp>

namespace wingman::follower_ctrl {

std::vector<std::string> FollowerOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (targets_channel.empty()) p.push_back(problem("input.targets_channel", targets_channel, "must not be empty"));
  if (own_pose_channel.empty()) p.push_back(problem("input.own_pose_channel", own_pose_channel, "must not be empty"));
  if (output_channel.empty()) p.push_back(problem("output.channel", output_channel, "must not be empty"));
  return p;
}

}  // namespace wingman::follower_ctrl
