// SPDX-License-Identifier: MIT
// The launching verbs of `wingman`: fly (a simulated flight; a build with the simulator), demo-camera (a video through
// the pipeline) and load (the four-camera load test and soak).
#pragma once

#include <memory>
#include <ostream>

namespace CLI {
class App;
}

namespace wingman::tools {

/// Adds `fly` (with the simulator), `demo-camera` and `load` to the CLI and runs the one chosen.
class LaunchVerbs {
 public:
  /// Registers the subcommand and its options on `app`.
  explicit LaunchVerbs(CLI::App& app);
  ~LaunchVerbs();

  /// After parsing: runs the chosen verb and returns its exit code (0 ok, 1 failure, 2 bad options, 130 interrupted),
  /// or -1 when none of these was chosen. What it shows goes to `out`; progress and errors to `err`.
  int run_if_chosen(std::ostream& out, std::ostream& err);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace wingman::tools
