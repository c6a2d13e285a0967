// SPDX-License-Identifier: MIT
// Training recipes: read with common::YamlMappingReader (every problem at once), run stage by stage as child
// processes of the other `wingman` verbs.
#include "wingman/tools/recipe.hpp"

#include "wingman/launcher/launch_setup.hpp"

#include <wingman/common/config.hpp>
#include <wingman/common/yaml_mapping_reader.hpp>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <stdexcept>

namespace wingman::tools {

namespace {

namespace fs = std::filesystem;
using common::YamlMappingReader;

template <class T>
const T* find_named(const std::vector<T>& items, const std::string& name) {
  for (const T& t : items)
    if (t.name == name) return &t;
  return nullptr;
}

std::string substitute(std::string s, const std::string& src) {
  for (size_t at = s.find("${src}"); at != std::string::npos; at = s.find("${src}", at + src.size()))
    s.replace(at, 6, src);
  return s;
}

/// Sets "a.b=value" in `root`: a first component naming a stage addresses that stage's mapping.
void apply_override(YAML::Node root, const std::string& item, std::vector<std::string>& problems,
                    const std::string& path) {
  const size_t eq = item.find('=');
  if (eq == std::string::npos || eq == 0) {
    problems.push_back(fmt::format("{}: --set '{}': expected KEY=VALUE", path, item));
    return;
  }
  std::vector<std::string> keys;
  for (size_t b = 0, e; b <= eq; b = e + 1) {
    e = std::min(item.find('.', b), eq);
    keys.push_back(item.substr(b, e - b));
  }
  YAML::Node value;
  try {
    value = YAML::Load(item.substr(eq + 1));
  } catch (const YAML::Exception& e) {
    problems.push_back(fmt::format("{}: --set '{}': not a YAML value: {}", path, item, e.msg));
    return;
  }
  YAML::Node node = root;
  size_t k = 0;
  if (keys.size() > 1 && root["stages"].IsSequence()) {
    for (YAML::Node s : root["stages"])
      if (s.IsMap() && s["name"] && s["name"].Scalar() == keys[0]) {
        node.reset(s);  // (node = s would replace root's content: yaml-cpp assigns through a node)
        k = 1;
        break;
      }
  }
  for (; k + 1 < keys.size(); ++k) {
    YAML::Node child = node[keys[k]];
    node.reset(child);
  }
  node[keys.back()] = value;
}

}  // namespace

const RecipeDataset* Recipe::dataset(const std::string& name) const { return find_named(datasets, name); }
const RecipeMix* Recipe::mix(const std::string& name) const { return find_named(mixes, name); }
const RecipeCfg* Recipe::cfg(const std::string& name) const { return find_named(cfgs, name); }
const RecipeStage* Recipe::stage(const std::string& name) const { return find_named(stages, name); }

void write_data_yaml_mix(const std::string& file, const std::string& path, const std::vector<std::string>& train,
                         const std::string& val, const std::vector<std::string>& names, const std::string& comment) {
  if (val.empty()) throw std::invalid_argument("a data.yaml needs a val entry");
  if (names.empty()) throw std::invalid_argument("a data.yaml needs class names");
  YAML::Emitter e;
  e << YAML::BeginMap << YAML::Key << "path" << YAML::Value << fs::absolute(path).lexically_normal().string();
  if (!train.empty()) e << YAML::Key << "train" << YAML::Value << YAML::Flow << train;
  e << YAML::Key << "val" << YAML::Value << val;
  e << YAML::Key << "nc" << YAML::Value << names.size();
  e << YAML::Key << "names" << YAML::Value << YAML::Flow << names << YAML::EndMap;
  if (const fs::path parent = fs::path(file).parent_path(); !parent.empty()) fs::create_directories(parent);
  std::ofstream f(file);
  if (!comment.empty()) f << "# " << comment << "\n";
  f << e.c_str() << "\n";
  if (!f.flush()) throw std::runtime_error(fmt::format("{}: cannot write the data.yaml", file));
}

Recipe load_recipe(const std::string& path, const std::vector<std::string>& overrides, const std::string& src) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw common::ConfigError(fmt::format("{}: cannot read the recipe", path));
  } catch (const YAML::Exception& e) {
    throw common::ConfigError(fmt::format("{}:{}: not valid YAML: {}", path, e.mark.line + 1, e.msg));
  }
  std::vector<std::string> problems;
  for (const std::string& o : overrides) apply_override(root, o, problems, path);

  Recipe r;
  r.path = path;
  YamlMappingReader top(path, root, "", &problems);
  std::string halmstad = "${src}/../shared/datasets/halmstad";
  top("model", r.model, "");
  top("meshes", r.meshes, "");
  top("halmstad", halmstad, "");
  RecipeTrainOptions& t = r.train;
  top("train.threads", t.threads, "");
  top("train.scales", t.scales, "");
  top("train.scale", t.scale, "");
  top("train.translate", t.translate, "");
  top("train.blur", t.blur, "");
  top("train.noise", t.noise, "");
  top("train.checkpoint_interval", t.checkpoint_interval, "");
  top("train.log_interval", t.log_interval, "");
  top("train.val_max_images", t.val_max_images, "");
  const auto datasets = top.take_list("datasets", true);
  const auto mixes = top.take_list("mixes", true);
  const auto cfgs = top.take_list("cfgs", false);
  const auto stages = top.take_list("stages", true);
  top.finish();
  if (t.threads < 1) top.problem("train.threads", "expected at least 1");

  const auto named = [&](YamlMappingReader& m, std::string& name, auto& seen) {
    m("name", name, "");
    if (name.empty())
      m.problem("name", "missing");
    else if (!seen.insert(name).second)
      m.problem("name", fmt::format("'{}' twice", name));
  };
  std::set<std::string> seen;
  for (size_t i = 0; i < datasets.size(); ++i) {
    YamlMappingReader m(path, datasets[i], fmt::format("datasets[{}].", i), &problems);
    RecipeDataset d;
    named(m, d.name, seen);
    m("kind", d.kind, "");
    m("seed", d.seed, "");
    if (d.kind == "halmstad") {
      d.source = halmstad;
      m("source", d.source, "");
      m("distractor_classes", d.distractor_classes, "");
      m("negative_frame_step", d.negative_frame_step, "");
    } else if (d.kind == "synth") {
      m("config", d.config, "");
      const size_t before = problems.size();
      m("count", d.count, "");
      if (d.config.empty()) m.problem("config", "missing");
      if (d.count < 1 && problems.size() == before) m.problem("count", "expected at least 1 image");
    } else if (d.kind == "flights") {
      const size_t before = problems.size();
      m("count", d.count, "");
      m("duration_s", d.duration_s, "");
      m("every", d.every, "");
      m("val", d.val, "");
      if (d.count < 1 && problems.size() == before) m.problem("count", "expected at least 1 flight");
      for (const int v : d.val)
        if (v < 0 || v >= d.count) m.problem("val", fmt::format("flight {}: expected 0..{}", v, d.count - 1));
    } else {
      m.problem("kind", fmt::format("'{}': expected halmstad, synth or flights", d.kind));
    }
    m.finish(d.kind.empty() ? "" : fmt::format(" (of a {} dataset)", d.kind));
    d.source = substitute(d.source, src);
    d.config = substitute(d.config, src);
    r.datasets.push_back(d);
  }
  seen.clear();
  for (size_t i = 0; i < mixes.size(); ++i) {
    YamlMappingReader m(path, mixes[i], fmt::format("mixes[{}].", i), &problems);
    RecipeMix x;
    named(m, x.name, seen);
    m("comment", x.comment, "");
    m("train", x.train, "");
    m("val", x.val, "");
    m("names", x.names, "");
    m.finish();
    for (const std::string& d : x.train)
      if (!r.dataset(d)) m.problem("train", fmt::format("'{}': no such dataset", d));
    if (!r.dataset(x.val)) m.problem("val", fmt::format("'{}': no such dataset", x.val));
    if (x.names.empty()) m.problem("names", "missing");
    r.mixes.push_back(x);
  }
  seen.clear();
  for (size_t i = 0; i < cfgs.size(); ++i) {
    YamlMappingReader m(path, cfgs[i], fmt::format("cfgs[{}].", i), &problems);
    RecipeCfg c;
    named(m, c.name, seen);
    m("from", c.from, "");
    m("heads", c.heads, "");
    m("anchors", c.anchors, "");
    m("input", c.input, "");
    m.finish();
    if (c.from.empty()) m.problem("from", "missing");
    if (!c.input.empty() && c.input.size() != 2) m.problem("input", "expected [width, height]");
    if (c.anchors.size() % 2 != 0) m.problem("anchors", "expected w, h pairs");
    if (!r.cfg(c.from)) c.from = substitute(c.from, src);  // an earlier variant or a path
    r.cfgs.push_back(c);
  }
  seen.clear();
  std::set<std::string> prepared;
  for (size_t i = 0; i < stages.size(); ++i) {
    YamlMappingReader m(path, stages[i], fmt::format("stages[{}].", i), &problems);
    RecipeStage s;
    named(m, s.name, seen);
    m("prepare", s.prepare, "");
    m("cfg", s.cfg, "");
    m("iou_loss", s.iou_loss, "");
    m("iou_normalizer", s.iou_normalizer, "");
    m("widen.cfg", s.widen.cfg, "");
    m("widen.weights", s.widen.weights, "");
    m("widen.classes", s.widen.classes, "");
    m("widen.iou_loss", s.widen.iou_loss, "");
    m("widen.iou_normalizer", s.widen.iou_normalizer, "");
    m("mix", s.mix, "");
    m("out", s.out, "");
    m("init", s.init, "");
    m("partial_weights", s.partial_weights, "");
    m("batches", s.batches, "");
    m("burn_in", s.burn_in, "");
    m("learning_rate", s.learning_rate, "");
    m("steps_percent", s.steps_percent, "");
    m("weights_interval", s.weights_interval, "");
    m("ema_decay", s.ema_decay, "");
    m.finish();
    for (const std::string& d : s.prepare) {
      if (!r.dataset(d)) m.problem("prepare", fmt::format("'{}': no such dataset", d));
      prepared.insert(d);
    }
    if (s.widen.classes > 0) {
      if (s.widen.cfg.empty() || s.widen.weights.empty()) m.problem("widen", "needs cfg and weights");
      if (!s.cfg.empty()) m.problem("cfg", "a stage with widen trains the widened .cfg");
    } else if (s.cfg.empty()) {
      m.problem("cfg", "missing");
    }
    s.cfg = r.cfg(s.cfg) ? s.cfg : substitute(s.cfg, src);
    s.widen.cfg = substitute(s.widen.cfg, src);
    s.widen.weights = substitute(s.widen.weights, src);
    if (!s.iou_loss.empty() && s.iou_loss != "mse" && s.iou_loss != "giou" && s.iou_loss != "diou" &&
        s.iou_loss != "ciou")
      m.problem("iou_loss", fmt::format("'{}': expected mse, giou, diou or ciou", s.iou_loss));
    if (const RecipeMix* x = r.mix(s.mix); !x) {
      m.problem("mix", fmt::format("'{}': no such mix", s.mix));
    } else {
      std::vector<std::string> used = x->train;
      used.push_back(x->val);
      for (const std::string& d : used)
        if (r.dataset(d) && !prepared.count(d))
          m.problem("mix", fmt::format("'{}' uses {}, which neither this stage nor an earlier one prepares", s.mix, d));
    }
    if (s.out.empty()) m.problem("out", "expected a folder under OUT ('.': OUT itself)");
    if (s.batches < 0) m.problem("batches", "expected 0 (stop before this stage) or more");
    for (const std::string& init : s.init) {
      const size_t colon = init.find(':');
      if (colon != std::string::npos && !r.stage(init.substr(0, colon)) && init.find('/') == std::string::npos)
        m.problem("init", fmt::format("'{}': no earlier stage {}", init, init.substr(0, colon)));
    }
    for (std::string& init : s.init) init = substitute(init, src);
    if (s.batches > 0) {
      // The rate steps must increase (the trainer's rule): N = 0, or large enough for these percentages.
      int last = 0;
      for (const int p : s.steps_percent) {
        const int step = static_cast<int>(static_cast<long long>(s.batches) * p / 100);
        if (step <= last || p >= 100) {
          m.problem("batches", fmt::format("{}: the rate steps at {} % of it must increase and stay below it",
                                           s.batches, fmt::join(s.steps_percent, ", ")));
          break;
        }
        last = step;
      }
    }
    r.stages.push_back(s);
  }
  r.meshes = substitute(r.meshes, src);
  if (!problems.empty())
    throw common::ConfigError(fmt::format("{} problem{} in the recipe:\n  {}", problems.size(),
                                          problems.size() == 1 ? "" : "s", fmt::join(problems, "\n  ")));
  return r;
}

