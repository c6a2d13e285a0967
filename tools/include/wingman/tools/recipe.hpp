// SPDX-License-Identifier: MIT
// A training recipe (config/training/*.yaml): the datasets to prepare, the data mixes, the .cfg variants and the
// training stages of a model, read with common::YamlMappingReader; and its runner (`wingman train-recipe`), which
// runs the other `wingman` verbs as child processes, stage by stage and resumably.
#pragma once

#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace wingman::tools {

/// One dataset the recipe prepares into DATA/<name> (kept once complete).
struct RecipeDataset {
  std::string name;
  /// halmstad: `wingman import-halmstad`; synth: `wingman dataset synth`; flights: training flights flown through
  /// the pipeline (tools/make_training_flights.py, tools/fly.sh) and taken with `wingman dataset from-log`.
  std::string kind;
  std::string source;               ///< halmstad: the videos' folder
  bool distractor_classes = false;  ///< halmstad: airplane, bird and helicopter boxes as classes 1-3
  int negative_frame_step = 0;      ///< halmstad: every Nth frame of the distractor clips (0: the importer's)
  std::string config;               ///< synth: the synth.* / render.* file
  int count = 0;                    ///< synth: images; flights: flights
  int seed = 1;
  int duration_s = 40;   ///< flights: seconds each
  int every = 5;         ///< flights: every Nth frame kept
  std::vector<int> val;  ///< flights: which flights (0-based) go to val; the others to train
};

/// A data.yaml for `wingman train --data` (DATA/<name>.yaml): the train split of some datasets, one's val split.
struct RecipeMix {
  std::string name;
  std::string comment;
  std::vector<std::string> train;  ///< dataset names (their images/train)
  std::string val;                 ///< a dataset name (its images/val)
  std::vector<std::string> names;  ///< class names
};

/// A .cfg variant OUT/<name>/<model>.cfg (`wingman model derive-cfg`).
struct RecipeCfg {
  std::string name;
  std::string from;  ///< another variant's name or a .cfg path
  int heads = 0;
  std::vector<int> anchors;
  std::vector<int> input;  ///< [width, height] or empty
};

/// A trained model to widen to more classes first (`wingman model widen-classes`) into <stage out>/init/.
struct RecipeWiden {
  std::string cfg, weights;
  int classes = 0;
  std::string iou_loss, iou_normalizer;
};

/// One `wingman train` run into OUT/<out>.
struct RecipeStage {
  std::string name;
  std::vector<std::string> prepare;      ///< datasets prepared before it (when an active stage uses them)
  std::string cfg;                       ///< a variant's name or a .cfg path
  std::string iou_loss, iou_normalizer;  ///< a box loss other than mse: trains OUT/cfg-<loss>[-<normalizer>]
  RecipeWiden widen;                     ///< widen.classes > 0: the stage trains the widened model
  std::string mix;
  std::string out = ".";
  std::vector<std::string> init;  ///< the first that exists (else the last): a path or STAGE:N / STAGE:final
  bool partial_weights = false;
  int batches = 0;  ///< 0: this stage and the later ones are not run
  int burn_in = 0;
  double learning_rate = 0.001;
  std::vector<int> steps_percent;  ///< rate steps at these percentages of batches
  int weights_interval = 100;
  std::string ema_decay;
};

/// `wingman train` options every stage gets.
struct RecipeTrainOptions {
  int threads = 2;
  std::string scales = "0.5,0.2,0.5";
  double scale = 0.25, translate = 0.1, blur = 0.1, noise = 0.1;
  int checkpoint_interval = 25, log_interval = 10, val_max_images = 400;
};

struct Recipe {
  std::string path;
  std::string model = "wingman-small";  ///< the trainer names its files after the .cfg: <model>_final.weights
  std::string meshes;                   ///< `dataset synth --meshes`
  RecipeTrainOptions train;
  std::vector<RecipeDataset> datasets;
  std::vector<RecipeMix> mixes;
  std::vector<RecipeCfg> cfgs;
  std::vector<RecipeStage> stages;

  const RecipeDataset* dataset(const std::string& name) const;
  const RecipeMix* mix(const std::string& name) const;
  const RecipeCfg* cfg(const std::string& name) const;
  const RecipeStage* stage(const std::string& name) const;
};

/// Writes a data.yaml for `wingman train --data` / `wingman val --data`: `# comment` (when not empty), then path (made
/// absolute), train (a list; left out when empty), val, nc and names, with yaml-cpp. Throws std::runtime_error when
/// it cannot write `file`.
void write_data_yaml_mix(const std::string& file, const std::string& path, const std::vector<std::string>& train,
                         const std::string& val, const std::vector<std::string>& names, const std::string& comment);

/// Reads a recipe. `overrides` ("KEY=VALUE", e.g. "stage6.batches=800" for a stage's key, or "train.threads=4") are
/// set before reading (the value read as YAML). ${src} in a path becomes `src`. Every problem of the file is
/// reported at once: common::ConfigError with one "<file>:<line>: <key>: <problem>" line each.
Recipe load_recipe(const std::string& path, const std::vector<std::string>& overrides = {},
                   const std::string& src = ".");

struct RecipeRunOptions {
  std::string recipe;
  std::vector<std::string> overrides;
  std::string src = ".";                          ///< the source tree (${src}; tools/*)
  std::string data = "build/training-data";       ///< DATA
  std::string out = "build/train-wingman-small";  ///< OUT
  std::string bin;                                ///< the folder of the `wingman` to run (empty: this one's)
  std::string stage;                              ///< only this stage (the datasets it uses are still prepared)
  std::string init;                               ///< with `stage`: the weights it starts from, instead of its init
  bool data_only = false;                         ///< prepare the datasets, train nothing
  bool dry_run = false;                           ///< print the commands, run nothing
};

/// Runs the recipe stage by stage: prepares the datasets the active stages use (a complete one is kept), writes the
/// mixes and .cfg variants and trains each active stage that has no <model>_final.weights yet (--resume from its
/// checkpoint.pt). Every command is printed to `out` ("+ ..." lines) before it runs; with dry_run nothing runs.
/// Returns 0, or throws (std::invalid_argument / common::ConfigError: bad options or recipe; std::runtime_error: a
/// command failed).
int run_recipe(const RecipeRunOptions& options, std::ostream& out, std::ostream& err);

}  // namespace wingman::tools
