// SPDX-License-Identifier: MIT
// How every `wingman` verb's --help shows its options' defaults (wingman and wingman-train alike).
#pragma once

#include <CLI/CLI.hpp>

#include <string>

namespace wingman::tools {

/// Every option's help shows its default, the value of the variable it is bound to (always_capture_default), but
/// not a required option's (it has none) nor an empty list's ("[]": not given; the description says what that does).
/// A default with a space is quoted, so that it does not run into the description.
inline void tidy_defaults(CLI::App& app) {
  for (CLI::Option* o : app.get_options()) {
    const std::string d = o->get_default_str();
    if (o->get_required() || d == "[]")
      o->default_str("");
    else if (d.find(' ') != std::string::npos)
      o->default_str('"' + d + '"');
  }
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) tidy_defaults(*sub);
}

}  // namespace wingman::tools