namespace {

/// A word as a POSIX shell reads it back.
using launcher::shell_word;

std::string num(double v) { return fmt::format("{}", v); }

class Runner {
 public:
  Runner(const RecipeRunOptions& o, const Recipe& r, std::ostream& out) : o_(o), r_(r), out_(out) {
    wingman_ = (fs::path(o.bin) / "wingman").string();
  }

  int run() {
    // The stages walked: up to the first with batches 0. The active ones: all of those, or --stage.
    std::vector<const RecipeStage*> walk;
    for (const RecipeStage& s : r_.stages) {
      if (s.batches == 0) break;
      walk.push_back(&s);
    }
    std::vector<const RecipeStage*> active = walk;
    if (!o_.stage.empty()) {
      if (!r_.stage(o_.stage))
        throw std::invalid_argument(fmt::format("--stage {}: {} has no such stage", o_.stage, r_.path));
      active.clear();
      for (const RecipeStage* s : walk)
        if (s->name == o_.stage) active.push_back(s);
      if (active.empty())
        throw std::invalid_argument(
            fmt::format("--stage {}: not reached (it or an earlier stage has batches 0)", o_.stage));
      walk.resize(static_cast<size_t>(std::find(walk.begin(), walk.end(), active[0]) - walk.begin()) + 1);
    }
    for (const RecipeStage* s : active) {
      const RecipeMix& x = *r_.mix(s->mix);
      used_.insert(x.train.begin(), x.train.end());
      used_.insert(x.val);
    }
    if (!o_.dry_run) check_tools();
    for (const RecipeStage* s : walk) {
      for (const std::string& d : s->prepare)
        if (used_.count(d) && prepared_.insert(d).second) prepare(*r_.dataset(d));
      if (std::find(active.begin(), active.end(), s) == active.end()) continue;
      write_mix(*r_.mix(s->mix));
      if (!o_.data_only) train(*s);
    }
    if (o_.data_only) out_ << "train-recipe: the datasets are ready in " << o_.data << "\n";
    return 0;
  }

