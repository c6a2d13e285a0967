// SPDX-License-Identifier: MIT
// YAML configuration: options structs are read and printed through one visit() list of keys.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace wingman::common {

/// A configuration or command-line problem. what() is one line that names the file and every bad key.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads an options struct from a YAML file of sections (`section: {key: value}`), collecting every
/// problem before failing once.
///
/// An options struct describes its keys once:
/// @code
///   template <class Visitor> void visit(Visitor& v) {
///     v("source.kind", source_kind, "v4l2 or file");
///   }
///   std::vector<std::string> validate() const;  // "source.kind = 'x': must be v4l2 or file"
/// @endcode
/// Keys are dotted paths into nested YAML mappings. Supported value types: bool, int, int64_t,
/// double, std::string, and std::vector of double, int or std::string (YAML sequences).
/// Keys missing from the file keep their defaults; keys in the file that no visit() names are errors.
class ConfigLoader {
 public:
  /// Parses the file. Throws ConfigError naming the file (and line) if it is unreadable or not YAML.
  static ConfigLoader from_file(const std::string& path);
  /// Parses YAML text; `source_name` stands for the file name in messages.
  static ConfigLoader from_string(const std::string& yaml_text, const std::string& source_name);

  template <class T>
  void operator()(const std::string& key, T& value, const char* /*doc*/) {
    known_.insert(key);
    auto it = leaves_.find(key);
    if (it == leaves_.end()) return;
    convert(key, it->second, value);
  }

  /// Throws ConfigError listing every conversion error, every unknown key and every entry of
  /// `validation_errors` (from the options' validate()), or returns if there are none.
  void finish(const std::vector<std::string>& validation_errors) const;

  /// Problems found so far (conversion errors only; unknown keys are found by finish()).
  const std::vector<std::string>& errors() const { return errors_; }

 private:
  ConfigLoader(std::string source_name, const YAML::Node& root);
  void flatten(const YAML::Node& node, const std::string& prefix);
  std::string where(const std::string& key, const YAML::Node& node) const;
  void convert(const std::string& key, const YAML::Node& node, bool& out);
  void convert(const std::string& key, const YAML::Node& node, int& out);
  void convert(const std::string& key, const YAML::Node& node, int64_t& out);
  void convert(const std::string& key, const YAML::Node& node, double& out);
  void convert(const std::string& key, const YAML::Node& node, std::string& out);
  void convert(const std::string& key, const YAML::Node& node, std::vector<double>& out);
  void convert(const std::string& key, const YAML::Node& node, std::vector<int>& out);
  void convert(const std::string& key, const YAML::Node& node, std::vector<std::string>& out);

  std::string source_name_;
  std::map<std::string, YAML::Node> leaves_;  // dotted key -> scalar or sequence node
  std::set<std::string> known_;
  std::vector<std::string> errors_;
};

/// Prints an options struct as the YAML a loader reads back, one `key: value  # doc` line per key,
/// grouped by section in visit() order.
class ConfigPrinter {
 public:
  template <class T>
  void operator()(const std::string& key, const T& value, const char* doc) {
    add(key, format(value), doc);
  }
  /// The YAML text, preceded by `header` as comment lines when it is not empty.
  std::string str(const std::string& header = "") const;

 private:
  void add(const std::string& key, const std::string& value, const char* doc);
  static std::string format(bool v);
  static std::string format(int v);
  static std::string format(int64_t v);
  static std::string format(double v);
  static std::string format(const std::string& v);
  static std::string format(const std::vector<double>& v);
  static std::string format(const std::vector<int>& v);
  static std::string format(const std::vector<std::string>& v);

  struct Entry {
    std::string section, name, value, doc;
  };
  std::vector<Entry> entries_;
};

/// Loads `Options` from `path` (defaults for missing keys) and validates it. Throws ConfigError
/// naming the file and every bad key at once.
template <class Options>
Options load_options(const std::string& path) {
  Options options;
  ConfigLoader loader = ConfigLoader::from_file(path);
  options.visit(loader);
  loader.finish(options.validate());
  return options;
}

/// Same as load_options, from YAML text (tests, embedded defaults).
template <class Options>
Options load_options_from_string(const std::string& yaml_text, const std::string& source_name) {
  Options options;
  ConfigLoader loader = ConfigLoader::from_string(yaml_text, source_name);
  options.visit(loader);
  loader.finish(options.validate());
  return options;
}

/// The effective configuration as YAML (what `--print-config` shows).
template <class Options>
std::string print_options(const Options& options, const std::string& header = "") {
  ConfigPrinter printer;
  const_cast<Options&>(options).visit(printer);  // visit() only reads through a printer
  return printer.str(header);
}

/// Helper for validate(): formats "key = value: rule".
std::string problem(const std::string& key, const std::string& value, const std::string& rule);
std::string problem(const std::string& key, double value, const std::string& rule);

}  // namespace wingman::common
