// SPDX-License-Identifier: MIT
// `wingman train`: the trainer's command line, run by wingman-train (libtorch; `wingman train` hands over to it).
#pragma once

#include <memory>
#include <ostream>

namespace CLI {
class App;
}

namespace wingman::tools {

/// What `wingman --help` and `wingman train --help` say of the verb (the same words in both executables).
inline constexpr const char* kTrainVerbDescription =
    "Train a Darknet .cfg network on a YOLO dataset (libtorch); writes .weights the detector loads";

/// Adds `train` to the CLI and runs it. A build without libtorch (no WINGMAN_WITH_TRAINING) has the options and
/// --help, and `train` answers with how to get the trainer.
class TrainVerb {
 public:
  /// Registers the subcommand and its options on `app`.
  explicit TrainVerb(CLI::App& app);
  ~TrainVerb();

  /// After parsing: runs `train` and returns its exit code (0 ok, 1 failure, 2 bad options, 130 interrupted), or -1
  /// when it was not chosen. Results go to `out`, progress and errors to `err`.
  int run_if_chosen(std::ostream& out, std::ostream& err);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace wingman::tools
