// SPDX-License-Identifier: MIT
// Child processes through posix_spawn: started in order, watched with waitpid, stopped with SIGTERM then SIGKILL.
#include "wingman/launcher/process_group.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace wingman::launcher {

namespace {

using Clock = std::chrono::steady_clock;

/// Creates (truncates) `path` so that a failure names the file, before the child opens it again.
void check_output_file(const std::string& path, const std::string& program, const char* stream) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    throw std::runtime_error(
        fmt::format("{}: cannot create its {} file {}: {}", program, stream, path, std::strerror(errno)));
  }
  ::close(fd);
}

/// posix_spawn's attributes and file actions, released on scope exit.
class SpawnSetup {
 public:
  SpawnSetup() {
    posix_spawnattr_init(&attr_);
    posix_spawn_file_actions_init(&actions_);
  }
  ~SpawnSetup() {
    posix_spawn_file_actions_destroy(&actions_);
    posix_spawnattr_destroy(&attr_);
  }
  SpawnSetup(const SpawnSetup&) = delete;
  SpawnSetup& operator=(const SpawnSetup&) = delete;
  posix_spawnattr_t attr_;
  posix_spawn_file_actions_t actions_;
};

// The last stop signal's number (0: none). Written by the handler only.
std::atomic<int> g_stop_signal{0};
// Whether a StopSignals is alive (one at a time).
std::atomic<bool> g_stop_signals_alive{false};
struct sigaction g_previous[3];
constexpr int kStopSignals[3] = {SIGINT, SIGTERM, SIGHUP};

extern "C" void on_stop_signal(int sig) { g_stop_signal.store(sig); }

}  // namespace

