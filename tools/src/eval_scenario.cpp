// SPDX-License-Identifier: MIT
// The start of a flight from its scenario, read with the simulator's scenario loader (builds with the simulator).
#include "wingman/tools/eval_target.hpp"

#include <wingman/sim/scenario.hpp>

#include <fmt/format.h>

namespace wingman::tools {

FlightStart load_flight_start(const std::string& path, int follower_id, int leader_id) {
  const sim::Scenario scenario = sim::load_scenario(path);
  const sim::VehicleSpec* follower = nullptr;
  const sim::VehicleSpec* leader = nullptr;
  for (const auto& v : scenario.vehicles) {
    if (v.id == follower_id) follower = &v;
    if (v.id == leader_id) leader = &v;
  }
  if (follower == nullptr || leader == nullptr)
    throw common::ConfigError(
        fmt::format("{}: no vehicle with id {} (the {}; --{}-id)", path, follower == nullptr ? follower_id : leader_id,
                    follower == nullptr ? "follower" : "leader", follower == nullptr ? "follower" : "leader"));
  return FlightStart{follower->p_initial_in_world, leader->p_initial_in_world};
}

}  // namespace wingman::tools
