// SPDX-License-Identifier: MIT
// wingman-train: `wingman train` (libtorch) in an executable of its own, so that `wingman` starts without libtorch.
// `wingman train ARGS` replaces itself with `wingman-train train ARGS` (forwarded_verbs.cpp); its help and errors read
// as the verb's.
#include "tidy_defaults.hpp"
#include "train_verb.hpp"

#include <CLI/CLI.hpp>
#include <wingman/common/version.hpp>

#include <iostream>
#include <string>

int main(int argc, char** argv) {
  using namespace wingman::tools;
  CLI::App app{"Wingman's trainer: `wingman train` runs here (wingman-train train ARGS)", "wingman"};
  app.require_subcommand(1);
  app.option_defaults()->always_capture_default();  // as `wingman`: the help shows the bound defaults
  app.set_version_flag("--version", std::string("wingman ") + wingman::common::version(),
                       "Print the version (and the commit built from) and exit");
  TrainVerb train(app);
  tidy_defaults(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() != 0) {
      std::cerr << "wingman: error: " << e.what() << " (see --help)" << std::endl;
      return 2;
    }
    return app.exit(e);
  }
  return train.run_if_chosen(std::cout, std::cerr);
}
