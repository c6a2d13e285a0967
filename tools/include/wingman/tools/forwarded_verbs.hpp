// SPDX-License-Identifier: MIT
// `wingman` verbs that run in an executable of their own beside it: `train` in wingman-train (libtorch).
#pragma once

#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace CLI {
class App;
}

namespace wingman::tools {

/// A verb whose libraries would slow every start of `wingman` (libtorch's static initialisers alone take ~0.7 s,
/// docs/benchmarks.md), built into an executable of its own installed beside `wingman`.
struct ForwardedVerb {
  std::string name;         ///< the verb as typed: `wingman <name> ...`
  std::string executable;   ///< the file name of its executable, in the folder of `wingman`'s own
  std::string description;  ///< what `wingman --help` says of it (the executable's own help says the same)
};

/// The forwarded verbs: `train` (wingman-train).
const std::vector<ForwardedVerb>& forwarded_verbs();

/// The file `executable` in the folder of the running executable (/proc/self/exe); "" when that cannot be read.
std::string sibling_executable(const std::string& executable);

/// Lists the forwarded verbs in `wingman --help` and hands a chosen one over to its executable.
class ForwardedVerbs {
 public:
  /// Registers each forwarded verb on `app` as a subcommand that parses nothing: every argument after it, --help
  /// included, is its executable's to read.
  explicit ForwardedVerbs(CLI::App& app);

  /// After parsing: when a forwarded verb was chosen, replaces this process with its executable (execv of
  /// sibling_executable() with argv[1..argc), the same environment, standard streams and process id: its exit code
  /// and signals are the verb's). Returns only when that fails: 1, with one line on `err` naming the missing
  /// executable. Returns -1 when none of these verbs was chosen.
  int run_if_chosen(int argc, char** argv, std::ostream& err) const;

 private:
  std::vector<std::pair<const ForwardedVerb*, CLI::App*>> verbs_;
};

}  // namespace wingman::tools
