// SPDX-License-Identifier: MIT
// A set of child processes started, watched and stopped together (a flight's pipeline, its logger, its simulator).
#pragma once

#include <sys/types.h>

#include <atomic>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace wingman::launcher {

/// One child process.
struct ProcessSpec {
  std::string name;               ///< for messages, e.g. "wingman-detector" (empty: argv[0])
  std::vector<std::string> argv;  ///< argv[0]: a path, or a name looked up on PATH; not empty
  std::string stdout_path;        ///< the child's stdout goes to this file (truncated); "" = the launcher's stdout
  std::string stderr_path;        ///< the same for stderr
  bool stderr_to_stdout = false;  ///< stderr goes where stdout goes (stderr_path unused), as a shell's 2>&1
  std::vector<std::string> env;   ///< KEY=VALUE set for the child over the launcher's environment

  /// "name" or argv[0].
  const std::string& label() const { return name.empty() ? argv.front() : name; }
  /// The command line as a person would type it (arguments with spaces or quotes in single quotes): for messages.
  std::string command_line() const;
};

/// Appends the arguments `more` to the argument list `argv` (a ProcessSpec's argv, or `--set` lists built for one).
inline void append_args(std::vector<std::string>& argv, const std::vector<std::string>& more) {
  argv.insert(argv.end(), more.begin(), more.end());
}

/// Child processes started in order and stopped together. Every child still running when the group is destroyed
/// is stopped (SIGTERM, then SIGKILL after `kDefaultGraceS`), so no child outlives a launcher that fails or throws.
/// Exit codes: the child's exit status, or 128 + the signal that ended it (as a shell reports them).
/// Not thread-safe: one thread owns the group.
class ProcessGroup {
 public:
  /// Seconds a child gets to end after SIGTERM before it is killed, when the group is destroyed.
  static constexpr double kDefaultGraceS = 10.0;

  ProcessGroup() = default;
  ~ProcessGroup();
  ProcessGroup(const ProcessGroup&) = delete;
  ProcessGroup& operator=(const ProcessGroup&) = delete;

  /// Starts `spec` and returns its index in the group. Throws std::runtime_error naming the program when it cannot
  /// be started (not found, not executable, an output file that cannot be created) and std::invalid_argument for an
  /// empty argv.
  size_t start(const ProcessSpec& spec);
  /// Starts `spec`, waits for it and returns its exit code (it stays in the group, ended).
  int run(const ProcessSpec& spec);

  /// Waits for child `index` to end; returns its exit code at once when it has ended before.
  int wait(size_t index);
  /// Its exit code when child `index` has ended, else nullopt (does not block).
  std::optional<int> poll(size_t index);
  /// Waits until one of `indices` ends (returns its index) or `stop_requested()` is true (returns nullopt),
  /// checking every `poll_ms` milliseconds. A child that ended before counts at once. `indices` not empty.
  std::optional<size_t> wait_any(const std::vector<size_t>& indices, const std::function<bool()>& stop_requested,
                                 int poll_ms = 20);

  /// Stops `indices` in that order: SIGTERM to every one still running, then waits up to `grace_s` seconds (all
  /// together) for them, then SIGKILL to those still running and waits for them. Returns nothing: read the codes
  /// with poll().
  void stop(const std::vector<size_t>& indices, double grace_s);
  /// stop() on every child, the last started first.
  void stop_all(double grace_s);

  size_t size() const { return children_.size(); }
  const ProcessSpec& spec(size_t index) const { return children_.at(index).spec; }
  pid_t pid(size_t index) const { return children_.at(index).pid; }

 private:
  struct Child {
    ProcessSpec spec;
    pid_t pid = -1;
    std::optional<int> exit_code;
  };
  /// waitpid(WNOHANG or blocking) on one child; records its code.
  std::optional<int> reap(Child& child, bool block);

  std::vector<Child> children_;
};

/// While alive, SIGINT, SIGTERM and SIGHUP set requested() instead of ending the process, so a launcher can stop its
/// children and clean up; the previous handlers come back on destruction. One at a time per process.
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  /// A stop signal arrived (the last one's number is signal()).
  bool requested() const;
  int signal() const;
};

/// `word` as a shell needs it: bare when it holds only safe characters, else in single quotes (for messages and
/// command lines a person may copy).
std::string shell_word(const std::string& word);

/// Exit code as a shell reports it, from a waitpid() status: the exit status, or 128 + the signal.
int exit_code_from_status(int status);

}  // namespace wingman::launcher
