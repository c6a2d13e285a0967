// SPDX-License-Identifier: MIT
// Internal: YAML mapping reader for scenarios (every problem with file, line and key path).
#include "yaml_reader.hpp"

#include <fmt/format.h>

#include <limits>

namespace wingman::sim::detail {

std::string describe_node(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  if (node.IsSequence()) return "a sequence";
  if (node.IsMap()) return "a mapping";
  return "nothing";
}

YamlReader::YamlReader(std::string source_name, const YAML::Node& mapping, std::string path_prefix,
                       std::vector<std::string>* problems)
    : source_name_(std::move(source_name)),
      path_prefix_(std::move(path_prefix)),
      mapping_(mapping),
      problems_(problems) {
  if (mapping.IsMap()) {
    flatten(mapping, "");
  } else if (mapping.IsDefined() && !mapping.IsNull()) {
    const std::string name = path_prefix_.empty() ? "top level" : path_prefix_.substr(0, path_prefix_.size() - 1);
    const auto mark = mapping.Mark();
    problems_->push_back(
        mark.line >= 0 ? fmt::format("{}:{}: {}: expected a mapping, got {}", source_name_, mark.line + 1, name,
                                     describe_node(mapping))
                       : fmt::format("{}: {}: expected a mapping, got {}", source_name_, name, describe_node(mapping)));
  }
}

void YamlReader::flatten(const YAML::Node& node, const std::string& prefix) {
  for (const auto& kv : node) {
    if (!kv.first.IsScalar()) {  // e.g. "? [a, b]": YAML allows it, a configuration does not
      const auto mark = kv.first.Mark();
      const std::string at = path_prefix_ + (prefix.empty() ? std::string("(top level)") : prefix);
      problems_->push_back(mark.line >= 0 ? fmt::format("{}:{}: {}: a key must be a plain name, got {}", source_name_,
                                                        mark.line + 1, at, describe_node(kv.first))
                                          : fmt::format("{}: {}: a key must be a plain name, got {}", source_name_, at,
                                                        describe_node(kv.first)));
      continue;
    }
    const std::string name = kv.first.as<std::string>();
    const std::string key = prefix.empty() ? name : prefix + "." + name;
    if (kv.second.IsMap()) {
      flatten(kv.second, key);
    } else {
      leaves_[key] = kv.second;
    }
  }
}

std::string YamlReader::where(const std::string& key, const YAML::Node& node) const {
  const auto mark = node.Mark();
  if (node.IsDefined() && mark.line >= 0)
    return fmt::format("{}:{}: {}{}", source_name_, mark.line + 1, path_prefix_, key);
  return fmt::format("{}: {}{}", source_name_, path_prefix_, key);
}

YAML::Node YamlReader::take(const std::string& key) {
  known_.insert(key);
  const auto it = leaves_.find(key);
  return it == leaves_.end() ? YAML::Node() : it->second;
}

void YamlReader::problem(const std::string& key, const std::string& message) {
  const auto it = leaves_.find(key);
  problems_->push_back(fmt::format("{}: {}", where(key, it == leaves_.end() ? YAML::Node() : it->second), message));
}

void YamlReader::validation_problem(const std::string& line) {
  // "key = value: rule" or "key: rule": the key ends at the first space or colon; its leaf gives the line number.
  const std::string key = line.substr(0, line.find_first_of(" :"));
  const auto it = leaves_.find(key);
  const YAML::Node node = it == leaves_.end() ? YAML::Node() : it->second;
  const auto mark = node.Mark();
  if (node.IsDefined() && mark.line >= 0) {
    problems_->push_back(fmt::format("{}:{}: {}{}", source_name_, mark.line + 1, path_prefix_, line));
  } else {
    problems_->push_back(fmt::format("{}: {}{}", source_name_, path_prefix_, line));
  }
}

void YamlReader::finish(const std::string& hint) {
  for (const auto& [key, node] : leaves_) {
    if (known_.count(key)) continue;
    problems_->push_back(fmt::format("{}: unknown key{}", where(key, node), hint));
  }
}

void YamlReader::operator()(const std::string& key, Eigen::Vector3d& value, const char* /*doc*/) {
  known_.insert(key);
  const auto it = leaves_.find(key);
  if (it == leaves_.end()) return;
  std::vector<double> v;
  const size_t before = problems_->size();
  convert(key, it->second, v);
  if (problems_->size() != before) return;
  if (v.size() != 3) {
    problems_->push_back(fmt::format("{}: expected 3 numbers [x, y, z], got {}", where(key, it->second), v.size()));
    return;
  }
  value = Eigen::Vector3d(v[0], v[1], v[2]);
}

void YamlReader::convert(const std::string& key, const YAML::Node& node, bool& out) {
  bool v;
  if (node.IsScalar() && YAML::convert<bool>::decode(node, v)) {
    out = v;
  } else {
    problems_->push_back(fmt::format("{}: expected true or false, got {}", where(key, node), describe_node(node)));
  }
}

void YamlReader::convert(const std::string& key, const YAML::Node& node, int64_t& out) {
  long long v;
  if (node.IsScalar() && YAML::convert<long long>::decode(node, v)) {
    out = v;
  } else {
    problems_->push_back(fmt::format("{}: expected an integer, got {}", where(key, node), describe_node(node)));
  }
}

void YamlReader::convert(const std::string& key, const YAML::Node& node, uint64_t& out) {
  unsigned long long v;
  if (node.IsScalar() && !node.Scalar().empty() && node.Scalar()[0] != '-' &&
      YAML::convert<unsigned long long>::decode(node, v)) {
    out = v;
  } else {
    problems_->push_back(
        fmt::format("{}: expected a non-negative integer, got {}", where(key, node), describe_node(node)));
  }
}

void YamlReader::convert(const std::string& key, const YAML::Node& node, int& out) {
  int64_t v = 0;
  const size_t before = problems_->size();
  convert(key, node, v);
  if (problems_->size() != before) return;
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max()) {
    problems_->push_back(fmt::format("{}: integer {} out of range", where(key, node), v));
    return;
  }
  out = static_cast<int>(v);
}

