// SPDX-License-Identifier: MIT
// `wingman experiment`: experiment files read with common::YamlMappingReader (every problem at once), their scenarios
// written and flights planned before any flies, then flown with `wingman fly`'s plan_flight and fly, and summed up by
// tools/experiment_summary.py.
#include "wingman/tools/experiment.hpp"

#include "wingman/launcher/launch_setup.hpp"
#include "wingman/tools/scenario_edit.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>
#include <wingman/common/config.hpp>
#include <wingman/common/yaml_limits.hpp>
#include <wingman/common/yaml_mapping_reader.hpp>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace wingman::tools {

namespace fs = std::filesystem;
using common::YamlMappingReader;

namespace {

/// Lines of a failed flight's output shown on the terminal.
constexpr size_t kFailureTailLines = 20;

/// A visit() callback that reads every key of an options struct under a prefix of one mapping reader.
struct PrefixedReader {
  YamlMappingReader& r;
  std::string prefix;
  template <class T>
  void operator()(const std::string& key, T& value, const char* doc) {
    r(prefix + key, value, doc);
  }
};

/// Keys of a flight's `fly:` that wingman experiment sets itself.
const std::vector<std::string>& runner_keys() {
  static const std::vector<std::string> keys = {"flight.out", "flight.detections", "run.config_dir", "run.bin_dir",
                                                "run.lcm_url"};
  return keys;
}

/// Whether the reader has a leaf under `prefix` (a mapping given there).
bool has_under(const YamlMappingReader& r, const std::string& prefix, const std::vector<std::string>& keys) {
  for (const auto& k : keys)
    if (r.has(prefix + k)) return true;
  return false;
}

/// One part of a flight (its defaults, its own keys, or a quick: part) under `p` ("", "quick.", "defaults.", ...),
/// read over `f`: a key given replaces the value; scenario_set and rescore_match_radius_m are appended.
void read_flight_part(YamlMappingReader& r, const std::string& p, ExperimentFlight& f) {
  r(p + "run", f.run, "");
  r(p + "meshes", f.meshes, "");
  PrefixedReader fly{r, p + "fly."};
  f.fly.visit(fly);
  std::vector<std::string> sets;
  r(p + "scenario_set", sets, "");
  f.scenario_sets.insert(f.scenario_sets.end(), sets.begin(), sets.end());
  std::vector<double> radii;
  r(p + "rescore_match_radius_m", radii, "");
  f.rescore_match_radii_m.insert(f.rescore_match_radii_m.end(), radii.begin(), radii.end());

  const std::string rp = p + "scenario_random.";
  if (has_under(r, rp, {"seed", "airframe", "view", "lighting"})) {
    if (!f.random) f.random.emplace();
    r(rp + "seed", f.random->seed, "");
    r(rp + "airframe", f.random->airframe, "");
    r(rp + "view", f.random->view, "");
    r(rp + "lighting", f.random->lighting, "");
  }
  const std::string sp = p + "scenario_sweep.";
  if (has_under(r, sp, {"seed", "airframe", "view", "lighting", "from_m", "to_m", "step_m", "frames_per_step"})) {
    if (!f.sweep) f.sweep.emplace();
    r(sp + "seed", f.sweep->seed, "");
    r(sp + "airframe", f.sweep->airframe, "");
    r(sp + "view", f.sweep->view, "");
    r(sp + "lighting", f.sweep->lighting, "");
    r(sp + "from_m", f.sweep->from_m, "");
    r(sp + "to_m", f.sweep->to_m, "");
    r(sp + "step_m", f.sweep->step_m, "");
    r(sp + "frames_per_step", f.sweep->frames_per_step, "");
  }
}

/// A problem for each key under the parts `parts` of `r` that wingman experiment sets itself.
void check_runner_keys(YamlMappingReader& r, std::initializer_list<const char*> parts) {
  for (const char* p : parts) {
    for (const auto& k : runner_keys()) {
      if (r.has(std::string(p) + "fly." + k))
        r.problem(std::string(p) + "fly." + k, "wingman experiment sets this itself (its own options)");
    }
  }
}

/// The flight's problems that need all its parts: the runner's own keys, one scenario source, the values' rules.
void check_flight(YamlMappingReader& r, const ExperimentFlight& f, bool gave_scenario) {
  check_runner_keys(r, {"", "quick."});
  if (f.meshes != "any" && f.meshes != "required" && f.meshes != "absent")
    r.problem("meshes", fmt::format("'{}': expected any, required or absent", f.meshes));
  const int sources = (gave_scenario ? 1 : 0) + (f.random ? 1 : 0) + (f.sweep ? 1 : 0);
  if (sources > 1)
    r.problem("fly.flight.scenario", "give one scenario: fly.flight.scenario, scenario_random or scenario_sweep");
  if (!f.scenario_sets.empty() && (f.random || f.sweep))
    r.problem("scenario_set", "applies to a named scenario (fly.flight.scenario), not a drawn one");
  for (const double m : f.rescore_match_radii_m) {
    if (!(m > 0.0)) r.problem("rescore_match_radius_m", fmt::format("{}: expected metres > 0", m));
  }
  for (const auto& line : f.fly.validate()) r.validation_problem("fly." + line);
  // Their files are the runner's to name (TABLE/scenarios/NAME.yaml).
  if (f.random) {
    ScenarioRandomOptions named = *f.random;
    named.out = "named.yaml";
    for (const auto& line : named.validate()) r.problem("scenario_random", line);
  }
  if (f.sweep) {
    ScenarioSweepOptions named = *f.sweep;
    named.out = "named.yaml";
    for (const auto& line : named.validate()) r.problem("scenario_sweep", line);
  }
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw common::ConfigError(fmt::format("{}: cannot read the experiment file", path));
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// `name` as a file: itself when it names one (has a '/' or ends in .yaml), else config_dir/experiments/NAME.yaml.
std::string experiment_path(const std::string& name, const std::string& config_dir) {
  if (name.find('/') != std::string::npos || fs::path(name).extension() == ".yaml") return name;
  return (fs::path(config_dir) / "experiments" / (name + ".yaml")).string();
}

std::string meshes_dir(const ExperimentOptions& o) {
  if (!o.meshes.empty()) return fs::absolute(o.meshes).lexically_normal().string();
  if (const char* env = std::getenv("WINGMAN_SHARED_MESHES"); env != nullptr && *env != '\0')
    return fs::absolute(env).lexically_normal().string();
  return fs::absolute("../shared/meshes").lexically_normal().string();
}

std::string radius_text(double m) { return fmt::format("{:g}", m); }

/// A flight ready to fly: its plan and what is scored after it.
struct PlannedFlight {
  const ExperimentFlight* flight;
  FlightPlan plan;
  std::string dir;       ///< its folder
  std::string log_path;  ///< its output: FOLDER.log
};

struct PlannedTable {
  const ExperimentTable* table;
  std::string dir;
  std::vector<PlannedFlight> flights;
};

/// Writes the flight's scenario (a copy with scenario_set, a random draw or a sweep) and returns the FlyOptions to
/// plan: the file's, with the runner's keys.
FlyOptions flight_options(const ExperimentOptions& o, const ExperimentFlight& f, const std::string& table_dir,
                          const std::string& meshes, const std::string& bin_dir, std::ostream& err) {
  FlyOptions fly = f.fly;
  fly.out = (fs::path(table_dir) / f.name).string();
  fly.detections = o.detections;
  fly.config_dir = o.config_dir;
  fly.bin_dir = bin_dir;
  fly.lcm_url = o.lcm_url;
  if (o.duration_s > 0.0) fly.duration_s = o.duration_s;
  const fs::path scenarios = fs::path(table_dir) / "scenarios";
  if (f.random || f.sweep) {
    fs::create_directories(scenarios);
    const std::string file = (scenarios / (f.name + ".yaml")).string();
    ScenarioRandomResult r;
    if (f.random) {
      ScenarioRandomOptions ro = *f.random;
      ro.airframe = expand_meshes(ro.airframe, meshes);
      ro.out = file;
      r = write_random_scenario(ro);
      fly.follower_config = r.follower_path;
    } else {
      ScenarioSweepOptions so = *f.sweep;
      so.airframe = expand_meshes(so.airframe, meshes);
      so.out = file;
      r = write_sweep_scenario(so);
    }
    err << "experiment: " << r.one_line() << std::endl;
    fly.scenario = r.scenario_path;
    fly.localizer_config = r.localizer_path;
    fly.render_config = r.render_path;
  } else if (!f.scenario_sets.empty()) {
    // A copy named as the original, so that the flight finds its config/flights/NAME.* files.
    ScenarioSetOptions s;
    s.file = scenario_file(fly.scenario, o.config_dir);
    s.sets = f.scenario_sets;
    s.out = (scenarios / f.name / fs::path(s.file).filename()).string();
    fs::create_directories(fs::path(s.out).parent_path());
    write_scenario_copy(s);
    fly.scenario = s.out;
  }
  return fly;
}

/// Each process of the flight writes into its own file in the flight's folder (not the terminal).
void quiet_processes(FlightPlan& plan) {
  const auto to_file = [&](launcher::ProcessSpec& spec) {
    spec.stdout_path = (fs::path(plan.out_dir) / (spec.label() + ".out")).string();
    spec.stderr_to_stdout = true;
  };
  to_file(plan.logger);
  for (auto& p : plan.pipeline) to_file(p);
  to_file(plan.sim);
}

}  // namespace

std::vector<std::string> ExperimentOptions::validate() const {
  std::vector<std::string> e;
  if (names.empty()) e.emplace_back("experiment.names: give at least one experiment (wingman experiment --list)");
  if (detections != "cnn" && detections != "truth")
    e.push_back(fmt::format("experiment.detections = '{}': must be cnn or truth", detections));
  if (!(duration_s >= 0.0)) e.push_back(fmt::format("experiment.duration_s = {}: must be >= 0", duration_s));
  if (summary_script.empty()) e.emplace_back("run.summary_script: must not be empty");
  return e;
}

std::string expand_meshes(const std::string& text, const std::string& meshes_dir) {
  std::string s = text;
  const std::string token = "{meshes}";
  for (size_t at = s.find(token); at != std::string::npos; at = s.find(token, at + meshes_dir.size()))
    s.replace(at, token.size(), meshes_dir);
  return s;
}

Experiment read_experiment(const std::string& path, bool quick) {
  const std::string text = read_text(path);
  if (const std::string bad = common::check_yaml_bounds(text, path); !bad.empty()) throw common::ConfigError(bad);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw common::ConfigError(fmt::format("{}:{}: not valid YAML: {}", path, e.mark.line + 1, e.msg));
  }
  Experiment x;
  x.file = path;
  x.name = fs::path(path).stem().string();
  std::vector<std::string> problems;
  YamlMappingReader top(path, root, "", &problems);
  top("title", x.title, "");
  top("folder", x.folder, "");
  std::string quick_folder;
  top("quick.folder", quick_folder, "");
  if (quick && !quick_folder.empty()) x.folder = quick_folder;
  if (x.folder.empty()) x.folder = x.name;
  top("detections", x.detections, "");
  top("experiments", x.experiments, "");
  const auto tables = top.take_list("tables", x.experiments.empty());
  top.finish();
  if (!x.experiments.empty() && !tables.empty()) top.problem("experiments", "give either experiments or tables");
  for (const auto& d : x.detections) {
    if (d != "cnn" && d != "truth") top.problem("detections", fmt::format("'{}': expected cnn or truth", d));
  }
  if (fs::path(x.folder).is_absolute() || x.folder.find("..") != std::string::npos)
    top.problem("folder", fmt::format("'{}': expected a folder name under the output root", x.folder));

