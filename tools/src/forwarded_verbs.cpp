// SPDX-License-Identifier: MIT
// `wingman train` hands over to wingman-train: the verbs that run in an executable of their own.
#include "wingman/tools/forwarded_verbs.hpp"

#include "train_verb.hpp"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

#include <unistd.h>

namespace wingman::tools {

const std::vector<ForwardedVerb>& forwarded_verbs() {
  static const std::vector<ForwardedVerb> verbs = {{"train", "wingman-train", kTrainVerbDescription}};
  return verbs;
}

std::string sibling_executable(const std::string& executable) {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return "";
  return (self.parent_path() / executable).string();
}

ForwardedVerbs::ForwardedVerbs(CLI::App& app) {
  for (const ForwardedVerb& v : forwarded_verbs()) {
    CLI::App* sub = app.add_subcommand(v.name, v.description);
    sub->prefix_command();  // the first argument and all after it are left unparsed
    sub->allow_extras();
    sub->set_help_flag();  // --help is the executable's
    verbs_.emplace_back(&v, sub);
  }
}

int ForwardedVerbs::run_if_chosen(int argc, char** argv, std::ostream& err) const {
  for (const auto& [verb, sub] : verbs_) {
    if (!*sub) continue;
    const std::string exe = sibling_executable(verb->executable);
    if (exe.empty()) {
      err << "wingman " << verb->name << ": error: cannot find " << verb->executable
          << ": /proc/self/exe (where wingman is) is not readable" << std::endl;
      return 1;
    }
    std::vector<char*> args;
    args.push_back(const_cast<char*>(exe.c_str()));
    for (int i = 1; i < argc; ++i) args.push_back(argv[i]);
    args.push_back(nullptr);
    err << std::flush;
    execv(exe.c_str(), args.data());
    err << "wingman " << verb->name << ": error: cannot start " << exe << " (" << std::strerror(errno) << "): `wingman "
        << verb->name << "` runs in " << verb->executable
        << ", built and installed beside wingman (cmake --build: target " << verb->executable << "; cmake --install)"
        << std::endl;
    return 1;
  }
  return -1;
}

}  // namespace wingman::tools
