// SPDX-License-Identifier: MIT
// The formation target `wingman eval` measures a flight against, from the follower's configuration and the scenario.
#pragma once

#include <wingman/common/config.hpp>
#include <wingman/follower_ctrl/follower_options.hpp>

#include <Eigen/Core>

#include <optional>
#include <string>

namespace wingman::tools {

/// Where the follower and the leader start (a scenario's `initial.position`s), metres, ENU.
struct FlightStart {
  Eigen::Vector3d p_follower_in_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_leader_in_world = Eigen::Vector3d::Zero();
};

/// The desired follower-minus-leader position (ENU, metres) the follower flies to:
/// - mode formation: formation.offset_m;
/// - mode pid_1d: the 1-D follow keeps the leader straight ahead, so the desired position is the leader's moved back to
///   the follower's own line: (0, y_follower - y_leader, 0) of the start, the error along the leader's path.
/// Throws common::ConfigError when pid_1d has no `start` (it needs the scenario).
Eigen::Vector3d formation_offset_for(const follower_ctrl::FollowerOptions& follower,
                                     const std::optional<FlightStart>& start);

/// The start of the vehicles with ids `follower_id` and `leader_id` in the scenario file `path`, read with the
/// simulator's scenario loader. Throws common::ConfigError (every problem of the file, or a missing id). Only in a
/// build with the simulator (WINGMAN_WITH_SIM).
FlightStart load_flight_start(const std::string& path, int follower_id, int leader_id);

/// `wingman eval --follower-config ... --follower-set ... --scenario FILE`: the formation offset of a flight.
struct FlightTargetSources {
  common::ConfigSources follower;  ///< the follower's configuration (none: its built-in defaults)
  std::string scenario;            ///< the scenario file ("" = none)
  bool given() const { return !follower.empty() || !scenario.empty(); }
};
/// The offset from `sources`: loads and validates the follower's options with common's loader, and, for a pid_1d
/// follower, the scenario. Throws common::ConfigError naming the file and key.
Eigen::Vector3d formation_offset_for(const FlightTargetSources& sources, int follower_id, int leader_id);

}  // namespace wingman::tools
