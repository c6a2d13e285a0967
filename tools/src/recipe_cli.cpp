// SPDX-License-Identifier: MIT
// `wingman train-recipe` and `wingman model derive-cfg`.
#include "wingman/tools/recipe_cli.hpp"

#include "run_verb.hpp"

#include "wingman/tools/cfg_derive.hpp"
#include "wingman/tools/recipe.hpp"

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace wingman::tools {

struct RecipeVerbs::State {
  CLI::App* derive = nullptr;
  CLI::App* recipe = nullptr;
  CLI::App* mix = nullptr;
  std::string mix_out, mix_path, mix_val, mix_comment;
  std::vector<std::string> mix_train, mix_names{"drone"};
  std::string cfg_in, cfg_out, input;
  CfgDerivation d;
  RecipeRunOptions run;
};

RecipeVerbs::RecipeVerbs(CLI::App& app) : s_(std::make_unique<State>()) {
  State& s = *s_;
  CLI::App* model = app.get_subcommand("model");
  s.derive = model->add_subcommand(
      "derive-cfg",
      "Write a variant of a .cfg (fewer heads, other anchors, another input size, a box loss), its other lines kept "
      "as they are, checked with the detector's .cfg parser");
  s.derive->add_option("--cfg", s.cfg_in, "The .cfg to derive from")->required();
  s.derive->add_option("--out", s.cfg_out, "The .cfg to write (its folder is created)")->required();
  s.derive->add_option("--heads", s.d.heads,
                       "Keep the first N [yolo] heads: the sections after the Nth go, with the comment lines above "
                       "the first of them (0: all)");
  s.derive
      ->add_option("--anchors", s.d.anchors,
                   "Every [yolo]'s anchors, w,h pairs in pixels; num follows (empty: "
                   "kept)")
      ->delimiter(',');
  s.derive->add_option("--input", s.input, "[net] width and height, WIDTHxHEIGHT (empty: kept)");
  s.derive->add_option("--iou-loss", s.d.iou_loss, "Every [yolo]'s box loss: mse, giou, diou or ciou (empty: kept)");
  s.derive->add_option("--iou-normalizer", s.d.iou_normalizer,
                       "Every [yolo]'s iou_normalizer, written as given (empty: kept)");

  // `dataset mix` beside `dataset synth` (a build with the simulator has `dataset`), else on its own.
  CLI::App* dataset = nullptr;
  for (CLI::App* sub : app.get_subcommands([](CLI::App* a) { return a->get_name() == "dataset"; })) dataset = sub;
  if (!dataset)
    dataset = app.add_subcommand("dataset", "Datasets: data.yaml files of several datasets")->require_subcommand(1);
  s.mix = dataset->add_subcommand(
      "mix", "Write a data.yaml (path, train, val, nc, names) of datasets under one folder, for train and val --data");
  s.mix->add_option("--out", s.mix_out, "The data.yaml to write")->required();
  s.mix->add_option("--path", s.mix_path, "The folder the entries are under (written absolute)")->required();
  s.mix->add_option("--train", s.mix_train, "Train entries: image folders or list files under --path")->delimiter(',');
  s.mix->add_option("--val", s.mix_val, "The val entry: an image folder or a list file under --path")->required();
  s.mix->add_option("--names", s.mix_names, "Class names")->delimiter(',');
  s.mix->add_option("--comment", s.mix_comment, "A comment line at the top (empty: none)");

  RecipeRunOptions& r = s.run;
  s.recipe = app.add_subcommand(
      "train-recipe",
      "Run a training recipe (config/training/*.yaml) stage by stage: prepare the datasets its stages use (kept once "
      "complete), write the data mixes and .cfg variants, train each stage not finished yet (resuming from its "
      "checkpoint); every command printed before it runs");
  s.recipe->add_option("recipe", r.recipe, "The recipe, e.g. config/training/wingman-small.yaml")->required();
  s.recipe->add_option("--data", r.data, "Where the datasets and mixes go (DATA)");
  s.recipe->add_option("--out", r.out, "Where the stages train (OUT; each stage in OUT/<its out>)");
  s.recipe->add_option("--src", r.src, "The source tree (${src} in the recipe; tools/fly.sh for the flights)");
  s.recipe->add_option("--bin", r.bin, "The folder of the wingman to run (empty: this one's)");
  s.recipe->add_option("--stage", r.stage,
                       "Train only this stage (the datasets it uses are still prepared; its start: --init)");
  s.recipe->add_option("--init", r.init, "With --stage: the weights it starts from (instead of the recipe's init)");
  s.recipe->add_option("--set", r.overrides,
                       "KEY=VALUE: a recipe key set before reading, STAGE.key for a stage's (e.g. stage6.batches=800, "
                       "train.threads=4); repeatable");
  s.recipe->add_flag("--data-only", r.data_only, "Prepare the datasets (and mixes) and train nothing");
  s.recipe->add_flag("--dry-run", r.dry_run, "Print every command it would run, run nothing");
}

RecipeVerbs::~RecipeVerbs() = default;

int RecipeVerbs::run_if_chosen(std::ostream& out, std::ostream& err) {
  State& s = *s_;
  if (*s.derive) {
    return run_verb("wingman model derive-cfg", err, [&] {
      if (!s.input.empty()) {
        char x = 0;
        char rest = 0;
        if (std::sscanf(s.input.c_str(), "%d%c%d%c", &s.d.width, &x, &s.d.height, &rest) != 3 || x != 'x' ||
            s.d.width <= 0 || s.d.height <= 0)
          throw std::invalid_argument(fmt::format("--input '{}': expected WIDTHxHEIGHT, e.g. 416x416", s.input));
      }
      derive_cfg_file(s.cfg_in, s.cfg_out, s.d);
      out << "wrote " << s.cfg_out << "\n";
      return 0;
    });
  }
  if (*s.mix) {
    return run_verb("wingman dataset mix", err, [&] {
      write_data_yaml_mix(s.mix_out, s.mix_path, s.mix_train, s.mix_val, s.mix_names, s.mix_comment);
      out << "wrote " << s.mix_out << "\n";
      return 0;
    });
  }
  if (*s.recipe) return run_verb("wingman train-recipe", err, [&] { return run_recipe(s.run, out, err); });
  return -1;
}

}  // namespace wingman::tools
