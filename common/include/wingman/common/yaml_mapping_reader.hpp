// SPDX-License-Identifier: MIT
// Reads one YAML mapping through visit() lists, collecting every problem with its file, line and full key path
// (e.g. "follow_1d.yaml:14: vehicles[1].motion.max_speed: expected a number, got 'fast'").
#pragma once

#include <yaml-cpp/yaml.h>

#include <array>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace wingman::common {

/// Reads the leaves of one mapping (nested mappings flattened to dotted keys; sequences are leaves) into values,
/// with the same conversions and messages as ConfigLoader. For files whose mappings sit inside sequences (a
/// scenario's `vehicles[1].motion.waypoints[0]`): one reader per mapping, all adding to one shared problem list,
/// so a whole file is reported at once. Keys are relative to the mapping; messages show `path_prefix` + key.
///
/// @code
///   std::vector<std::string> problems;
///   YamlMappingReader vr("a.yaml", root["vehicles"][1], "vehicles[1].", &problems);
///   vr("motion.max_speed", max_speed, "m/s");  // "a.yaml:14: vehicles[1].motion.max_speed: expected a number, ..."
///   vr.finish();                               // "a.yaml:15: vehicles[1].motion.colour: unknown key"
/// @endcode
/// Supported value types: bool, int, int64_t, uint64_t (no leading '-'), double, std::string (null reads as ""),
/// std::vector of double, int or std::string (YAML sequences), std::array<double, 3> (exactly three numbers).
/// A value that does not convert keeps its default and adds a problem.
class YamlMappingReader {
 public:
  /// Flattens `mapping` (a problem for every key that is not a plain name). `source_name` is the file name in
  /// messages; `path_prefix` ("" or ending in '.', e.g. "vehicles[1].") is put before every key in messages;
  /// `problems` (not null) must outlive the reader. A null or undefined `mapping` reads as empty; anything else
  /// that is not a mapping is a problem ("<prefix>: expected a mapping, got ...") and nothing is read.
  YamlMappingReader(std::string source_name, const YAML::Node& mapping, std::string path_prefix,
                    std::vector<std::string>* problems);

  /// visit() callback: converts the leaf `key` into `value` if present (else leaves the default) and marks `key`
  /// known.
  template <class T>
  void operator()(const std::string& key, T& value, const char* /*doc*/) {
    known_.insert(key);
    const auto it = leaves_.find(key);
    if (it != leaves_.end()) convert(key, it->second, value);
  }

  /// Whether the mapping has the leaf `key` (known or not).
  bool has(const std::string& key) const { return leaves_.count(key) > 0; }
  /// The leaf node of `key` (marks it known): for values read by hand, e.g. a sequence of mappings. When absent, an
  /// undefined node (IsDefined() false; a `key:` with no value is a defined null).
  YAML::Node take(const std::string& key);
  /// The leaf `key` as a list of mappings (marks it known), each to be read by its own reader: a problem ("missing (a
  /// list of mappings)" when `required`, "expected a list of mappings, got ..." for another value) and an empty list
  /// otherwise. An absent or null `key` that is not `required` is an empty list.
  std::vector<YAML::Node> take_list(const std::string& key, bool required);
  /// Records a problem about `key`: "<file>:<line>: <prefix><key>: <message>" (no line when `key` is absent).
  void problem(const std::string& key, const std::string& message);
  /// Records a "key = value: rule" line from a validate() as "<file>:<line>: <prefix><line>": the key (up to the
  /// first space or colon) is looked up for its line number.
  void validation_problem(const std::string& line);
  /// Records every leaf that no visit() named as "<file>:<line>: <prefix><key>: unknown key<hint>". Call it once,
  /// after every visit() and take().
  void finish(const std::string& hint = "");

  const std::string& source_name() const { return source_name_; }
  const std::string& path_prefix() const { return path_prefix_; }

  /// What a node holds, for messages: "'text'", "a sequence", "a mapping", or "nothing" (null or undefined).
  static std::string describe(const YAML::Node& node);

 private:
  /// "<file>:<line>: <path>", or "<file>: <path>" when `node` has no line (`path`: e.g. "vehicles[1].name").
  std::string where(const std::string& path, const YAML::Node& node) const;
  void convert(const std::string& key, const YAML::Node& node, bool& out);
  void convert(const std::string& key, const YAML::Node& node, int& out);
  void convert(const std::string& key, const YAML::Node& node, int64_t& out);
  void convert(const std::string& key, const YAML::Node& node, uint64_t& out);
  void convert(const std::string& key, const YAML::Node& node, double& out);
  void convert(const std::string& key, const YAML::Node& node, std::string& out);
  void convert(const std::string& key, const YAML::Node& node, std::vector<double>& out);
  void convert(const std::string& key, const YAML::Node& node, std::vector<int>& out);
  void convert(const std::string& key, const YAML::Node& node, std::vector<std::string>& out);
  void convert(const std::string& key, const YAML::Node& node, std::array<double, 3>& out);

  std::string source_name_;
  std::string path_prefix_;
  std::vector<std::string>* problems_;
  std::map<std::string, YAML::Node> leaves_;  // dotted key -> scalar, sequence or null
  std::set<std::string> known_;               // keys named by a visit() or take()
};

}  // namespace wingman::common
