// SPDX-License-Identifier: MIT
// A simulation scenario (config/scenarios/*.yaml): the vehicles, how they look, how they fly and what they do.
#pragma once

#include "wingman/sim/drone_spec.hpp"
#include "wingman/sim/motion_script.hpp"
#include "wingman/sim/multirotor.hpp"

#include <wingman/common/config.hpp>

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace wingman::sim {

/// A scenario file that cannot be used. what() is one line naming the file and every problem with its line and
/// key, e.g. "2 problems in scenario: s.yaml:14: vehicles[1].motion.max_speed: expected a number, got 'fast'; ...".
/// Derives from common::ConfigError: a bad scenario is a bad configuration (exit code 2).
class ScenarioError : public common::ConfigError {
 public:
  using common::ConfigError::ConfigError;
};

/// One simulated vehicle (an entry of `vehicles:`).
struct VehicleSpec {
  /// Who commands the vehicle: setpoint_t messages (only the camera vehicle, id 0), or its motion script.
  enum class Control { kSetpoints, kScript };

  std::string name;  ///< `name`, unique, e.g. "leader"
  int id = 0;        ///< `id`, unique, >= 0; 0 is the camera vehicle (the follower)
  /// `control`: setpoints (default for id 0) or script (default otherwise; the only choice for id != 0).
  Control control = Control::kScript;
  Eigen::Vector3d p_initial_in_world = Eigen::Vector3d::Zero();  ///< `initial.position`, metres, ENU
  double yaw_initial_rad = 0.0;  ///< `initial.yaw_deg` (degrees in the file): heading from east towards north
  DroneSpec drone;               ///< `drone.*`: appearance (renderer) and bounding radius
  MultirotorLimits dynamics;     ///< `dynamics.*`
  MotionSpec motion;             ///< `motion.*`: the script of a scripted vehicle (default hover)
};

/// A whole scenario. Time: frame 0 is exposed at start_utime; the camera's rate comes from the simulator's options.
struct Scenario {
  std::string name;         ///< `name` (default: the file name without .yaml)
  std::string description;  ///< `description`: one line, free text
  std::string source;       ///< the file it was read from (or the name given to parse_scenario)
  /// `start_utime`: exposure of frame 0, microseconds since epoch (fixed, so runs repeat). Default 2026-01-01.
  int64_t start_utime = 1767225600000000;
  /// `duration_s`: simulated time, s; 0 = until every finite script has ended (teleport steps, waypoints without
  /// loop), which is an error when no script is finite.
  double duration_s = 0.0;
  /// `command_delay_s`: a setpoint for time t applies from t + command_delay_s (pipeline lag, deterministic), s.
  double command_delay_s = 0.1;
  /// `seed`: seed of the per-frame image noise (with the frame number) and of anything random the scenario does not
  /// seed itself.
  uint64_t seed = 1;
  std::vector<VehicleSpec> vehicles;  ///< `vehicles`: the camera vehicle (id 0) and the targets

  /// The vehicle with id 0 (the loader guarantees there is exactly one).
  const VehicleSpec& camera_vehicle() const;
};

/// Reads a scenario file. Relative `drone.mesh_path`s are resolved against the file's folder. Throws ScenarioError
/// listing every problem at once (file unreadable, not YAML, wrong types, unknown keys, missing keys, rule
/// violations, a vehicle list without exactly one id 0, ...).
Scenario load_scenario(const std::string& path);

/// Same from YAML text; `source_name` stands for the file name in messages and `base_dir` resolves relative mesh
/// paths ("" = the current directory).
Scenario parse_scenario(const std::string& yaml_text, const std::string& source_name, const std::string& base_dir = "");

}  // namespace wingman::sim
