// SPDX-License-Identifier: MIT
// `wingman scenario set`: a copy of a scenario with some keys replaced, checked with the simulator's loader.
#include "wingman/tools/scenario_edit.hpp"

#include <wingman/common/config.hpp>
#include <wingman/sim/scenario.hpp>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace wingman::tools {
namespace {

namespace fs = std::filesystem;
using common::ConfigError;

std::vector<std::string> split_key(const std::string& key) {  // a valid dotted name (parse_set_assignment)
  std::vector<std::string> parts;
  std::istringstream ss(key);
  for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
  return parts;
}

// A list whose entries are mappings (vehicles), as opposed to a value such as a position.
bool is_entry_list(const YAML::Node& node) {
  if (!node.IsSequence() || node.size() == 0) return false;
  for (size_t i = 0; i < node.size(); ++i)
    if (!node[i].IsMap()) return false;
  return true;
}

// Sets one KEY=VALUE in `root` (a scenario's mapping).
void apply_set(YAML::Node root, const std::string& assignment) {
  std::string error;
  const auto set = common::parse_set_assignment(assignment, "vehicles.camera.motion.frames_per_step=2", &error);
  if (!set) throw ConfigError(error);
  const std::string& key = set->key;
  const YAML::Node& value = set->value;
  const std::vector<std::string> parts = split_key(key);
  YAML::Node node = root;
  std::string at;  // the path walked so far
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    const std::string& p = parts[i];
    YAML::Node next;
    if (is_entry_list(node)) {  // an entry of a list (vehicles), named by its `name`
      std::string names;
      for (size_t j = 0; j < node.size(); ++j) {
        const YAML::Node entry = node[j];
        const std::string name =
            entry.IsMap() && entry["name"] && entry["name"].IsScalar() ? entry["name"].Scalar() : "";
        if (name == p) next.reset(entry);
        names += (names.empty() ? "" : ", ") + name;
      }
      if (!next.IsDefined() || next.IsNull())
        throw ConfigError(fmt::format("--set {}: {} has no entry named '{}' (names: {})", key, at, p, names));
    } else if (node.IsMap()) {
      if (!node[p]) node[p] = YAML::Node(YAML::NodeType::Map);
      next.reset(node[p]);
    } else {
      throw ConfigError(fmt::format("--set {}: {} is a value, not a mapping", key, at));
    }
    node.reset(next);
    at = at.empty() ? p : at + "." + p;
  }
  if (!node.IsMap())
    throw ConfigError(fmt::format("--set {}: {} is {}", key, at,
                                  is_entry_list(node) ? "a list: name one of its entries" : "a value, not a mapping"));
  node[parts.back()] = value;
}

// Relative drone.mesh_path of each vehicle made absolute against `base_dir`.
void absolute_mesh_paths(YAML::Node root, const fs::path& base_dir) {
  YAML::Node vehicles = root["vehicles"];
  if (!vehicles.IsSequence()) return;
  for (size_t i = 0; i < vehicles.size(); ++i) {
    YAML::Node v = vehicles[i];
    if (!v.IsMap() || !v["drone"] || !v["drone"].IsMap()) continue;
    YAML::Node drone = v["drone"];
    if (!drone["mesh_path"] || !drone["mesh_path"].IsScalar()) continue;
    const fs::path mesh = drone["mesh_path"].Scalar();
    if (!mesh.empty() && mesh.is_relative()) drone["mesh_path"] = (base_dir / mesh).lexically_normal().string();
  }
}

}  // namespace

void write_scenario_copy(const ScenarioSetOptions& o) {
  if (o.out.empty()) throw ConfigError("--out: required (the copy to write)");
  sim::load_scenario(o.file);  // the original first: its own problems name it
  std::ifstream in(o.file);
  std::stringstream text;
  text << in.rdbuf();
  YAML::Node root = YAML::Load(text.str());  // loaded above: valid YAML of a mapping
  for (const auto& s : o.sets) apply_set(root, s);
  absolute_mesh_paths(root, fs::absolute(o.file).parent_path());
  YAML::Emitter emitter;
  emitter << root;
  std::string header = "# Written by wingman scenario set: " + o.file;
  for (const auto& s : o.sets) header += " --set " + s;
  const std::string yaml = header + "\n" + emitter.c_str() + "\n";
  sim::parse_scenario(yaml, o.out, fs::absolute(o.out).parent_path().string());  // every problem of the copy
  const fs::path parent = fs::path(o.out).parent_path();
  if (!parent.empty()) fs::create_directories(parent);
  std::ofstream out(o.out);
  out << yaml;
  if (!out.flush()) throw std::runtime_error(o.out + ": cannot write");
}

}  // namespace wingman::tools
