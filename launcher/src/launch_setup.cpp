// SPDX-License-Identifier: MIT
// The checks every launcher makes before it starts anything.
#include "wingman/launcher/launch_setup.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace wingman::launcher {

namespace fs = std::filesystem;

ProcessSpec process(std::string name, std::vector<std::string> argv) {
  ProcessSpec spec;
  spec.name = std::move(name);
  spec.argv = std::move(argv);
  return spec;
}

int run_in_foreground(const ProcessSpec& spec) {
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  struct sigaction old_int {};
  struct sigaction old_quit {};
  ::sigaction(SIGINT, &ignore, &old_int);
  ::sigaction(SIGQUIT, &ignore, &old_quit);
  const auto restore = [&] {
    ::sigaction(SIGINT, &old_int, nullptr);
    ::sigaction(SIGQUIT, &old_quit, nullptr);
  };
  try {
    ProcessGroup group;
    const int rc = group.run(spec);
    restore();
    return rc;
  } catch (...) {
    restore();
    throw;
  }
}

std::string output_tail(const std::string& path, size_t lines) {
  std::ifstream in(path);
  std::deque<std::string> last;
  for (std::string line; std::getline(in, line);) {
    last.push_back(line);
    if (last.size() > lines) last.pop_front();
  }
  std::string text;
  for (const auto& l : last) text += l + "\n";
  return text;
}

std::string executable_dir() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot read /proc/self/exe to find the executables: give --bin-dir");
  return self.parent_path().string();
}

std::string executables_dir(const std::string& bin_dir, const std::vector<std::string>& names) {
  const std::string dir = bin_dir.empty() ? executable_dir() : bin_dir;
  for (const auto& name : names) {
    const fs::path p = fs::path(dir) / name;
    std::error_code ec;
    if (!fs::is_regular_file(p, ec) || ::access(p.c_str(), X_OK) != 0)
      throw std::invalid_argument(
          fmt::format("{} is missing: build first (tools/build.sh) or give --bin-dir", p.string()));
  }
  return dir;
}

std::string private_bus_url(const std::string& given, const std::string& verb, const std::string& script) {
  if (!given.empty()) return given;
  const char* env = std::getenv("WINGMAN_LCM_URL");
  if (env != nullptr && *env != '\0') return env;
  throw std::invalid_argument(fmt::format(
      "no LCM bus: run {} in a private network namespace (tools/netns_run.sh sets WINGMAN_LCM_URL; {} does it for "
      "you) or give --lcm-url",
      verb, script));
}

}  // namespace wingman::launcher