std::string shell_word(const std::string& word) {
  const bool safe = !word.empty() && word.find_first_not_of(
                                         "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                         "0123456789_-+=/.,:@%") == std::string::npos;
  if (safe) return word;
  std::string quoted = "'";
  for (const char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string ProcessSpec::command_line() const {
  std::string line;
  for (const auto& a : argv) line += (line.empty() ? "" : " ") + shell_word(a);
  return line;
}

int exit_code_from_status(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return 255;
}

ProcessGroup::~ProcessGroup() { stop_all(kDefaultGraceS); }

size_t ProcessGroup::start(const ProcessSpec& spec) {
  if (spec.argv.empty() || spec.argv.front().empty())
    throw std::invalid_argument(fmt::format("process '{}': empty command", spec.name));
  const std::string& program = spec.label();
  SpawnSetup setup;
  // The child starts with every signal unblocked and the stop signals at their defaults (this process may block or
  // catch them: StopSignals).
  sigset_t none, defaults;
  sigemptyset(&none);
  sigemptyset(&defaults);
  for (const int sig : {SIGINT, SIGQUIT, SIGTERM, SIGHUP, SIGPIPE, SIGCHLD}) sigaddset(&defaults, sig);
  posix_spawnattr_setsigmask(&setup.attr_, &none);
  posix_spawnattr_setsigdefault(&setup.attr_, &defaults);
  posix_spawnattr_setflags(&setup.attr_, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  if (!spec.stdout_path.empty()) {
    check_output_file(spec.stdout_path, program, "stdout");
    posix_spawn_file_actions_addopen(&setup.actions_, STDOUT_FILENO, spec.stdout_path.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
  }
  if (spec.stderr_to_stdout) {
    posix_spawn_file_actions_adddup2(&setup.actions_, STDOUT_FILENO, STDERR_FILENO);
  } else if (!spec.stderr_path.empty()) {
    check_output_file(spec.stderr_path, program, "stderr");
    posix_spawn_file_actions_addopen(&setup.actions_, STDERR_FILENO, spec.stderr_path.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
  }
  std::vector<char*> args;
  args.reserve(spec.argv.size() + 1);
  for (const auto& a : spec.argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = -1;
  // The environment: this process's, with spec.env's KEY=VALUE entries replacing or adding keys.
  std::vector<std::string> env_entries;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry = *e;
    const std::string key = entry.substr(0, entry.find('='));
    bool replaced = false;
    for (const auto& over : spec.env) replaced = replaced || over.substr(0, over.find('=')) == key;
    if (!replaced) env_entries.push_back(entry);
  }
  env_entries.insert(env_entries.end(), spec.env.begin(), spec.env.end());
  std::vector<char*> envp;
  envp.reserve(env_entries.size() + 1);
  for (auto& e : env_entries) envp.push_back(e.data());
  envp.push_back(nullptr);
  const int rc = posix_spawnp(&pid, args.front(), &setup.actions_, &setup.attr_, args.data(), envp.data());
  if (rc != 0)
    throw std::runtime_error(fmt::format("{}: cannot start {}: {}", program, spec.argv.front(), std::strerror(rc)));
  children_.push_back(Child{spec, pid, std::nullopt});
  return children_.size() - 1;
}

int ProcessGroup::run(const ProcessSpec& spec) { return wait(start(spec)); }

std::optional<int> ProcessGroup::reap(Child& child, bool block) {
  if (child.exit_code) return child.exit_code;
  int status = 0;
  for (;;) {
    const pid_t r = ::waitpid(child.pid, &status, block ? 0 : WNOHANG);
    if (r == child.pid) {
      child.exit_code = exit_code_from_status(status);
      return child.exit_code;
    }
    if (r == 0) return std::nullopt;  // still running
    if (errno == EINTR) continue;     // a signal (StopSignals) while blocking: wait again
    // ECHILD: somebody else reaped it; nothing more can be known.
    child.exit_code = 255;
    return child.exit_code;
  }
}

int ProcessGroup::wait(size_t index) { return *reap(children_.at(index), true); }

std::optional<int> ProcessGroup::poll(size_t index) { return reap(children_.at(index), false); }

std::optional<size_t> ProcessGroup::wait_any(const std::vector<size_t>& indices,
                                             const std::function<bool()>& stop_requested, int poll_ms) {
  if (indices.empty()) throw std::invalid_argument("ProcessGroup::wait_any: no process to wait for");
  for (;;) {
    for (const size_t i : indices) {
      if (poll(i)) return i;
    }
    if (stop_requested && stop_requested()) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(poll_ms));
  }
}

void ProcessGroup::stop(const std::vector<size_t>& indices, double grace_s) {
  for (const size_t i : indices) {
    if (!poll(i)) ::kill(children_.at(i).pid, SIGTERM);
  }
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(grace_s > 0.0 ? grace_s : 0.0));
  for (;;) {
    bool running = false;
    for (const size_t i : indices) running = running || !poll(i);
    if (!running) return;
    if (Clock::now() >= deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  for (const size_t i : indices) {
    if (!poll(i)) {
      ::kill(children_.at(i).pid, SIGKILL);
      wait(i);
    }
  }
}

void ProcessGroup::stop_all(double grace_s) {
  std::vector<size_t> indices;
  for (size_t i = children_.size(); i-- > 0;) indices.push_back(i);
  stop(indices, grace_s);
}

StopSignals::StopSignals() {
  if (g_stop_signals_alive.exchange(true)) throw std::logic_error("StopSignals: one is already active");
  g_stop_signal.store(0);
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: a blocking wait returns EINTR and looks at requested()
  for (int i = 0; i < 3; ++i) ::sigaction(kStopSignals[i], &sa, &g_previous[i]);
}

StopSignals::~StopSignals() {
  for (int i = 0; i < 3; ++i) ::sigaction(kStopSignals[i], &g_previous[i], nullptr);
  g_stop_signals_alive.store(false);
}

bool StopSignals::requested() const { return g_stop_signal.load() != 0; }
int StopSignals::signal() const { return g_stop_signal.load(); }

}  // namespace wingman::launcher