  std::set<std::string> names;
  std::set<std::string> folders;
  for (size_t t = 0; t < tables.size(); ++t) {
    ExperimentTable table;
    YamlMappingReader tr(path, tables[t], fmt::format("tables[{}].", t), &problems);
    tr("folder", table.folder, "");
    tr("summary", table.summary, "");
    tr("args", table.args, "");
    std::vector<std::string> quick_args;
    tr("quick.args", quick_args, "");
    if (quick) table.args.insert(table.args.end(), quick_args.begin(), quick_args.end());
    tr("inputs", table.inputs, "");
    const auto flights = tr.take_list("flights", true);
    // The defaults: read onto a scratch flight once, so that their keys are known and checked.
    ExperimentFlight scratch;
    read_flight_part(tr, "defaults.", scratch);
    read_flight_part(tr, "defaults.quick.", scratch);
    tr.finish();
    check_runner_keys(tr, {"defaults.", "defaults.quick."});
    if (table.summary.empty()) tr.problem("summary", "missing (a table of tools/experiment_summary.py)");
    if (table.inputs != "eval" && table.inputs != "folder")
      tr.problem("inputs", fmt::format("'{}': expected eval or folder", table.inputs));
    if (!folders.insert(table.folder).second) tr.problem("folder", fmt::format("'{}' twice", table.folder));

    for (size_t i = 0; i < flights.size(); ++i) {
      ExperimentFlight f;
      YamlMappingReader fr(path, flights[i], fmt::format("tables[{}].flights[{}].", t, i), &problems);
      read_flight_part(tr, "defaults.", f);
      fr("name", f.name, "");
      read_flight_part(fr, "", f);
      if (quick) {
        read_flight_part(tr, "defaults.quick.", f);
        read_flight_part(fr, "quick.", f);
      } else {
        ExperimentFlight unused = f;
        read_flight_part(fr, "quick.", unused);  // known and checked, not applied
      }
      fr.finish();
      if (f.name.empty()) {
        fr.problem("name", "missing");
      } else if (f.name.find('/') != std::string::npos || f.name == "." || f.name == ".." || f.name == "scenarios") {
        fr.problem("name", fmt::format("'{}': expected a folder name (not scenarios)", f.name));
      } else if (!names.insert(table.folder + "/" + f.name).second) {
        fr.problem("name", fmt::format("'{}' twice", f.name));
      }
      // A scenario the defaults name is the fallback for the flights that draw none.
      check_flight(fr, f, fr.has("fly.flight.scenario") || fr.has("quick.fly.flight.scenario"));
      table.flights.push_back(std::move(f));
    }
    x.tables.push_back(std::move(table));
  }
  if (!problems.empty()) {
    throw common::ConfigError(fmt::format("{} problem{} in the experiment:\n  {}", problems.size(),
                                          problems.size() == 1 ? "" : "s", fmt::join(problems, "\n  ")));
  }
  return x;
}