 private:
  struct Command {
    std::vector<std::string> argv;
    std::vector<std::pair<std::string, std::string>> env;
    std::string output;  // stdout and stderr to this file ("": inherited)
  };

  void check_tools() {
    for (const std::string& d : used_)
      if (const RecipeDataset* ds = r_.dataset(d); ds->kind == "halmstad" && !fs::is_directory(ds->source))
        throw std::invalid_argument(fmt::format("{} is missing (the Halmstad videos)", ds->source));
    if (exec(Command{{wingman_, "train", "--help"}, {}, "/dev/null"}, false) != 0)
      throw std::invalid_argument(
          fmt::format("{} has no trainer: build with -DWINGMAN_WITH_TRAINING=ON (libtorch-dev)", wingman_));
    fs::create_directories(o_.data);
    fs::create_directories(o_.out);
  }

  void note(const std::string& line) { out_ << "+ " << line << std::endl; }

  /// Prints and (unless dry-run) runs a command; throws when it fails.
  void run(const Command& c) {
    std::string line;
    for (const auto& [k, v] : c.env) line += k + "=" + shell_word(v) + " ";
    for (size_t i = 0; i < c.argv.size(); ++i) line += (i ? " " : "") + shell_word(c.argv[i]);
    if (!c.output.empty()) line += " > " + shell_word(c.output) + " 2>&1";
    note(line);
    if (o_.dry_run) return;
    const int rc = exec(c, true);
    if (rc != 0)
      throw std::runtime_error(fmt::format("{} exited with {}{}",
                                           c.argv[0] == wingman_ ? "wingman " + c.argv[1] : c.argv[0], rc,
                                           c.output.empty() ? "" : " (log: " + c.output + ")"));
  }

