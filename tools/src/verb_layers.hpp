// SPDX-License-Identifier: MIT
// Internal: a verb's options as data. --config FILE... and --set KEY=VALUE... through common's one loader, the flags
// given on the command line as the last --set layer (they win), and --print-config.
#pragma once

#include "run_verb.hpp"

#include <CLI/CLI.hpp>
#include <wingman/common/config.hpp>

#include <initializer_list>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

namespace wingman::tools {

/// `problems` as a library's validate() words them (each line beginning with a field's or a flag's name), with each
/// name of `to_key` at the start of a line replaced by its key: the lines a verb's validate() returns.
inline std::vector<std::string> named_by_key(
    std::vector<std::string> problems, std::initializer_list<std::pair<std::string_view, std::string_view>> to_key) {
  for (std::string& line : problems) {
    for (const auto& [name, key] : to_key) {
      const bool starts = line.compare(0, name.size(), name) == 0 &&
                          (line.size() == name.size() || line[name.size()] == ' ' || line[name.size()] == ':');
      if (!starts) continue;
      line = std::string(key) + line.substr(name.size());
      break;
    }
  }
  return problems;
}

/// Layers for one verb whose options struct has visit() and validate(). Each flag of the verb is bound to a CLI
/// variable as usual and registered with its key; after the parse, load() reads the options from the defaults, the
/// --config files, the --set assignments and then the flags that were given.
class VerbLayers {
 public:
  /// Adds --config FILE (repeatable), --set KEY=VALUE (repeatable) and --print-config to `verb`.
  explicit VerbLayers(CLI::App* verb) : verb_(verb) {
    verb->add_option("--config", sources_.files,
                     "A file of this verb's keys (as --print-config shows them; repeatable, a later file wins); the "
                     "flags given on the command line win over it")
        ->allow_extra_args(false)
        ->type_name("FILE");
    verb->add_option("--set", sources_.sets, "KEY=VALUE over the --config files (repeatable)")
        ->allow_extra_args(false)
        ->type_name("KEY=VALUE");
    verb->add_flag("--print-config", print_config_, "Print the effective options (files, --set and flags) and exit");
  }

  /// The verb's option `flag` (added before) is the key `key`; `quote`: its value is text (a YAML string), else a
  /// number or a switch. A list option becomes a YAML flow sequence of strings.
  void key(const std::string& flag, const std::string& key, bool quote) {
    CLI::Option* option = verb_->get_option(flag);  // throws for an unknown flag
    keyed_.push_back({option, key, quote});
  }

  /// key() for each (flag, key, quote), then check_every_flag(except).
  void keys(std::initializer_list<std::tuple<const char*, const char*, bool>> keyed,
            const std::vector<std::string>& except = {}) {
    for (const auto& [flag, k, quote] : keyed) key(flag, k, quote);
    check_every_flag(except);
  }

  /// Throws std::logic_error naming a flag of the verb without a key (it would be parsed and ignored), but `except`.
  void check_every_flag(std::vector<std::string> except) const {
    except.insert(except.end(), {"--help", "--config", "--set", "--print-config"});
    for (const CLI::Option* opt : verb_->get_options()) {
      bool known = false;
      for (const auto& e : except) known = known || opt->get_name() == e;
      for (const auto& k : keyed_) known = known || k.option == opt;
      if (!known) {
        throw std::logic_error("wingman " + verb_->get_name() + ": the option " + opt->get_name() +
                               " has no key (VerbLayers::key)");
      }
    }
  }

  /// The files, the sets, then each flag given as KEY=VALUE, then `extra` (KEY=VALUE, last).
  common::ConfigSources sources(const std::vector<std::string>& extra = {}) const {
    common::ConfigSources s = sources_;
    for (const auto& k : keyed_) {
      if (k.option->count() == 0) continue;
      if (k.option->get_expected_max() > 1) {
        std::string list;
        for (const auto& item : k.option->as<std::vector<std::string>>())
          list += (list.empty() ? "" : ", ") + quoted(item);
        s.sets.push_back(k.key + "=[" + list + "]");
        continue;
      }
      const std::string value = k.option->get_expected_min() == 0 ? "true" : k.option->as<std::string>();
      s.sets.push_back(k.key + "=" + (k.quote ? quoted(value) : value));
    }
    s.sets.insert(s.sets.end(), extra.begin(), extra.end());
    return s;
  }

  /// The options from sources(extra), validated (common::ConfigError naming every bad key at once). With
  /// --print-config they are printed on `out` and `*printed` is set.
  template <class Options>
  Options load(std::ostream& out, bool* printed, const std::vector<std::string>& extra = {}) const {
    const common::ConfigSources s = sources(extra);
    Options options = common::load_options<Options>(s);
    *printed = print_config_;
    if (print_config_) {
      out << common::print_options(options, command() + ": the effective options (from " + s.describe() + ")");
    }
    return options;
  }

  /// load() for a verb that runs with the options it returns: nullopt and `*rc` 0 after --print-config, or 2 after a
  /// bad option (one line "wingman VERB: error: ..." on `err`, every bad key in it).
  template <class Options>
  std::optional<Options> load_or_exit(std::ostream& out, std::ostream& err, int* rc,
                                      const std::vector<std::string>& extra = {}) const {
    std::optional<Options> options;
    *rc = run_verb(command(), err, [&] {
      bool printed = false;
      options = load<Options>(out, &printed, extra);
      return printed ? 0 : -1;
    });
    if (*rc >= 0) return std::nullopt;
    return options;
  }

  /// "wingman VERB" (with its parent verb: "wingman bench detector").
  std::string command() const {
    std::string c = verb_->get_name();
    for (const CLI::App* p = verb_->get_parent(); p != nullptr; p = p->get_parent())
      c = (p->get_parent() == nullptr ? std::string("wingman") : p->get_name()) + " " + c;
    return c;
  }

  /// `text` as a double-quoted YAML scalar (backslashes and quotes escaped), read back as is.
  static std::string quoted(const std::string& text) {
    std::string q = "\"";
    for (const char c : text) {
      if (c == '"' || c == '\\') q += '\\';
      q += c;
    }
    return q + "\"";
  }

 private:
  struct Keyed {
    CLI::Option* option;
    std::string key;
    bool quote;
  };
  CLI::App* verb_;
  common::ConfigSources sources_;
  bool print_config_ = false;
  std::vector<Keyed> keyed_;
};

}  // namespace wingman::tools
