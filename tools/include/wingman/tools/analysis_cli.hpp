// SPDX-License-Identifier: MIT
// The analysis verbs of `wingman`: localize (one box), predict (the detector on images), bench detector, eval and
// report (a flight's errors against its ground truth).
#pragma once

#include <memory>
#include <ostream>

namespace CLI {
class App;
}

namespace wingman::tools {

/// Adds `localize`, `predict`, `eval`, `report` and `bench detector` to the CLI and runs the one chosen.
class AnalysisVerbs {
 public:
  /// Registers the subcommands and their options on `app`.
  explicit AnalysisVerbs(CLI::App& app);
  ~AnalysisVerbs();

  /// After parsing: runs the chosen verb and returns its exit code (0 ok, 1 failure, 2 bad options), or -1 when none
  /// of these verbs was chosen. Results go to `out`, progress and errors to `err`.
  int run_if_chosen(std::ostream& out, std::ostream& err);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace wingman::tools
