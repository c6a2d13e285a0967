// SPDX-License-Identifier: MIT
// `wingman`: the tools CLI. Verbs: replay (deterministic log player), spy, loginfo, make-video, localize, predict,
// bench detector, eval (flight errors against ground truth), report (its HTML page), dataset synth, scenario random
// (out-of-sample flights), train / val / import-halmstad (training; `train` runs in wingman-train).
#include "wingman/tools/analysis_cli.hpp"
#include "wingman/tools/forwarded_verbs.hpp"
#include "wingman/tools/launch_cli.hpp"
#include "wingman/tools/log_cli.hpp"
#include "wingman/tools/model_cli.hpp"
#include "wingman/tools/recipe_cli.hpp"
#include "wingman/tools/train_cli.hpp"
#ifdef WINGMAN_WITH_SIM
#include "wingman/tools/dataset_synth.hpp"
#include "wingman/tools/scenario_random.hpp"
#endif

#include "tidy_defaults.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <wingman/common/version.hpp>

#include <iostream>
#include <string>

int main(int argc, char** argv) {
  using namespace wingman::tools;
  CLI::App app{"Wingman tools: replay logs through the pipeline, monitor and inspect it", "wingman"};
  app.require_subcommand(1);
  // Every verb's help shows each option's default from the variable it is bound to (subcommands inherit this).
  app.option_defaults()->always_capture_default();
  app.set_version_flag("--version", std::string("wingman ") + wingman::common::version(),
                       "Print the version (and the commit built from) and exit");

  LogVerbs logs(app);             // replay, spy, make-video, loginfo
  AnalysisVerbs analysis(app);    // localize, predict, eval, report, bench detector
  ForwardedVerbs forwarded(app);  // train: runs in wingman-train (libtorch), so that wingman starts without it
  TrainingVerbs training(app);    // val, import-halmstad
  LaunchVerbs launching(app);     // fly (with the simulator), demo-camera
  ModelVerbs model_verbs(app);    // model widen-classes
#ifdef WINGMAN_WITH_SIM
  DatasetVerbs dataset(app);    // dataset synth
  ScenarioVerbs scenario(app);  // scenario random
#endif
  // train-recipe, model derive-cfg, dataset mix (after ModelVerbs and DatasetVerbs: `model` and `dataset` exist)
  RecipeVerbs recipe_verbs(app);
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
  if (const int rc = forwarded.run_if_chosen(argc, argv, std::cerr); rc >= 0) return rc;  // returns on failure only
  auto logger = spdlog::stderr_color_st("wingman");
  logger->set_pattern("%Y-%m-%dT%H:%M:%S.%e [%n] %^%l%$: %v");
  spdlog::set_default_logger(logger);

  try {
    if (const int rc = logs.run_if_chosen(std::cout, std::cerr); rc >= 0) return rc;
    if (const int rc = analysis.run_if_chosen(std::cout, std::cerr); rc >= 0) return rc;
    if (const int rc = training.run_if_chosen(std::cout, std::cerr); rc >= 0) return rc;
    if (const int rc = launching.run_if_chosen(std::cout, std::cerr); rc >= 0) return rc;
    if (const int rc = model_verbs.run_if_chosen(std::cout, std::cerr); rc >= 0) return rc;
    if (const int rc = recipe_verbs.run_if_chosen(std::cout, std::cerr); rc >= 0) return rc;
#ifdef WINGMAN_WITH_SIM
    if (const int rc = dataset.run_if_chosen(std::cout, std::cerr); rc >= 0) return rc;
    if (const int rc = scenario.run_if_chosen(std::cout, std::cerr); rc >= 0) return rc;
#endif
  } catch (const std::exception& e) {
    std::cerr << "wingman: error: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
