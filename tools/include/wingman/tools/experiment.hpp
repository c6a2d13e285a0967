// SPDX-License-Identifier: MIT
// `wingman experiment`: the thesis's experiments and the out-of-sample suite as data (config/experiments/*.yaml): which
// flights, over which scenarios, with which settings, and which table sums them up.
#pragma once

#include "wingman/tools/fly.hpp"
#include "wingman/tools/scenario_random.hpp"

#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace wingman::tools {

/// How `wingman experiment` runs. Read from layered files and `--set` (the one loader in common, keys below) with the
/// command line's flags over them; relative paths are taken from the working directory (tools/experiment.sh runs it
/// from the checkout's root).
struct ExperimentOptions {
  /// Experiments to run, in order: NAME (config_dir/experiments/NAME.yaml) or an experiment file.
  std::vector<std::string> names;
  bool quick = false;              ///< each flight's and table's `quick:` over it (short flights: a check, not results)
  std::string out;                 ///< output root ("" = build/experiments, or build/experiments-truth with truth)
  std::string detections = "cnn";  ///< cnn (the shipped model on rendered images) or truth (ground-truth boxes)
  double duration_s = 0.0;         ///< > 0: fly only the first this many seconds of every flight
  /// The four shared airframes ("" = $WINGMAN_SHARED_MESHES, else ../shared/meshes): `{meshes}` in a file, and what
  /// decides the flights marked `meshes: required` or `meshes: absent`.
  std::string meshes;
  bool dry_run = false;  ///< write the scenarios and plan every flight (all checks), print the plans; fly nothing
  std::string summary_script = "tools/experiment_summary.py";  ///< the tables (Python, run with python3)
  std::string config_dir = "config";  ///< the checkout's config/ (experiments, scenarios, flights)
  std::string bin_dir;                ///< the executables ("" = the folder of the running wingman)
  std::string lcm_url;                ///< the bus ("" = $WINGMAN_LCM_URL, set by tools/netns_run.sh)

  template <class V>
  void visit(V& v) {
    v("experiment.names", names, "experiments in order: NAME (run.config_dir/experiments/NAME.yaml) or a file");
    v("experiment.quick", quick, "short flights and sparse sweeps (each file's quick: parts): a check, not results");
    v("experiment.out", out, "output root; \"\" = build/experiments (build/experiments-truth with truth)");
    v("experiment.detections", detections, "cnn (the shipped model on rendered images) or truth (ground-truth boxes)");
    v("experiment.duration_s", duration_s, "fly only the first this many seconds of every flight; 0 = their own");
    v("experiment.meshes", meshes,
      "the shared airframes' folder; \"\" = $WINGMAN_SHARED_MESHES, else ../shared/meshes (absent: those skipped)");
    v("experiment.dry_run", dry_run, "write the scenarios and plan every flight, print the plans, fly nothing");
    v("run.summary_script", summary_script, "the tables: tools/experiment_summary.py (python3)");
    v("run.config_dir", config_dir, "the checkout's config folder (experiments, scenarios, flights)");
    v("run.bin_dir", bin_dir, "the executables; \"\" = the folder of this wingman");
    v("run.lcm_url", lcm_url, "the LCM bus; \"\" = $WINGMAN_LCM_URL (tools/netns_run.sh sets it)");
  }
  /// Every problem with the values alone, one line each naming the key.
  std::vector<std::string> validate() const;
};

/// One flight of an experiment as its file gives it, with the `quick:` parts applied or not.
struct ExperimentFlight {
  std::string name;  ///< its folder in the table's folder; unique in the experiment
  bool run = true;   ///< `run`: false leaves it out (in this mode)
  /// `meshes`: any (always flies), required (only with the shared meshes: they are in it), absent (only without them:
  /// a stand-in for a flight that needs them).
  std::string meshes = "any";
  FlyOptions fly;                          ///< `fly:` (FlyOptions keys, as `wingman fly --print-config` shows them)
  std::vector<std::string> scenario_sets;  ///< `scenario_set:` KEY=VALUE over fly's scenario (`wingman scenario set`)
  /// `scenario_random:` (seed, airframe, view, lighting): the scenario is drawn (`wingman scenario random`) and flown
  /// with the localizer, follower and render files drawn beside it.
  std::optional<ScenarioRandomOptions> random;
  /// `scenario_sweep:` (seed, airframe, view, lighting, from_m, to_m, step_m, frames_per_step): a range sweep
  /// (`wingman scenario sweep`) flown with the localizer and render files beside it.
  std::optional<ScenarioSweepOptions> sweep;
  std::vector<double> rescore_match_radii_m;  ///< `rescore_match_radius_m:` also scored with these match radii
};

/// One table of an experiment: its flights and the summary over them.
struct ExperimentTable {
  std::string folder;             ///< under the experiment's folder ("" = the experiment's folder itself)
  std::string summary;            ///< tools/experiment_summary.py KIND
  std::vector<std::string> args;  ///< the summary's arguments before the flights' (the quick part's appended)
  std::string inputs = "eval";    ///< per flight flown, in order: its eval.json (eval) or its folder (folder)
  std::vector<ExperimentFlight> flights;
};

/// An experiment file (config/experiments/NAME.yaml), read for one mode (quick or not).
struct Experiment {
  std::string name;    ///< the file's stem
  std::string file;    ///< the file read
  std::string title;   ///< one line, printed before it runs
  std::string folder;  ///< under the output root ("" = name; the quick part may give another)
  std::vector<std::string> detections = {"cnn"};  ///< the detections it can run with
  std::vector<std::string> experiments;           ///< a list file (`experiments:`): these names, in order; no tables
  std::vector<ExperimentTable> tables;
};

/// Reads `path` for the mode `quick`. In a table, each flight is read as: the table's `defaults:`, the flight's own
/// keys, then with `quick` the defaults' `quick:` and the flight's `quick:` (a later part replaces a key; the
/// `scenario_set` and `rescore_match_radius_m` lists are appended). Throws common::ConfigError naming the file, and for
/// each problem the line and key (every problem at once): unknown keys, wrong types, a flight's FlyOptions::validate()
/// lines, duplicate flight names, a flight with more than one scenario source.
Experiment read_experiment(const std::string& path, bool quick);

/// `{meshes}` in `text` replaced by `meshes_dir`.
std::string expand_meshes(const std::string& text, const std::string& meshes_dir);

/// Prints one line per experiment file in `config_dir`/experiments: its name and title (a list file: its
/// experiments). Throws common::ConfigError for a file that does not read.
void list_experiments(const std::string& config_dir, std::ostream& out);

/// Runs `options`: reads every experiment (a list file's too) and checks them all first, then each in turn: clears its
/// folder, writes its scenarios (copies, random draws, sweeps) and plans all its flights (every check plan_flight
/// makes), flies them one by one (each flight's output in FOLDER.log beside its folder, the last lines shown when it
/// fails), and writes each table with the summary script. Progress on `err`, the plans (dry run) and results on `out`.
/// Returns 0, 1 when a flight or a summary failed (a summary's bounds included), 130 when interrupted; throws
/// std::invalid_argument or common::ConfigError for bad options or files before anything flies.
int run_experiments(const ExperimentOptions& options, std::ostream& out, std::ostream& err);

}  // namespace wingman::tools
