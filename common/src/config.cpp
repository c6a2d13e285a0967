// SPDX-License-Identifier: MIT
// YAML configuration loader and printer.
#include "wingman/common/config.hpp"

#include "wingman/common/yaml_limits.hpp"
#include "yaml_convert.hpp"

#include <fmt/format.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace wingman::common {
namespace {

std::string quote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

}  // namespace

ConfigLoader ConfigLoader::from_file(const std::string& path) {
  // A directory opens as a stream on Linux and reads as empty, which meant all defaults with exit 0 (issue 33).
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw ConfigError(fmt::format("{}: is a directory, not a config file", path));
  std::ifstream in(path);
  if (!in) throw ConfigError(fmt::format("{}: cannot open config file", path));
  std::stringstream ss;
  ss << in.rdbuf();
  return from_string(ss.str(), path);
}

ConfigLoader ConfigLoader::from_string(const std::string& yaml_text, const std::string& source_name) {
  // Size and alias expansion bounded before yaml-cpp builds anything: a 663-byte alias bomb took 4.2 GB, 31 s and
  // a 630 MB error line (issue 33).
  if (const std::string bad = check_yaml_bounds(yaml_text, source_name); !bad.empty()) throw ConfigError(bad);
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(
        fmt::format("{}:{}:{}: not valid YAML: {}", source_name, e.mark.line + 1, e.mark.column + 1, e.msg));
  }
  if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);  // an empty file means all defaults
  if (!root.IsMap()) {
    throw ConfigError(fmt::format("{}: expected a mapping of sections at the top level, got {}", source_name,
                                  yaml_convert::describe_node(root)));
  }
  return ConfigLoader(source_name, root);
}

ConfigLoader::ConfigLoader(std::string source_name, const YAML::Node& root) : source_name_(std::move(source_name)) {
  flatten(root, "", source_name_);
}

std::string ConfigSources::describe() const {
  if (empty()) return "built-in defaults";
  std::string out;
  for (const auto& f : files) out += (out.empty() ? "" : ", ") + f;
  for (const auto& s : sets) out += (out.empty() ? "" : ", ") + ("--set " + s);
  return out;
}

ConfigLoader ConfigLoader::from_sources(const ConfigSources& sources) {
  // One file alone reads exactly as from_file (its name is every message's source).
  ConfigLoader out(sources.files.size() == 1 && sources.sets.empty() ? sources.files.front() : sources.describe());
  for (const auto& file : sources.files) {
    const ConfigLoader one = from_file(file);  // throws at once for an unreadable file or one that is not YAML
    for (const auto& [key, leaf] : one.leaves_) out.leaves_[key] = leaf;  // a later file's key wins
    out.errors_.insert(out.errors_.end(), one.errors_.begin(), one.errors_.end());
  }
  for (const auto& assignment : sources.sets) out.add_set(assignment);
  return out;
}

std::optional<SetAssignment> parse_set_assignment(const std::string& assignment, const std::string& example,
                                                  std::string* error) {
  const auto eq = assignment.find('=');
  const std::string key = eq == std::string::npos ? "" : assignment.substr(0, eq);
  bool plain = !key.empty() && key.front() != '.' && key.back() != '.' && key.find("..") == std::string::npos;
  for (char c : key) plain = plain && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '-');
  if (!plain) {
    *error = fmt::format("--set '{}': expected KEY=VALUE with KEY a dotted name (e.g. {})", assignment, example);
    return std::nullopt;
  }
  const std::string text = assignment.substr(eq + 1);
  if (std::string bad = check_yaml_bounds(text, "--set " + key); !bad.empty()) {
    *error = std::move(bad);
    return std::nullopt;
  }
  try {
    return SetAssignment{key, YAML::Load(text)};
  } catch (const YAML::Exception& e) {
    *error = fmt::format("--set {}: not valid YAML: {}", key, e.msg);
    return std::nullopt;
  }
}