  /// Runs `c` to its end as system() does (launcher::run_in_foreground: Ctrl-C reaches the child, the trainer saves
  /// its checkpoint and stops, and this process then reports its exit). A program that cannot start: 127.
  static int exec(const Command& c, bool report) {
    std::cout.flush();
    launcher::ProcessSpec spec;
    spec.argv = c.argv;
    for (const auto& [k, v] : c.env) spec.env.push_back(k + "=" + v);
    spec.stdout_path = c.output;
    spec.stderr_to_stdout = !c.output.empty();
    try {
      return launcher::run_in_foreground(spec);
    } catch (const std::runtime_error& e) {
      if (report) std::cerr << "train-recipe: " << e.what() << std::endl;
      return 127;
    }
  }

  void remove_all(const fs::path& p) {
    if (!fs::exists(p)) return;
    note("rm -rf " + shell_word(p.string()));
    if (!o_.dry_run) fs::remove_all(p);
  }
  void touch(const fs::path& p) {
    note("touch " + shell_word(p.string()));
    if (!o_.dry_run) std::ofstream(p).flush();
  }

  void prepare(const RecipeDataset& d) {
    const fs::path dir = fs::path(o_.data) / d.name;
    if (d.kind == "flights") return prepare_flights(d, dir);
    if (fs::exists(dir / "data.yaml")) return;
    remove_all(dir);
    if (d.kind == "halmstad") {
      Command c{{wingman_, "import-halmstad", d.source, dir.string()}, {}, ""};
      if (d.distractor_classes) c.argv.push_back("--distractor-classes");
      if (d.negative_frame_step > 0) {
        c.argv.push_back("--negative-frame-step");
        c.argv.push_back(std::to_string(d.negative_frame_step));
      }
      return run(c);
    }
    Command c{{wingman_, "dataset", "synth", "--out", dir.string(), "--count", std::to_string(d.count), "--seed",
               std::to_string(d.seed), "--config", d.config},
              {},
              ""};
    if (!r_.meshes.empty()) c.argv.insert(c.argv.end(), {"--meshes", r_.meshes});
    run(c);
  }

