// SPDX-License-Identifier: MIT
// Reads one YAML mapping through visit() lists (every problem with file, line and key path).
#include "wingman/common/yaml_mapping_reader.hpp"

#include "yaml_convert.hpp"

#include <fmt/format.h>

namespace wingman::common {

YamlMappingReader::YamlMappingReader(std::string source_name, const YAML::Node& mapping, std::string path_prefix,
                                     std::vector<std::string>* problems)
    : source_name_(std::move(source_name)), path_prefix_(std::move(path_prefix)), problems_(problems) {
  // The mapping's own name: "vehicles[1]" for the prefix "vehicles[1].", "" for the root.
  const std::string name = path_prefix_.empty() ? "" : path_prefix_.substr(0, path_prefix_.size() - 1);
  if (mapping.IsMap()) {
    const auto on_leaf = [this](const std::string& key, const YAML::Node& value) { leaves_[key] = value; };
    const auto on_bad_key = [&](const std::string& at, const YAML::Node& key, const std::string& message) {
      // A bad key directly in the mapping is named by the mapping: "vehicles[1]", or "(top level)" for the root.
      const std::string path = !at.empty() ? path_prefix_ + at : !name.empty() ? name : "(top level)";
      problems_->push_back(fmt::format("{}: {}", where(path, key), message));
    };
    yaml_convert::flatten(mapping, "", on_leaf, on_bad_key);
  } else if (mapping.IsDefined() && !mapping.IsNull()) {
    problems_->push_back(fmt::format("{}: expected a mapping, got {}",
                                     where(name.empty() ? "top level" : name, mapping), describe(mapping)));
  }
}

std::string YamlMappingReader::describe(const YAML::Node& node) { return yaml_convert::describe_node(node); }

std::string YamlMappingReader::where(const std::string& path, const YAML::Node& node) const {
  if (node.IsDefined() && node.Mark().line >= 0)
    return fmt::format("{}:{}: {}", source_name_, node.Mark().line + 1, path);
  return fmt::format("{}: {}", source_name_, path);
}

YAML::Node YamlMappingReader::take(const std::string& key) {
  known_.insert(key);
  const auto it = leaves_.find(key);
  // YAML::Node() is defined (a null); callers tell "absent" from "key: ~" by IsDefined().
  return it == leaves_.end() ? YAML::Node(YAML::NodeType::Undefined) : it->second;
}

std::vector<YAML::Node> YamlMappingReader::take_list(const std::string& key, bool required) {
  const YAML::Node n = take(key);
  std::vector<YAML::Node> items;
  if (!n.IsDefined() || n.IsNull()) {
    if (required) problem(key, "missing (a list of mappings)");
    return items;
  }
  if (!n.IsSequence()) {
    problem(key, "expected a list of mappings, got " + describe(n));
    return items;
  }
  for (const YAML::Node& item : n) items.push_back(item);
  return items;
}

void YamlMappingReader::problem(const std::string& key, const std::string& message) {
  const auto it = leaves_.find(key);
  const YAML::Node node = it == leaves_.end() ? YAML::Node() : it->second;
  problems_->push_back(fmt::format("{}: {}", where(path_prefix_ + key, node), message));
}

void YamlMappingReader::validation_problem(const std::string& line) {
  // "key = value: rule" or "key: rule": the key ends at the first space or colon; its leaf gives the line number.
  const auto it = leaves_.find(line.substr(0, line.find_first_of(" :")));
  problems_->push_back(where(path_prefix_ + line, it == leaves_.end() ? YAML::Node() : it->second));
}

void YamlMappingReader::finish(const std::string& hint) {
  for (const auto& [key, node] : leaves_) {
    if (known_.count(key)) continue;
    problems_->push_back(fmt::format("{}: unknown key{}", where(path_prefix_ + key, node), hint));
  }
}

// Every conversion is the shared one (the texts of ConfigLoader); a problem is located at the key's leaf.
void YamlMappingReader::convert(const std::string& key, const YAML::Node& node, bool& out) {
  if (const auto bad = yaml_convert::convert(node, out)) problems_->push_back(bad->at(where(path_prefix_ + key, node)));
}
void YamlMappingReader::convert(const std::string& key, const YAML::Node& node, int& out) {
  if (const auto bad = yaml_convert::convert(node, out)) problems_->push_back(bad->at(where(path_prefix_ + key, node)));
}
void YamlMappingReader::convert(const std::string& key, const YAML::Node& node, int64_t& out) {
  if (const auto bad = yaml_convert::convert(node, out)) problems_->push_back(bad->at(where(path_prefix_ + key, node)));
}
void YamlMappingReader::convert(const std::string& key, const YAML::Node& node, uint64_t& out) {
  if (const auto bad = yaml_convert::convert(node, out)) problems_->push_back(bad->at(where(path_prefix_ + key, node)));
}
void YamlMappingReader::convert(const std::string& key, const YAML::Node& node, double& out) {
  if (const auto bad = yaml_convert::convert(node, out)) problems_->push_back(bad->at(where(path_prefix_ + key, node)));
}
void YamlMappingReader::convert(const std::string& key, const YAML::Node& node, std::string& out) {
  if (const auto bad = yaml_convert::convert(node, out)) problems_->push_back(bad->at(where(path_prefix_ + key, node)));
}
void YamlMappingReader::convert(const std::string& key, const YAML::Node& node, std::vector<double>& out) {
  if (const auto bad = yaml_convert::convert(node, out)) problems_->push_back(bad->at(where(path_prefix_ + key, node)));
}
void YamlMappingReader::convert(const std::string& key, const YAML::Node& node, std::vector<int>& out) {
  if (const auto bad = yaml_convert::convert(node, out)) problems_->push_back(bad->at(where(path_prefix_ + key, node)));
}
void YamlMappingReader::convert(const std::string& key, const YAML::Node& node, std::vector<std::string>& out) {
  if (const auto bad = yaml_convert::convert(node, out)) problems_->push_back(bad->at(where(path_prefix_ + key, node)));
}
void YamlMappingReader::convert(const std::string& key, const YAML::Node& node, std::array<double, 3>& out) {
  if (const auto bad = yaml_convert::convert(node, out)) problems_->push_back(bad->at(where(path_prefix_ + key, node)));
}

}  // namespace wingman::common
