// SPDX-License-Identifier: MIT
// `wingman spy`: starts LCM's lcm-spy with the Wingman message classes, so every channel decodes.
#pragma once

#include <string>
#include <vector>

namespace wingman::tools {

/// Options of `wingman spy`.
struct SpyOptions {
  std::string lcm_url;        ///< LCM URL to listen on; "" = LCM_DEFAULT_URL or LCM's default
  std::string java = "java";  ///< Java runtime to start
  std::string types_jar;      ///< jar of the wingman message classes; "" = the one built with this binary
  bool dry_run = false;       ///< print the command instead of running it
};

/// The java command line that starts lcm.spy.Spy with lcm.jar, jchart2d.jar and the types jar.
/// Debian's lcm-spy wrapper passes -Xincgc, which Java 17 rejects, so we start the class directly.
/// Throws std::runtime_error naming any jar that does not exist.
std::vector<std::string> spy_command(const SpyOptions& options);

/// Runs lcm-spy in the foreground (replaces nothing; waits for it). Returns its exit code.
int run_spy(const SpyOptions& options);

}  // namespace wingman::tools
