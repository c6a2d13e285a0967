// SPDX-License-Identifier: MIT
// YAML configuration: options structs are read and printed through one visit() list of keys.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <map>
#include <optional>
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

/// Where a configuration comes from: YAML files read in order, then `key=value` overrides (the command line's
/// `--config A --config B --set k=v`). A key in a later file replaces the same key of an earlier one; a `--set`
/// replaces both. No file and no `--set`: the built-in defaults.
struct ConfigSources {
  std::vector<std::string> files;  ///< --config FILE, in order
  std::vector<std::string> sets;   ///< --set KEY=VALUE, in order (VALUE: a YAML scalar or flow sequence)

  bool empty() const { return files.empty() && sets.empty(); }
  /// "built-in defaults", "a.yaml", or "a.yaml, b.yaml, --set k=v" (for --print-config headers).
  std::string describe() const;
};

/// One `--set KEY=VALUE`, parsed: KEY a dotted name (letters, digits, '_', '-', '.'; no empty part), VALUE YAML
/// (a scalar, a flow sequence or a flow mapping), bounded as every configuration text (check_yaml_bounds).
struct SetAssignment {
  std::string key;
  YAML::Node value;
};

/// Parses `assignment`; returns nullopt and sets `*error` to one line naming it ("--set 'x': expected KEY=VALUE with
/// KEY a dotted name (e.g. EXAMPLE)", "--set KEY: not valid YAML: ...") when it is not one. The one parser of --set
/// for process configurations and scenario copies (`wingman scenario set`).
std::optional<SetAssignment> parse_set_assignment(const std::string& assignment, const std::string& example,
                                                  std::string* error);

/// Reads an options struct from YAML files of sections (`section: {key: value}`), collecting every
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
  /// Layers `sources`: every file in order, then every `--set`. Each key remembers the file (and line) or the
  /// `--set` that gave it, and every problem names that source. Throws ConfigError at once for a file that is
  /// unreadable or not YAML; a `--set` that is not KEY=VALUE, or whose value is not a scalar or a sequence, is one
  /// of the problems finish() reports.
  static ConfigLoader from_sources(const ConfigSources& sources);

  template <class T>
  void operator()(const std::string& key, T& value, const char* /*doc*/) {
    known_.insert(key);
    auto it = leaves_.find(key);
    if (it == leaves_.end()) return;
    current_ = &it->second;
    convert(key, it->second.node, value);
    current_ = nullptr;
  }

  /// Throws ConfigError listing every conversion error, every unknown key and every entry of
  /// `validation_errors` (from the options' validate()), or returns if there are none.
  void finish(const std::vector<std::string>& validation_errors) const;

  /// Problems found so far (conversion errors only; unknown keys are found by finish()).
  const std::vector<std::string>& errors() const { return errors_; }

 private:
  /// One value and where it came from.
  struct Leaf {
    YAML::Node node;     ///< scalar, sequence or null
    std::string source;  ///< the file name, or "--set"
    bool has_lines;      ///< whether node's line numbers refer to `source` (not for a --set value)
  };
  ConfigLoader(std::string source_name, const YAML::Node& root);
  explicit ConfigLoader(std::string source_name) : source_name_(std::move(source_name)) {}
  void flatten(const YAML::Node& node, const std::string& prefix, const std::string& source);
  void add_set(const std::string& assignment);
  /// "file:line: key", or "--set key" for a --set value: `node` of the leaf being converted (current_).
  std::string where(const std::string& key, const YAML::Node& node) const;
  std::string where(const std::string& key, const YAML::Node& node, const std::string& source, bool has_lines) const;
  void convert(const std::string& key, const YAML::Node& node, bool& out);
  void convert(const std::string& key, const YAML::Node& node, int& out);
  void convert(const std::string& key, const YAML::Node& node, int64_t& out);
  void convert(const std::string& key, const YAML::Node& node, double& out);
  void convert(const std::string& key, const YAML::Node& node, std::string& out);
  void convert(const std::string& key, const YAML::Node& node, std::vector<double>& out);
  void convert(const std::string& key, const YAML::Node& node, std::vector<int>& out);
  void convert(const std::string& key, const YAML::Node& node, std::vector<std::string>& out);

  std::string source_name_;             // every source, for problems that no single key's source owns
  std::map<std::string, Leaf> leaves_;  // dotted key -> its value from the last source that gave it
  const Leaf* current_ = nullptr;       // the leaf convert() is working on (names its source)
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

/// Loads `Options` from layered files and `--set` overrides (defaults for keys none gives) and validates it.
/// Throws ConfigError naming, for each bad key, the file or `--set` that gave it, every problem at once.
template <class Options>
Options load_options(const ConfigSources& sources) {
  Options options;
  if (sources.empty()) {
    if (const auto problems = options.validate(); !problems.empty())
      throw ConfigError("built-in defaults invalid: " + problems.front());
    return options;
  }
  ConfigLoader loader = ConfigLoader::from_sources(sources);
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
