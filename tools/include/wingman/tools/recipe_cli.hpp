// SPDX-License-Identifier: MIT
// `wingman train-recipe` (a training recipe run stage by stage) and `wingman model derive-cfg` (a .cfg variant).
#pragma once

#include <memory>
#include <ostream>

namespace CLI {
class App;
}

namespace wingman::tools {

/// Adds `train-recipe` and `model derive-cfg` to the CLI (construct it after ModelVerbs: `model` must exist) and
/// runs them when chosen.
class RecipeVerbs {
 public:
  explicit RecipeVerbs(CLI::App& app);
  ~RecipeVerbs();

  /// After parsing: runs the chosen verb and returns its exit code (0 ok, 1 failure, 2 bad options or recipe), or
  /// -1 when none of these verbs was chosen.
  int run_if_chosen(std::ostream& out, std::ostream& err);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace wingman::tools