  /// Training flights (kept per flight: an interrupted run keeps the flights it finished; the big logs go).
  void prepare_flights(const RecipeDataset& d, const fs::path& dir) {
    if (fs::exists(dir / ".complete")) return;
    const fs::path logs = fs::path(o_.data) / "flight-logs";
    run({{"python3", (fs::path(o_.src) / "tools/make_training_flights.py").string(), "--out",
          (logs / "scenarios").string(), "--count", std::to_string(d.count), "--seed", std::to_string(d.seed),
          "--duration", std::to_string(d.duration_s)},
         {},
         ""});
    for (int k = 0; k < d.count; ++k) {
      const std::string name = fmt::format("train_flight_{:02d}", k);
      if (fs::exists(logs / (name + ".done"))) continue;
      remove_all(logs / name);
      note(fmt::format("rm -f {0}/images/*/{1}_* {0}/labels/*/{1}_*", shell_word(dir.string()), name));
      if (!o_.dry_run)
        for (const char* sub : {"images", "labels"}) {
          std::error_code ec;
          if (!fs::is_directory(dir / sub)) continue;
          for (const auto& split : fs::directory_iterator(dir / sub, ec))
            for (const auto& f : fs::directory_iterator(split.path(), ec))
              if (f.path().filename().string().rfind(name + "_", 0) == 0) fs::remove(f.path(), ec);
        }
      const fs::path flight = logs / name;
      run({{(fs::path(o_.src) / "tools/fly.sh").string(), "--scenario",
            (logs / "scenarios" / (name + ".yaml")).string(), "--out", flight.string(), "--detections", "truth",
            "--truth-box", "silhouette", "--render", "--record-images"},
           {{"WINGMAN_BIN_DIR", o_.bin}},
           (logs / (name + ".log")).string()});
      const fs::path log = flight / (name + ".lcmlog");
      note(fmt::format("mv {} {}", shell_word((flight / "flight.lcmlog").string()), shell_word(log.string())));
      if (!o_.dry_run) fs::rename(flight / "flight.lcmlog", log);
      const bool val = std::find(d.val.begin(), d.val.end(), k) != d.val.end();
      run({{wingman_, "dataset", "from-log", log.string(), "--out", dir.string(), "--split", val ? "val" : "train",
            "--every", std::to_string(d.every)},
           {},
           ""});
      note("rm -f " + shell_word(log.string()));
      if (!o_.dry_run) fs::remove(log);
      touch(logs / (name + ".done"));
    }
    touch(dir / ".complete");
  }

