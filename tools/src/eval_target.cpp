// SPDX-License-Identifier: MIT
// The formation target of a flight, from the follower's configuration and the scenario.
#include "wingman/tools/eval_target.hpp"

#include <fmt/format.h>

#include <vector>

namespace wingman::tools {

Eigen::Vector3d formation_offset_for(const follower_ctrl::FollowerOptions& follower,
                                     const std::optional<FlightStart>& start) {
  if (follower.controller_mode() == follower_ctrl::ControllerMode::kFormation) {
    const std::vector<double>& o = follower.formation.offset_m;  // three numbers (FollowerOptions::validate)
    return {o[0], o[1], o[2]};
  }
  if (!start)
    throw common::ConfigError(
        "the follower's controller.mode is pid_1d: its target comes from the scenario's start (give --scenario FILE)");
  return {0.0, start->p_follower_in_world.y() - start->p_leader_in_world.y(), 0.0};
}

Eigen::Vector3d formation_offset_for(const FlightTargetSources& sources, int follower_id, int leader_id) {
  const auto follower = common::load_options<follower_ctrl::FollowerOptions>(sources.follower);
  // Only the 1-D follow's target depends on the scenario: it is read for that mode alone.
  if (follower.controller_mode() == follower_ctrl::ControllerMode::kFormation || sources.scenario.empty())
    return formation_offset_for(follower, std::nullopt);
  return formation_offset_for(follower, load_flight_start(sources.scenario, follower_id, leader_id));
}

#ifndef WINGMAN_WITH_SIM
FlightStart load_flight_start(const std::string& path, int /*follower_id*/, int /*leader_id*/) {
  throw common::ConfigError(path + ": this build has no simulator to read scenarios (WINGMAN_WITH_SIM is off)");
}
#endif

}  // namespace wingman::tools
