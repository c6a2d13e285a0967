// SPDX-License-Identifier: MIT
// Helpers for tests that run the real processes.
#include "test_support.hpp"

#include <lcm/lcm-cpp.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace wingman::testing {
namespace {

std::string env_or(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return v && *v ? v : fallback;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

std::string first_difference(const ChannelPayloads& expected, const ChannelPayloads& actual) {
  for (const auto& [channel, msgs] : expected) {
    const auto it = actual.find(channel);
    if (it == actual.end()) return "channel " + channel + " missing";
    if (it->second.size() != msgs.size())
      return "channel " + channel + ": " + std::to_string(it->second.size()) + " messages, expected " +
             std::to_string(msgs.size());
    for (size_t i = 0; i < msgs.size(); ++i) {
      if (it->second[i] != msgs[i]) return "channel " + channel + ": message " + std::to_string(i) + " differs";
    }
  }
  for (const auto& [channel, msgs] : actual) {
    if (!expected.count(channel))
      return "unexpected channel " + channel + " (" + std::to_string(msgs.size()) + " messages)";
  }
  return "";
}

std::string bin_path(const std::string& name) { return env_or("WINGMAN_BIN_DIR", "build/bin") + "/" + name; }
std::string source_path(const std::string& relative) { return env_or("WINGMAN_SOURCE_DIR", ".") + "/" + relative; }

TempDir::TempDir() {
  std::string tmpl = env_or("TMPDIR", "/tmp") + "/wingman-test-XXXXXX";
  if (mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("cannot create a temporary directory in " + tmpl);
  path_ = tmpl;
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

Child::Child(const std::vector<std::string>& argv) {
  if (argv.empty()) throw std::runtime_error("Child: empty command");
  const std::string out = dir_.file("stdout"), err = dir_.file("stderr");
  pid_ = fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) {
    const int fo = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int fe = open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fo, 1);
    dup2(fe, 2);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execvp(args[0], args.data());
    dprintf(2, "exec %s failed\n", args[0]);
    _exit(127);
  }
}

Child::~Child() {
  if (!reaped_ && pid_ > 0) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
}

void Child::signal(int sig) const {
  if (!reaped_) kill(pid_, sig);
}

int Child::wait(std::chrono::milliseconds timeout) {
  if (reaped_) return exit_code_;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    int status = 0;
    const pid_t r = waitpid(pid_, &status, WNOHANG);
    if (r == pid_) {
      reaped_ = true;
      exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      return exit_code_;
    }
    if (std::chrono::steady_clock::now() >= deadline) return -1;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

bool Child::running() { return wait(std::chrono::milliseconds(0)) == -1; }
std::string Child::out() const { return slurp(dir_.file("stdout")); }
std::string Child::err() const { return slurp(dir_.file("stderr")); }

RunResult run(const std::vector<std::string>& argv, std::chrono::milliseconds timeout) {
  Child c(argv);
  int rc = c.wait(timeout);
  if (rc == -1) {
    c.signal(SIGKILL);
    c.wait(std::chrono::seconds(5));
    rc = -1;
  }
  return {rc, c.out(), c.err()};
}

std::vector<LogEvent> read_log(const std::string& path) {
  lcm::LogFile log(path, "r");
  if (!log.good()) throw std::runtime_error(path + ": cannot open LCM log");
  std::vector<LogEvent> events;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    const auto* p = static_cast<const uint8_t*>(ev->data);
    events.push_back({ev->timestamp, ev->channel, std::vector<uint8_t>(p, p + ev->datalen)});
  }
  return events;
}

void write_log(const std::string& path, const std::vector<LogEvent>& events) {
  lcm::LogFile log(path, "w");
  if (!log.good()) throw std::runtime_error(path + ": cannot create LCM log");
  for (const auto& e : events) {
    lcm::LogEvent ev;
    ev.eventnum = 0;
    ev.timestamp = e.timestamp;
    ev.channel = e.channel;
    ev.datalen = static_cast<int32_t>(e.data.size());
    ev.data = const_cast<uint8_t*>(e.data.data());
    if (log.writeEvent(&ev) != 0) throw std::runtime_error(path + ": write failed");
  }
}

std::map<std::string, std::vector<std::vector<uint8_t>>> payloads_by_channel(
    const std::vector<LogEvent>& events, const std::string& channel_prefix_to_skip) {
  std::map<std::string, std::vector<std::vector<uint8_t>>> out;
  for (const auto& e : events) {
    if (!channel_prefix_to_skip.empty() && e.channel.rfind(channel_prefix_to_skip, 0) == 0) continue;
    out[e.channel].push_back(e.data);
  }
  return out;
}

}  // namespace wingman::testing

namespace wingman::testing {
std::string test_bin_path(const std::string& name) {
  return env_or("WINGMAN_TEST_BIN_DIR", "build/tests") + "/" + name;
}

std::string netns_lcm_url() {
  const char* in = std::getenv("WINGMAN_IN_NETNS");
  const char* url = std::getenv("WINGMAN_LCM_URL");
  if (!in || std::string(in) != "1" || !url) {
    throw std::runtime_error("this test multicasts: run it through tools/netns_run.sh (ctest does)");
  }
  return url;
}
}  // namespace wingman::testing