  /// DATA/<mix>.yaml, a data.yaml for `wingman train --data` (written every run, as the datasets are).
  void write_mix(const RecipeMix& x) {
    const fs::path file = fs::path(o_.data) / (x.name + ".yaml");
    note(fmt::format("write {} (train: {}; val: {})", shell_word(file.string()), fmt::join(x.train, ", "), x.val));
    if (o_.dry_run) return;
    std::vector<std::string> train;
    for (const std::string& d : x.train) train.push_back(d + "/images/train");
    write_data_yaml_mix(file.string(), o_.data, train, x.val + "/images/val", x.names, x.comment);
  }

  /// The path of a .cfg variant (derived this run, once) or of a .cfg file.
  std::string cfg_path(const std::string& name) {
    const RecipeCfg* c = r_.cfg(name);
    if (!c) return name;
    const std::string path = (fs::path(o_.out) / c->name / (r_.model + ".cfg")).string();
    if (derived_.insert(name).second) {
      Command cmd{{wingman_, "model", "derive-cfg", "--cfg", cfg_path(c->from), "--out", path}, {}, ""};
      if (c->heads > 0) cmd.argv.insert(cmd.argv.end(), {"--heads", std::to_string(c->heads)});
      if (!c->anchors.empty())
        cmd.argv.insert(cmd.argv.end(), {"--anchors", fmt::format("{}", fmt::join(c->anchors, ","))});
      if (!c->input.empty())
        cmd.argv.insert(cmd.argv.end(), {"--input", fmt::format("{}x{}", c->input[0], c->input[1])});
      run(cmd);
    }
    return path;
  }

  std::string weights_path(const std::string& ref) const {
    const size_t colon = ref.find(':');
    if (colon == std::string::npos || ref.find('/') != std::string::npos) return ref;
    const RecipeStage* s = r_.stage(ref.substr(0, colon));
    return (stage_out(*s) / fmt::format("{}_{}.weights", r_.model, ref.substr(colon + 1))).string();
  }

  fs::path stage_out(const RecipeStage& s) const { return s.out == "." ? fs::path(o_.out) : fs::path(o_.out) / s.out; }

