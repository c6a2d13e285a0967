// SPDX-License-Identifier: MIT
// TrainOptions: validation and the [net] section's training keys.
#include "wingman/training/train_options.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace wingman::training {

std::vector<std::string> TrainOptions::validate() const {
  std::vector<std::string> p;
  if (cfg.empty()) p.push_back("cfg is empty: the network's .cfg is required");
  if (data.empty()) p.push_back("data is empty: a data.yaml or YOLO-layout folder is required");
  if (train_split.empty()) p.push_back("train_split is empty");
  if (out_dir.empty()) p.push_back("out_dir is empty");
  if (init_partial && init_weights.empty())
    p.push_back("init_partial is set without init_weights: partial weights need a .weights file");
  if (batch < 1) p.push_back(fmt::format("batch = {}: must be >= 1", batch));
  if (subdivisions < 1 || (batch >= 1 && batch % subdivisions != 0))
    p.push_back(fmt::format("subdivisions = {}: must be >= 1 and divide batch = {}", subdivisions, batch));
  if (max_batches < 1) p.push_back(fmt::format("max_batches = {}: must be >= 1", max_batches));
  if (!(momentum >= 0.0 && momentum < 1.0)) p.push_back(fmt::format("momentum = {}: must be in [0, 1)", momentum));
  if (!(decay >= 0.0)) p.push_back(fmt::format("decay = {}: must be >= 0", decay));
  for (const auto& s : lr.validate()) p.push_back(s);
  for (const auto& s : augment.validate()) p.push_back(s);
  for (const auto& s : ema.validate()) p.push_back(s);
  if (threads < 1) p.push_back(fmt::format("threads = {}: must be >= 1", threads));
  if (checkpoint_interval < 1) p.push_back(fmt::format("checkpoint_interval = {}: must be >= 1", checkpoint_interval));
  if (weights_interval < 0) p.push_back(fmt::format("weights_interval = {}: must be >= 0", weights_interval));
  if (log_interval < 1) p.push_back(fmt::format("log_interval = {}: must be >= 1", log_interval));
  if (val_max_images < 0) p.push_back(fmt::format("val_max_images = {}: must be >= 0", val_max_images));
  return p;
}

namespace {

class NetKeys {
 public:
  NetKeys(const detector::NetParams& net, const std::string& cfg) : net_(net), cfg_(cfg) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw std::invalid_argument(
        fmt::format("{}: [net] key '{}' = '{}': {}", cfg_, key, net_.other.count(key) ? net_.other.at(key) : "", what));
  }
  const std::string* find(const std::string& key) const {
    const auto it = net_.other.find(key);
    return it == net_.other.end() ? nullptr : &it->second;
  }
  double number(const std::string& key, double def) const {
    const std::string* v = find(key);
    if (!v) return def;
    char* end = nullptr;
    const double x = std::strtod(v->c_str(), &end);
    if (end == v->c_str() || *end != '\0') fail(key, "expected a number");
    return x;
  }
  int integer(const std::string& key, int def) const {
    const std::string* v = find(key);
    if (!v) return def;
    char* end = nullptr;
    errno = 0;
    const long x = std::strtol(v->c_str(), &end, 10);
    if (errno != 0 || end == v->c_str() || *end != '\0') fail(key, "expected an integer");
    return static_cast<int>(x);
  }
  template <class T>
  std::vector<T> list(const std::string& key, const std::vector<T>& def) const {
    const std::string* v = find(key);
    if (!v) return def;
    std::vector<T> out;
    std::stringstream ss(*v);
    std::string item;
    while (std::getline(ss, item, ',')) {
      if (item.empty()) continue;
      char* end = nullptr;
      const double x = std::strtod(item.c_str(), &end);
      if (end == item.c_str() || *end != '\0') fail(key, fmt::format("'{}' is not a number", item));
      out.push_back(static_cast<T>(x));
    }
    return out;
  }

 private:
  const detector::NetParams& net_;
  const std::string& cfg_;
};

}  // namespace

TrainOptions train_options_from_model(const detector::DarknetModel& model, const std::string& cfg_path) {
  TrainOptions o;
  o.cfg = cfg_path;
  const NetKeys k(model.net, cfg_path);
  o.batch = k.integer("batch", o.batch);
  o.subdivisions = k.integer("subdivisions", o.subdivisions);
  o.max_batches = k.integer("max_batches", static_cast<int>(o.max_batches));
  o.momentum = k.number("momentum", o.momentum);
  o.decay = k.number("decay", o.decay);
  o.lr.base = k.number("learning_rate", o.lr.base);
  o.lr.burn_in = k.integer("burn_in", o.lr.burn_in);
  o.lr.power = k.number("power", o.lr.power);
  const std::string policy = k.find("policy") ? *k.find("policy") : "steps";
  if (policy == "steps") {
    o.lr.steps = k.list<int>("steps", o.lr.steps);
    o.lr.scales = k.list<double>("scales", o.lr.scales);
  } else if (policy == "constant") {
    o.lr.steps.clear();
    o.lr.scales.clear();
  } else {
    k.fail("policy", "supported are steps and constant");
  }
  o.augment.hue = k.number("hue", o.augment.hue);
  o.augment.saturation = k.number("saturation", o.augment.saturation);
  o.augment.exposure = k.number("exposure", o.augment.exposure);
  const std::vector<int> heads = model.heads();
  const double head_jitter = heads.empty() ? o.augment.jitter : model.layers[static_cast<size_t>(heads.back())].jitter;
  o.augment.jitter = k.number("jitter", head_jitter);
  // Darknet's flip=1 means "flip half of the images"; 0 turns flipping off.
  o.augment.flip = k.integer("flip", 1) != 0 ? 0.5 : 0.0;
  o.augment.mosaic = k.integer("mosaic", 0) != 0 ? 0.5 : 0.0;
  if (k.number("angle", 0.0) != 0.0) k.fail("angle", "rotation is not supported by the trainer; use angle=0");
  return o;
}

std::string multi_scale_note(const detector::DarknetModel& model) {
  for (int h : model.heads()) {
    const detector::Layer& l = model.layers[static_cast<size_t>(h)];
    if (l.random != 0.0f)
      return fmt::format(
          "{}:{}: random={} asks for multi-scale training, which wingman train does not do: it trains "
          "at {}x{}",
          model.cfg_path, l.cfg_line, l.random, model.net.width, model.net.height);
  }
  return "";
}

}  // namespace wingman::training
