// SPDX-License-Identifier: MIT
// The `fly` verb of `wingman` (a build with the simulator).
#pragma once

#include <memory>
#include <ostream>

namespace CLI {
class App;
}

namespace wingman::tools {

/// Adds `fly` to the CLI and runs it when chosen.
class FlyVerb {
 public:
  /// Registers the subcommand and its options on `app`.
  explicit FlyVerb(CLI::App& app);
  ~FlyVerb();

  /// After parsing: flies and returns the exit code (0 ok, 1 failure, 2 bad options, 130 interrupted), or -1 when
  /// `fly` was not chosen. The flight's lines and eval's table go to `out`; progress and errors to `err`.
  int run_if_chosen(std::ostream& out, std::ostream& err);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace wingman::tools