  void train(const RecipeStage& s) {
    out_ << "# stage " << s.name << ": " << s.batches << " iterations into " << stage_out(s).string() << std::endl;
    const fs::path out = stage_out(s);
    std::string cfg, init;
    if (s.widen.classes > 0) {
      cfg = (out / "init" / (r_.model + ".cfg")).string();
      init = (out / "init" / (r_.model + ".weights")).string();
      if (!fs::exists(init)) {
        Command c{{wingman_, "model", "widen-classes", "--cfg", s.widen.cfg, "--weights", s.widen.weights, "--classes",
                   std::to_string(s.widen.classes)},
                  {},
                  ""};
        if (!s.widen.iou_loss.empty()) c.argv.insert(c.argv.end(), {"--iou-loss", s.widen.iou_loss});
        if (!s.widen.iou_normalizer.empty()) c.argv.insert(c.argv.end(), {"--iou-normalizer", s.widen.iou_normalizer});
        c.argv.insert(c.argv.end(), {"--out-cfg", cfg, "--out-weights", init});
        run(c);
      }
    } else {
      cfg = cfg_path(s.cfg);
      if (!s.iou_loss.empty() && s.iou_loss != "mse") {
        // A copy with the box loss in every [yolo]; it keeps the cfg's name (the trainer names its files after it).
        const std::string normalizer = s.iou_normalizer.empty() ? "0.75" : s.iou_normalizer;
        const std::string variant = s.iou_loss + (normalizer == "0.75" ? "" : "-" + normalizer);
        const std::string path = (fs::path(o_.out) / ("cfg-" + variant) / (r_.model + ".cfg")).string();
        if (derived_.insert("cfg-" + variant).second)
          run({{wingman_, "model", "derive-cfg", "--cfg", cfg, "--out", path, "--iou-loss", s.iou_loss,
                "--iou-normalizer", normalizer},
               {},
               ""});
        cfg = path;
      }
      for (const std::string& candidate : s.init) {
        init = weights_path(candidate);
        if (fs::exists(init)) break;
      }
    }
    if (fs::exists(out / (r_.model + "_final.weights"))) {
      out_ << "# stage " << s.name << ": done (" << (out / (r_.model + "_final.weights")).string() << ")\n";
      return;
    }
    const RecipeTrainOptions& t = r_.train;
    Command c{{wingman_,
               "train",
               "--cfg",
               cfg,
               "--threads",
               std::to_string(t.threads),
               "--scales",
               t.scales,
               "--scale",
               num(t.scale),
               "--translate",
               num(t.translate),
               "--blur",
               num(t.blur),
               "--noise",
               num(t.noise),
               "--checkpoint-interval",
               std::to_string(t.checkpoint_interval),
               "--log-interval",
               std::to_string(t.log_interval),
               "--val-max-images",
               std::to_string(t.val_max_images),
               "--data",
               (fs::path(o_.data) / (s.mix + ".yaml")).string(),
               "--out",
               out.string()},
              {},
              ""};
    if (!init.empty()) c.argv.insert(c.argv.end(), {"--weights", init});
    if (s.partial_weights) c.argv.push_back("--partial-weights");
    std::vector<std::string> steps;
    for (const int p : s.steps_percent) steps.push_back(std::to_string(static_cast<long long>(s.batches) * p / 100));
    c.argv.insert(c.argv.end(),
                  {"--max-batches", std::to_string(s.batches), "--burn-in", std::to_string(s.burn_in),
                   "--learning-rate", num(s.learning_rate), "--steps", fmt::format("{}", fmt::join(steps, ",")),
                   "--weights-interval", std::to_string(s.weights_interval)});
    if (!s.ema_decay.empty()) c.argv.insert(c.argv.end(), {"--ema-decay", s.ema_decay});
    if (fs::exists(out / "checkpoint.pt")) c.argv.push_back("--resume");
    run(c);
  }

  const RecipeRunOptions& o_;
  const Recipe& r_;
  std::ostream& out_;
  std::string wingman_;
  std::set<std::string> used_, prepared_, derived_;
};

}  // namespace

int run_recipe(const RecipeRunOptions& options, std::ostream& out, std::ostream& /*err*/) {
  RecipeRunOptions o = options;
  if (o.bin.empty()) {
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    o.bin = ec ? "." : self.parent_path().string();
  }
  Recipe r = load_recipe(o.recipe, o.overrides, o.src);
  if (!o.init.empty()) {
    if (o.stage.empty()) throw std::invalid_argument("--init: needs --stage (the stage that starts from it)");
    for (RecipeStage& s : r.stages)
      if (s.name == o.stage) s.init = {o.init};
  }
  return Runner(o, r, out).run();
}

}  // namespace wingman::tools