void list_experiments(const std::string& config_dir, std::ostream& out) {
  const fs::path dir = fs::path(config_dir) / "experiments";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw std::invalid_argument(fmt::format("no experiments folder {}", dir.string()));
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ".yaml") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    const Experiment x = read_experiment(f.string(), false);
    out << fmt::format(
               "{:<14} {}", x.name,
               x.experiments.empty() ? x.title : fmt::format("{} ({})", x.title, fmt::join(x.experiments, ", ")))
        << '\n';
  }
}

int run_experiments(const ExperimentOptions& o, std::ostream& out, std::ostream& err) {
  if (const auto bad = o.validate(); !bad.empty()) throw std::invalid_argument(fmt::format("{}", fmt::join(bad, "; ")));

  // Every experiment, a list file's included, read and checked before anything runs.
  std::vector<Experiment> experiments;
  std::vector<std::string> queue(o.names.rbegin(), o.names.rend());
  size_t expanded = 0;
  while (!queue.empty()) {
    const std::string name = queue.back();
    queue.pop_back();
    Experiment x = read_experiment(experiment_path(name, o.config_dir), o.quick);
    if (!x.experiments.empty()) {
      if (++expanded > 64) throw std::invalid_argument(fmt::format("{}: experiment lists nest too deep", x.file));
      queue.insert(queue.end(), x.experiments.rbegin(), x.experiments.rend());
      continue;
    }
    if (std::find(x.detections.begin(), x.detections.end(), o.detections) == x.detections.end()) {
      throw std::invalid_argument(fmt::format(
          "{} ({}) runs with --detections {} only (detections: in the file); it measures {}", x.name, x.file,
          fmt::join(x.detections, " or "), o.detections == "truth" ? "the detector" : "ground-truth boxes"));
    }
    experiments.push_back(std::move(x));
  }

  const std::string root =
      fs::absolute(o.out.empty() ? (o.detections == "truth" ? "build/experiments-truth" : "build/experiments") : o.out)
          .lexically_normal()
          .string();
  const std::string meshes = meshes_dir(o);
  const bool have_meshes = fs::is_directory(meshes);
  const std::string bin_dir = launcher::executables_dir(o.bin_dir, {"wingman", "wingman-sim"});
  if (!o.dry_run) launcher::private_bus_url(o.lcm_url, "wingman experiment", "tools/experiment.sh");

  int failures = 0;
  for (const Experiment& x : experiments) {
    const std::string dir = (fs::path(root) / x.folder).string();
    err << "experiment: " << x.name << (x.title.empty() ? "" : ": " + x.title) << std::endl;
    fs::remove_all(dir);
    fs::create_directories(dir);
    const auto needs_meshes = [](const ExperimentTable& t) {
      return std::any_of(t.flights.begin(), t.flights.end(),
                         [](const ExperimentFlight& f) { return f.run && f.meshes == "required"; });
    };
    if (!have_meshes && std::any_of(x.tables.begin(), x.tables.end(), needs_meshes)) {
      err << "experiment: " << x.name << ": no shared meshes (" << meshes << "): the flights that need them are skipped"
          << std::endl;
    }

    // Scenarios written and every flight planned (all plan_flight's checks) before the first flies.
    std::vector<PlannedTable> tables;
    size_t total = 0;
    for (const auto& t : x.tables) {
      PlannedTable pt{&t, t.folder.empty() ? dir : (fs::path(dir) / t.folder).string(), {}};
      fs::create_directories(pt.dir);
      for (const auto& f : t.flights) {
        if (!f.run || (f.meshes == "required" && !have_meshes) || (f.meshes == "absent" && have_meshes)) continue;
        FlightPlan plan = plan_flight(flight_options(o, f, pt.dir, meshes, bin_dir, err));
        quiet_processes(plan);
        const std::string fdir = (fs::path(pt.dir) / f.name).string();
        pt.flights.push_back({&f, std::move(plan), fdir, fdir + ".log"});
        ++total;
      }
      tables.push_back(std::move(pt));
    }
    if (o.dry_run) {
      for (const auto& pt : tables) {
        for (const auto& pf : pt.flights) {
          out << "# " << x.name << " / " << (pt.table->folder.empty() ? "" : pt.table->folder + " / ")
              << pf.flight->name << " (" << pf.dir << ")\n";
          for (const auto& line : pf.plan.notes) out << line << '\n';
          for (const auto& spec : pf.plan.pipeline) out << spec.command_line() << '\n';
          out << pf.plan.sim.command_line() << '\n';
        }
      }
      continue;
    }

    // The flights, one after the other.
    size_t done = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (auto& pt : tables) {
      for (auto& pf : pt.flights) {
        err << fmt::format("experiment: {}: flying {} ({} of {})", x.name, pf.flight->name, ++done, total);
        if (done > 1) {
          const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          err << fmt::format(", {:.0f} s so far", elapsed);
        }
        err << " ..." << std::endl;
        std::ofstream log(pf.log_path);
        const int rc = fly(pf.plan, log, log);
        log.close();
        if (rc == 130) {
          err << "experiment: interrupted during " << pf.flight->name << " (its output: " << pf.log_path << ")"
              << std::endl;
          return 130;
        }
        if (rc != 0) {
          err << launcher::output_tail(pf.log_path, kFailureTailLines) << "experiment: the flight " << pf.flight->name
              << " failed (exit " << rc << "; its output: " << pf.log_path << ", its processes' in " << pf.dir
              << "/*.out)" << std::endl;
          return 1;
        }
        for (const double m : pf.flight->rescore_match_radii_m) {
          // Scored again, matching targets within `m` of a vehicle (e.g. how far a lone leader's track is kept).
          EvalOptions e = pf.plan.eval;
          e.match_radius_m = m;
          e.report_path.clear();
          e.json_path = (fs::path(pf.dir) / ("eval_r" + radius_text(m) + ".json")).string();
          e.csv_path = (fs::path(pf.dir) / ("targets_r" + radius_text(m) + ".csv")).string();
          evaluate_log(e);
        }
      }
    }

    // The tables.
    for (const auto& pt : tables) {
      if (pt.flights.empty()) {
        err << "experiment: " << x.name << ": no flight of the table " << pt.dir << " ran: no table" << std::endl;
        ++failures;
        continue;
      }
      launcher::ProcessSpec py =
          launcher::process("experiment_summary", {"python3", o.summary_script, pt.table->summary, pt.dir});
      py.argv.insert(py.argv.end(), pt.table->args.begin(), pt.table->args.end());
      for (const auto& pf : pt.flights)
        py.argv.push_back(pt.table->inputs == "eval" ? (fs::path(pf.dir) / "eval.json").string() : pf.dir);
      const int rc = launcher::run_in_foreground(py);
      if (rc != 0) {
        err << "experiment: " << x.name << ": the table failed (exit " << rc << "): " << py.command_line() << std::endl;
        if (rc == 130 || rc == 128 + 2) return 130;
        ++failures;
      }
    }
  }
  if (!o.dry_run) err << "experiment: results in " << root << std::endl;
  return failures == 0 ? 0 : 1;
}

}  // namespace wingman::tools