void ConfigLoader::add_set(const std::string& assignment) {
  std::string error;
  const auto set = parse_set_assignment(assignment, "formation.offset_m=[-6,2,0]", &error);
  if (!set) {
    errors_.push_back(error);
    return;
  }
  if (set->value.IsMap()) {  // --set section={a: 1, b: 2}: each key of the mapping
    flatten(set->value, set->key, "--set");
    return;
  }
  leaves_[set->key] = Leaf{set->value, "--set", false};
}

void ConfigLoader::flatten(const YAML::Node& node, const std::string& prefix, const std::string& source) {
  const bool has_lines = source != "--set";
  const auto on_leaf = [&](const std::string& key, const YAML::Node& value) {
    leaves_[key] = Leaf{value, source, has_lines};
  };
  const auto on_bad_key = [&](const std::string& at, const YAML::Node& key, const std::string& message) {
    errors_.push_back(fmt::format("{}: {}", where(at.empty() ? "(top level)" : at, key, source, has_lines), message));
  };
  yaml_convert::flatten(node, prefix, on_leaf, on_bad_key);
}

std::string ConfigLoader::where(const std::string& key, const YAML::Node& node) const {
  if (current_ != nullptr) return where(key, node, current_->source, current_->has_lines);
  return where(key, node, source_name_, true);
}

std::string ConfigLoader::where(const std::string& key, const YAML::Node& node, const std::string& source,
                                bool has_lines) const {
  if (!has_lines) return fmt::format("{} {}", source, key);  // "--set formation.offset_m"
  const auto mark = node.Mark();
  if (mark.line >= 0) return fmt::format("{}:{}: {}", source, mark.line + 1, key);
  return fmt::format("{}: {}", source, key);
}

// Every conversion is the shared one (the texts of YamlMappingReader); a problem names the leaf's source and line.
void ConfigLoader::convert(const std::string& key, const YAML::Node& node, bool& out) {
  if (const auto bad = yaml_convert::convert(node, out)) errors_.push_back(bad->at(where(key, node)));
}
void ConfigLoader::convert(const std::string& key, const YAML::Node& node, int& out) {
  if (const auto bad = yaml_convert::convert(node, out)) errors_.push_back(bad->at(where(key, node)));
}
void ConfigLoader::convert(const std::string& key, const YAML::Node& node, int64_t& out) {
  if (const auto bad = yaml_convert::convert(node, out)) errors_.push_back(bad->at(where(key, node)));
}
void ConfigLoader::convert(const std::string& key, const YAML::Node& node, double& out) {
  if (const auto bad = yaml_convert::convert(node, out)) errors_.push_back(bad->at(where(key, node)));
}
void ConfigLoader::convert(const std::string& key, const YAML::Node& node, std::string& out) {
  if (const auto bad = yaml_convert::convert(node, out)) errors_.push_back(bad->at(where(key, node)));
}
void ConfigLoader::convert(const std::string& key, const YAML::Node& node, std::vector<double>& out) {
  if (const auto bad = yaml_convert::convert(node, out)) errors_.push_back(bad->at(where(key, node)));
}
void ConfigLoader::convert(const std::string& key, const YAML::Node& node, std::vector<int>& out) {
  if (const auto bad = yaml_convert::convert(node, out)) errors_.push_back(bad->at(where(key, node)));
}
void ConfigLoader::convert(const std::string& key, const YAML::Node& node, std::vector<std::string>& out) {
  if (const auto bad = yaml_convert::convert(node, out)) errors_.push_back(bad->at(where(key, node)));
}

