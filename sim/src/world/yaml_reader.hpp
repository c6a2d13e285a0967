// SPDX-License-Identifier: MIT
// Internal: reads one YAML mapping of a scenario through visit() lists, collecting every problem with its file,
// line and full key path (e.g. "follow_1d.yaml:14: vehicles[1].motion.max_speed: expected a number, got 'fast'").
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace wingman::sim::detail {

/// Reads the leaves of one mapping (nested mappings flattened to dotted keys; sequences are leaves) into values,
/// with the same conversions and messages as common::ConfigLoader. Problems go to a shared list so a whole
/// scenario is reported at once. Keys are relative to the mapping; messages show `path_prefix` + key.
class YamlReader {
 public:
  /// `mapping` must be a mapping (a problem is recorded otherwise and nothing is read).
  YamlReader(std::string source_name, const YAML::Node& mapping, std::string path_prefix,
             std::vector<std::string>* problems);

  /// visit() callback: converts the leaf `key` into `value` if present (else leaves the default).
  template <class T>
  void operator()(const std::string& key, T& value, const char* /*doc*/) {
    known_.insert(key);
    const auto it = leaves_.find(key);
    if (it != leaves_.end()) convert(key, it->second, value);
  }
  /// A 3-vector given as a sequence of three numbers.
  void operator()(const std::string& key, Eigen::Vector3d& value, const char* doc);

  bool has(const std::string& key) const { return leaves_.count(key) > 0; }
  /// The leaf node of `key` (marks it known); an undefined node when absent.
  YAML::Node take(const std::string& key);
  /// Records a problem about `key`: "<file>:<line>: <prefix><key>: <message>".
  void problem(const std::string& key, const std::string& message);
  /// Records a "key = value: rule" line from a validate(): the key is looked up for its line number.
  void validation_problem(const std::string& line);
  /// Records every leaf that no visit() named as "unknown key" (`hint` appended when not empty).
  void finish(const std::string& hint = "");

  const std::string& source_name() const { return source_name_; }
  const std::string& path_prefix() const { return path_prefix_; }

 private:
  void flatten(const YAML::Node& node, const std::string& prefix);
  std::string where(const std::string& key, const YAML::Node& node) const;
  void convert(const std::string& key, const YAML::Node& node, bool& out);
  void convert(const std::string& key, const YAML::Node& node, int& out);
  void convert(const std::string& key, const YAML::Node& node, int64_t& out);
  void convert(const std::string& key, const YAML::Node& node, uint64_t& out);
  void convert(const std::string& key, const YAML::Node& node, double& out);
  void convert(const std::string& key, const YAML::Node& node, std::string& out);
  void convert(const std::string& key, const YAML::Node& node, std::vector<double>& out);
  void convert(const std::string& key, const YAML::Node& node, std::vector<int>& out);
  void convert(const std::string& key, const YAML::Node& node, std::vector<std::string>& out);

  std::string source_name_;
  std::string path_prefix_;
  YAML::Node mapping_;
  std::vector<std::string>* problems_;
  std::map<std::string, YAML::Node> leaves_;
  std::set<std::string> known_;
};

/// What a node holds, for messages: "'text'", "a sequence", "a mapping", "nothing".
std::string describe_node(const YAML::Node& node);

}  // namespace wingman::sim::detail
