// SPDX-License-Identifier: MIT
// The log verbs of `wingman`: replay (a log into the pipeline), spy (lcm-spy), make-video (a test clip) and loginfo.
#pragma once

#include <memory>
#include <ostream>

namespace CLI {
class App;
}

namespace wingman::tools {

/// Adds `replay`, `spy`, `make-video` and `loginfo` to the CLI and runs the one chosen.
class LogVerbs {
 public:
  /// Registers the subcommands and their options on `app`.
  explicit LogVerbs(CLI::App& app);
  ~LogVerbs();

  /// After parsing: runs the chosen verb and returns its exit code (0 ok, 1 failure, 2 bad options), or -1 when none
  /// of these verbs was chosen. Results go to `out`, progress and errors to `err` (a failure: "wingman: error: ...").
  int run_if_chosen(std::ostream& out, std::ostream& err);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace wingman::tools
