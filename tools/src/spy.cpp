// SPDX-License-Identifier: MIT
// `wingman spy`: builds the java command line of lcm.spy.Spy with our jars and runs it in the foreground.
#include "wingman/tools/spy.hpp"

#include <fmt/format.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <utility>

extern char** environ;

namespace wingman::tools {
namespace {

/// Debian's libjchart2d-java; lcm-spy draws its charts with it and does not start without it.
constexpr const char* kJchart2dJar = "/usr/share/java/jchart2d.jar";

bool is_regular_file(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

/// Pid of the running lcm-spy, read by the signal handler (0 when none).
std::atomic<pid_t> g_child_pid{0};

extern "C" void forward_signal(int sig) {
  const pid_t pid = g_child_pid.load();
  if (pid > 0) ::kill(pid, sig);
}

/// Installs forward_signal for SIGINT and SIGTERM for its lifetime, restores the old handlers after.
class SignalForwarder {
 public:
  SignalForwarder() {
    struct sigaction sa {};
    sa.sa_handler = forward_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;  // no SA_RESTART: waitpid returns EINTR and we wait again
    ::sigaction(SIGINT, &sa, &old_int_);
    ::sigaction(SIGTERM, &sa, &old_term_);
  }
  ~SignalForwarder() {
    ::sigaction(SIGINT, &old_int_, nullptr);
    ::sigaction(SIGTERM, &old_term_, nullptr);
  }
  SignalForwarder(const SignalForwarder&) = delete;
  SignalForwarder& operator=(const SignalForwarder&) = delete;

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

/// Quotes one argument for a POSIX shell when it needs it (for --dry-run output only).
std::string shell_quote(const std::string& arg) {
  if (!arg.empty() && arg.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                                            "_-+=/.,:@%") == std::string::npos) {
    return arg;
  }
  std::string quoted = "'";
  for (char c : arg) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
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
  const std::vector<std::string> cmd = spy_command(options);
  if (options.dry_run) {
    std::string line;
    for (const auto& arg : cmd) line += (line.empty() ? "" : " ") + shell_quote(arg);
    std::fputs((line + "\n").c_str(), stdout);
    std::fflush(stdout);
    return 0;
  }

  std::vector<char*> argv;
  argv.reserve(cmd.size() + 1);
  for (const auto& arg : cmd) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);

  SignalForwarder forwarder;
  pid_t pid = 0;
  const int rc = ::posix_spawnp(&pid, argv[0], nullptr, nullptr, argv.data(), environ);
  if (rc != 0) {
    throw std::runtime_error(fmt::format("spy: cannot start '{}': {}", options.java, std::strerror(rc)));
  }
  g_child_pid.store(pid);

  int status = 0;
  pid_t waited = 0;
  do {
    waited = ::waitpid(pid, &status, 0);
  } while (waited < 0 && errno == EINTR);
  g_child_pid.store(0);
  if (waited < 0) throw std::runtime_error(fmt::format("spy: waitpid failed: {}", std::strerror(errno)));
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return 1;
}

}  // namespace wingman::tools
