// SPDX-License-Identifier: MIT
// What every launcher checks before it starts anything: the executables, and the private bus it may multicast on.
#pragma once

#include "wingman/launcher/process_group.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace wingman::launcher {

/// A ProcessSpec named `name` running `argv` (output inherited, no extra environment).
ProcessSpec process(std::string name, std::vector<std::string> argv);

/// Runs `spec` to its end as system() does: while it runs, this process ignores SIGINT and SIGQUIT (the child gets
/// them, at their defaults: Ctrl-C stops the child, and then this process reports its exit). Returns the exit code
/// (128 + signal when killed). Throws std::runtime_error naming the program when it cannot be started.
int run_in_foreground(const ProcessSpec& spec);

/// The last `lines` lines of the file at `path` (a process's output, shown when it failed); "" when it cannot be read.
std::string output_tail(const std::string& path, size_t lines);

/// The folder of the running executable (the build's or the installation's bin/), from /proc/self/exe. Throws
/// std::runtime_error when it cannot be read.
std::string executable_dir();

/// `bin_dir` when given, else executable_dir(); checks that each of `names` is an executable file there. Throws
/// std::invalid_argument naming the first missing one ("DIR/NAME is missing: build first (tools/build.sh) or give
/// --bin-dir").
std::string executables_dir(const std::string& bin_dir, const std::vector<std::string>& names);

/// The LCM bus a launcher multicasts on: `given` when not empty, else $WINGMAN_LCM_URL (set by tools/netns_run.sh in
/// its private network namespace). Throws std::invalid_argument saying how to run `verb` (e.g. "wingman fly") through
/// `script` (e.g. "tools/fly.sh") when there is none: a launcher never multicasts on the host's network.
std::string private_bus_url(const std::string& given, const std::string& verb, const std::string& script);

}  // namespace wingman::launcher
