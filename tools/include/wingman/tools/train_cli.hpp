// SPDX-License-Identifier: MIT
// The training verbs of `wingman` that need no libtorch: val and import-halmstad (`train` runs in wingman-train).
#pragma once

#include <memory>
#include <ostream>

namespace CLI {
class App;
}

namespace wingman::tools {

/// Adds `val` and `import-halmstad` to the CLI and runs the one chosen. `train` is wingman-train's (train_verb.hpp),
/// which `wingman train` hands over to (forwarded_verbs.hpp).
class TrainingVerbs {
 public:
  /// Registers the subcommands and their options on `app`.
  explicit TrainingVerbs(CLI::App& app);
  ~TrainingVerbs();

  /// After parsing: runs the chosen verb and returns its exit code (0 ok, 1 failure, 2 bad options), or -1 when
  /// none of these verbs was chosen. Results go to `out`, progress and errors to `err`.
  int run_if_chosen(std::ostream& out, std::ostream& err);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace wingman::tools
