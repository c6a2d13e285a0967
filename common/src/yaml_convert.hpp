// SPDX-License-Identifier: MIT
// Internal: the one flattening walk and value conversions behind ConfigLoader and YamlMappingReader.
#pragma once

#include <yaml-cpp/yaml.h>

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace wingman::common::yaml_convert {

/// What a node holds, for messages: "'text'", "a sequence", "a mapping", or "nothing" (null or undefined).
std::string describe_node(const YAML::Node& node);

/// Called for every leaf of a flattened mapping: `key` its dotted path, `value` a scalar, a sequence or null.
using LeafFn = std::function<void(const std::string& key, const YAML::Node& value)>;
/// Called for every key that is not a plain name: `at` the dotted path of the mapping holding it ("" for the top),
/// `key` the offending key node (its mark gives the line), `message` "a key must be a plain name, got a sequence".
using BadKeyFn = std::function<void(const std::string& at, const YAML::Node& key, const std::string& message)>;

/// Walks `mapping` depth first: nested mappings become dotted keys below `prefix` ("" or "a.b"), every other value
/// (scalar, sequence, null) is a leaf. Precondition: mapping.IsMap().
void flatten(const YAML::Node& mapping, const std::string& prefix, const LeafFn& on_leaf, const BadKeyFn& on_bad_key);

/// Why a value could not be converted.
struct ValueProblem {
  std::string element;  ///< "" for the value itself, "[i]" for element i of a sequence
  std::string message;  ///< e.g. "expected a number, got 'fast'"

  /// The whole line: `location` (e.g. "a.yaml:3: camera.fps"), the element and the message.
  std::string at(const std::string& location) const { return location + element + ": " + message; }
};

/// Each converts `node` into `out`, or leaves `out` unchanged and says why not (yaml-cpp's scalar decoding). An int
/// is read as int64_t, then range-checked; a uint64_t must not start with '-'; a std::string also takes null (as "");
/// a sequence is converted whole or not at all (the first bad element is named).
std::optional<ValueProblem> convert(const YAML::Node& node, bool& out);
std::optional<ValueProblem> convert(const YAML::Node& node, int& out);
std::optional<ValueProblem> convert(const YAML::Node& node, int64_t& out);
std::optional<ValueProblem> convert(const YAML::Node& node, uint64_t& out);
std::optional<ValueProblem> convert(const YAML::Node& node, double& out);
std::optional<ValueProblem> convert(const YAML::Node& node, std::string& out);
std::optional<ValueProblem> convert(const YAML::Node& node, std::vector<double>& out);
std::optional<ValueProblem> convert(const YAML::Node& node, std::vector<int>& out);
std::optional<ValueProblem> convert(const YAML::Node& node, std::vector<std::string>& out);
/// A 3-vector: a sequence of exactly three numbers [x, y, z].
std::optional<ValueProblem> convert(const YAML::Node& node, std::array<double, 3>& out);

}  // namespace wingman::common::yaml_convert
