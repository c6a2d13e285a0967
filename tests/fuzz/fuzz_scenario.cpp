// SPDX-License-Identifier: MIT
// Fuzz target: the simulator's scenario files (sim/src/world/scenario.cpp and its YAML reader), as wingman-sim
// reads its `scenario`. Anything wrong must be a ScenarioError (a ConfigError listing every problem).
#include "fuzz_support.hpp"

#include <wingman/sim/scenario.hpp>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const wingman::sim::Scenario s =
        wingman::sim::parse_scenario(std::string(reinterpret_cast<const char*>(data), size), "<fuzz>", "/nonexistent");
    (void)s;
  } catch (const wingman::common::ConfigError&) {
  }
  return 0;
}
