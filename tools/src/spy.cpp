// SPDX-License-Identifier: MIT
// `wingman spy`: builds the java command line of lcm.spy.Spy with our jars and runs it in the foreground.
#include "wingman/tools/spy.hpp"

#include "wingman/launcher/process_group.hpp"

#include <fmt/format.h>
#include <sys/stat.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <utility>

namespace wingman::tools {
namespace {

/// Debian's libjchart2d-java; lcm-spy draws its charts with it and does not start without it.
constexpr const char* kJchart2dJar = "/usr/share/java/jchart2d.jar";

bool is_regular_file(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

}  // namespace

std::vector<std::string> spy_command(const SpyOptions& options) {
  if (options.java.empty()) throw std::runtime_error("spy: java is empty: name a Java runtime (e.g. java)");
  const std::string types_jar = options.types_jar.empty() ? std::string(WINGMAN_LCMTYPES_JAR) : options.types_jar;
  const std::vector<std::pair<std::string, std::string>> jars = {
      {WINGMAN_LCM_JAR, "lcm.jar (Debian package liblcm-java)"},
      {kJchart2dJar, "jchart2d.jar (Debian package libjchart2d-java)"},
      {types_jar, options.types_jar.empty() ? "the wingman types jar (build target wingman_lcmtypes_jar)"
                                            : "the wingman types jar (--types-jar)"}};
  std::string missing;
  for (const auto& [path, what] : jars) {
    if (!is_regular_file(path)) missing += fmt::format("{}{} not found: {}", missing.empty() ? "" : "; ", what, path);
  }
  if (!missing.empty()) throw std::runtime_error("spy: " + missing);

  std::string url = options.lcm_url;
  if (url.empty()) {
    if (const char* env = std::getenv("LCM_DEFAULT_URL"); env != nullptr) url = env;
  }

  // The flags of Debian's /usr/bin/lcm-spy without -Xincgc (removed in Java 9, fatal on Java 17),
  // with a larger heap: every channel keeps its newest message, and camera frames are megabytes.
  std::vector<std::string> cmd = {options.java,
                                  "-Djava.net.preferIPv4Stack=true",
                                  "-Xmx256m",
                                  "-Xms64m",
                                  "-ea",
                                  "-cp",
                                  fmt::format("{}:{}:{}", jars[0].first, jars[1].first, jars[2].first),
                                  "lcm.spy.Spy"};
  // lcm.spy.Spy (LCM 1.3.1) takes "-l URL", "--lcm-url URL" or "--lcm-url=URL"; without one it
  // uses LCM_DEFAULT_URL or LCM's default.
  if (!url.empty()) cmd.push_back("--lcm-url=" + url);
  return cmd;
}

int run_spy(const SpyOptions& options) {
  launcher::ProcessSpec java;
  java.name = "spy";
  java.argv = spy_command(options);
  if (options.dry_run) {
    std::fputs((java.command_line() + "\n").c_str(), stdout);
    std::fflush(stdout);
    return 0;
  }
  // Ctrl-C or SIGTERM to `wingman spy` is passed on to lcm-spy, which then ends; its exit code is ours.
  launcher::StopSignals signals;
  launcher::ProcessGroup group;
  const size_t child = group.start(java);  // names the java runtime when it cannot start
  if (!group.wait_any({child}, [&] { return signals.requested(); })) ::kill(group.pid(child), signals.signal());
  return group.wait(child);
}

}  // namespace wingman::tools