void ConfigLoader::finish(const std::vector<std::string>& validation_errors) const {
  std::vector<std::string> all = errors_;
  for (const auto& [key, leaf] : leaves_) {
    if (known_.count(key)) continue;
    // Suggest a known key with the same last component, if any (typo in the section).
    std::string hint;
    const std::string last = key.substr(key.rfind('.') + 1);
    for (const auto& k : known_) {
      if (k.substr(k.rfind('.') + 1) == last) {
        hint = fmt::format(" (did you mean '{}'?)", k);
        break;
      }
    }
    all.push_back(fmt::format("{}: unknown key{}", where(key, leaf.node, leaf.source, leaf.has_lines), hint));
  }
  for (const auto& e : validation_errors) {
    // "key = value: rule": named by the source that gave the key, else by every source.
    const std::string key = e.substr(0, e.find_first_of(" :"));
    const auto it = leaves_.find(key);
    if (it == leaves_.end())
      all.push_back(fmt::format("{}: {}", source_name_, e));
    else if (it->second.source == "--set")
      all.push_back("--set " + e);  // "--set key = value: rule"
    else
      all.push_back(fmt::format("{}: {}", it->second.source, e));
  }
  if (all.empty()) return;
  std::string msg = fmt::format("{} problem{} in configuration: ", all.size(), all.size() == 1 ? "" : "s");
  for (size_t i = 0; i < all.size(); ++i) msg += (i ? "; " : "") + all[i];
  throw ConfigError(msg);
}

void ConfigPrinter::add(const std::string& key, const std::string& value, const char* doc) {
  const auto dot = key.rfind('.');
  Entry e;
  e.section = dot == std::string::npos ? "" : key.substr(0, dot);
  e.name = dot == std::string::npos ? key : key.substr(dot + 1);
  e.value = value;
  e.doc = doc ? doc : "";
  entries_.push_back(std::move(e));
}

std::string ConfigPrinter::str(const std::string& header) const {
  std::string out;
  if (!header.empty()) {
    std::istringstream hs(header);
    for (std::string line; std::getline(hs, line);) out += "# " + line + "\n";
  }
  // Group by section in order of first appearance; nested sections ("a.b") are indented.
  std::vector<std::string> order;
  for (const auto& e : entries_) {
    if (std::find(order.begin(), order.end(), e.section) == order.end()) order.push_back(e.section);
  }
  std::vector<std::string> open;  // currently open section path components
  for (const auto& section : order) {
    std::vector<std::string> parts;
    if (!section.empty()) {
      std::istringstream ss(section);
      for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
    }
    size_t common = 0;
    while (common < open.size() && common < parts.size() && open[common] == parts[common]) ++common;
    if (common == 0 && !out.empty()) out += "\n";
    for (size_t i = common; i < parts.size(); ++i) out += std::string(2 * i, ' ') + parts[i] + ":\n";
    open = parts;
    const std::string indent(2 * parts.size(), ' ');
    for (const auto& e : entries_) {
      if (e.section != section) continue;
      if (!e.doc.empty()) out += indent + "# " + e.doc + "\n";
      out += indent + e.name + ": " + e.value + "\n";
    }
  }
  return out;
}

std::string ConfigPrinter::format(bool v) { return v ? "true" : "false"; }
std::string ConfigPrinter::format(int v) { return std::to_string(v); }
std::string ConfigPrinter::format(int64_t v) { return std::to_string(v); }
std::string ConfigPrinter::format(double v) {
  std::string s = fmt::format("{}", v);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";  // keep it a float for readers
  return s;
}
std::string ConfigPrinter::format(const std::string& v) { return quote(v); }
std::string ConfigPrinter::format(const std::vector<double>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + format(v[i]);
  return s + "]";
}
std::string ConfigPrinter::format(const std::vector<int>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + format(v[i]);
  return s + "]";
}
std::string ConfigPrinter::format(const std::vector<std::string>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + quote(v[i]);
  return s + "]";
}

std::string problem(const std::string& key, const std::string& value, const std::string& rule) {
  return fmt::format("{} = '{}': {}", key, value, rule);
}
std::string problem(const std::string& key, double value, const std::string& rule) {
  return fmt::format("{} = {}: {}", key, value, rule);
}

}  // namespace wingman::common
