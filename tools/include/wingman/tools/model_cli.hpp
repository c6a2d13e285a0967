// SPDX-License-Identifier: MIT
// `wingman model`: operations on a detector model's files (.cfg + .weights).
#pragma once

#include <memory>
#include <ostream>

namespace CLI {
class App;
}

namespace wingman::tools {

/// Adds `model widen-classes` to the CLI and runs it when chosen: a trained model's [yolo] heads grown to more classes
/// (detector::widen_classes), written as a .cfg and a .weights file that `wingman train --weights` continues from.
class ModelVerbs {
 public:
  /// Registers the subcommands and their options on `app`.
  explicit ModelVerbs(CLI::App& app);
  ~ModelVerbs();

  /// After parsing: runs the chosen verb and returns its exit code (0 ok, 1 failure, 2 bad options), or -1 when
  /// none of these verbs was chosen. Results go to `out`, errors to `err`.
  int run_if_chosen(std::ostream& out, std::ostream& err);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace wingman::tools