void YamlReader::convert(const std::string& key, const YAML::Node& node, double& out) {
  double v;
  if (node.IsScalar() && YAML::convert<double>::decode(node, v)) {
    out = v;
  } else {
    problems_->push_back(fmt::format("{}: expected a number, got {}", where(key, node), describe_node(node)));
  }
}

void YamlReader::convert(const std::string& key, const YAML::Node& node, std::string& out) {
  if (node.IsScalar()) {
    out = node.Scalar();
  } else if (node.IsNull()) {
    out.clear();
  } else {
    problems_->push_back(fmt::format("{}: expected a string, got {}", where(key, node), describe_node(node)));
  }
}

void YamlReader::convert(const std::string& key, const YAML::Node& node, std::vector<double>& out) {
  if (!node.IsSequence()) {
    problems_->push_back(
        fmt::format("{}: expected a sequence of numbers, got {}", where(key, node), describe_node(node)));
    return;
  }
  std::vector<double> v;
  for (size_t i = 0; i < node.size(); ++i) {
    double x;
    if (!node[i].IsScalar() || !YAML::convert<double>::decode(node[i], x)) {
      problems_->push_back(
          fmt::format("{}[{}]: expected a number, got {}", where(key, node), i, describe_node(node[i])));
      return;
    }
    v.push_back(x);
  }
  out = v;
}

void YamlReader::convert(const std::string& key, const YAML::Node& node, std::vector<int>& out) {
  if (!node.IsSequence()) {
    problems_->push_back(
        fmt::format("{}: expected a sequence of integers, got {}", where(key, node), describe_node(node)));
    return;
  }
  std::vector<int> v;
  for (size_t i = 0; i < node.size(); ++i) {
    int x;
    if (!node[i].IsScalar() || !YAML::convert<int>::decode(node[i], x)) {
      problems_->push_back(
          fmt::format("{}[{}]: expected an integer, got {}", where(key, node), i, describe_node(node[i])));
      return;
    }
    v.push_back(x);
  }
  out = v;
}

void YamlReader::convert(const std::string& key, const YAML::Node& node, std::vector<std::string>& out) {
  if (!node.IsSequence()) {
    problems_->push_back(
        fmt::format("{}: expected a sequence of strings, got {}", where(key, node), describe_node(node)));
    return;
  }
  std::vector<std::string> v;
  for (size_t i = 0; i < node.size(); ++i) {
    if (!node[i].IsScalar()) {
      problems_->push_back(
          fmt::format("{}[{}]: expected a string, got {}", where(key, node), i, describe_node(node[i])));
      return;
    }
    v.push_back(node[i].Scalar());
  }
  out = v;
}

}  // namespace wingman::sim::detail
