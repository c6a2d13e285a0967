// SPDX-License-Identifier: MIT
// `wingman scenario set`: a copy of a scenario with some keys replaced, checked with the simulator's loader.
#pragma once

#include <string>
#include <vector>

namespace wingman::tools {

/// What `wingman scenario set FILE --set KEY=VALUE... --out OUT` does.
struct ScenarioSetOptions {
  std::string file;               ///< the scenario to copy
  std::vector<std::string> sets;  ///< KEY=VALUE, applied in order
  std::string out;                ///< the copy to write
};

/// Writes `o.out`: `o.file` with each KEY set to VALUE (a YAML scalar, flow sequence or flow mapping; a missing key
/// is added). KEY is a dotted path through the scenario's mappings (`seed`, `duration_s`); in `vehicles` an entry is
/// named by its `name` (`vehicles.camera.motion.frames_per_step`, `vehicles.target.initial.yaw_deg`). Relative
/// `drone.mesh_path`s are made absolute against `o.file`'s folder, so the copy flies from any folder. The copy is read
/// back with the simulator's scenario loader before it is written. Throws common::ConfigError naming the --set or
/// every problem of the copy (nothing is written then).
void write_scenario_copy(const ScenarioSetOptions& o);

}  // namespace wingman::tools
