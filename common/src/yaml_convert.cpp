// SPDX-License-Identifier: MIT
// Internal: the one flattening walk and value conversions behind ConfigLoader and YamlMappingReader.
#include "yaml_convert.hpp"

#include <fmt/format.h>

#include <limits>

namespace wingman::common::yaml_convert {
namespace {

std::optional<ValueProblem> problem(std::string message) { return ValueProblem{"", std::move(message)}; }

std::optional<ValueProblem> element_problem(size_t i, std::string message) {
  return ValueProblem{fmt::format("[{}]", i), std::move(message)};
}

/// A sequence of scalars decoded one by one as `Element`; `what` names the sequence and `element_what` an element
/// ("a sequence of numbers", "a number").
template <class Element>
std::optional<ValueProblem> convert_sequence(const YAML::Node& node, std::vector<Element>& out, const char* what,
                                             const char* element_what) {
  if (!node.IsSequence()) return problem(fmt::format("expected {}, got {}", what, describe_node(node)));
  std::vector<Element> v;
  for (size_t i = 0; i < node.size(); ++i) {
    Element x;
    if (!node[i].IsScalar() || !YAML::convert<Element>::decode(node[i], x))
      return element_problem(i, fmt::format("expected {}, got {}", element_what, describe_node(node[i])));
    v.push_back(x);
  }
  out = std::move(v);
  return std::nullopt;
}

}  // namespace

std::string describe_node(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  if (node.IsSequence()) return "a sequence";
  if (node.IsMap()) return "a mapping";
  return "nothing";
}

void flatten(const YAML::Node& mapping, const std::string& prefix, const LeafFn& on_leaf, const BadKeyFn& on_bad_key) {
  for (const auto& kv : mapping) {
    if (!kv.first.IsScalar()) {  // e.g. "? mode: x" or "? [a, b]": YAML allows it, a configuration does not
      on_bad_key(prefix, kv.first, "a key must be a plain name, got " + describe_node(kv.first));
      continue;
    }
    const std::string name = kv.first.as<std::string>();
    const std::string key = prefix.empty() ? name : prefix + "." + name;
    if (kv.second.IsMap()) {
      flatten(kv.second, key, on_leaf, on_bad_key);
    } else {
      on_leaf(key, kv.second);
    }
  }
}

std::optional<ValueProblem> convert(const YAML::Node& node, bool& out) {
  bool v;
  if (!node.IsScalar() || !YAML::convert<bool>::decode(node, v))
    return problem("expected true or false, got " + describe_node(node));
  out = v;
  return std::nullopt;
}

std::optional<ValueProblem> convert(const YAML::Node& node, int64_t& out) {
  long long v;
  if (!node.IsScalar() || !YAML::convert<long long>::decode(node, v))
    return problem("expected an integer, got " + describe_node(node));
  out = v;
  return std::nullopt;
}

std::optional<ValueProblem> convert(const YAML::Node& node, int& out) {
  int64_t v = 0;
  if (auto bad = convert(node, v)) return bad;
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    return problem(fmt::format("integer {} out of range", v));
  out = static_cast<int>(v);
  return std::nullopt;
}

std::optional<ValueProblem> convert(const YAML::Node& node, uint64_t& out) {
  unsigned long long v;
  // yaml-cpp decodes "-1" as 2^64 - 1: a leading '-' is refused here.
  if (!node.IsScalar() || node.Scalar().empty() || node.Scalar()[0] == '-' ||
      !YAML::convert<unsigned long long>::decode(node, v))
    return problem("expected a non-negative integer, got " + describe_node(node));
  out = v;
  return std::nullopt;
}

std::optional<ValueProblem> convert(const YAML::Node& node, double& out) {
  double v;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, v))
    return problem("expected a number, got " + describe_node(node));
  out = v;
  return std::nullopt;
}

std::optional<ValueProblem> convert(const YAML::Node& node, std::string& out) {
  if (node.IsScalar()) {
    out = node.Scalar();
  } else if (node.IsNull()) {
    out.clear();
  } else {
    return problem("expected a string, got " + describe_node(node));
  }
  return std::nullopt;
}

std::optional<ValueProblem> convert(const YAML::Node& node, std::vector<double>& out) {
  return convert_sequence(node, out, "a sequence of numbers", "a number");
}

std::optional<ValueProblem> convert(const YAML::Node& node, std::vector<int>& out) {
  return convert_sequence(node, out, "a sequence of integers", "an integer");
}

std::optional<ValueProblem> convert(const YAML::Node& node, std::vector<std::string>& out) {
  return convert_sequence(node, out, "a sequence of strings", "a string");
}

std::optional<ValueProblem> convert(const YAML::Node& node, std::array<double, 3>& out) {
  std::vector<double> v;
  if (auto bad = convert(node, v)) return bad;
  if (v.size() != 3) return problem(fmt::format("expected 3 numbers [x, y, z], got {}", v.size()));
  out = {v[0], v[1], v[2]};
  return std::nullopt;
}

}  // namespace wingman::common::yaml_convert
