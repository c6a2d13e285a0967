// SPDX-License-Identifier: MIT
// ProcessGroup and StopSignals with real children: /bin/sh scripts and sleep.
#include <gtest/gtest.h>
#include <signal.h>
#include <wingman/launcher/launch_setup.hpp>
#include <wingman/launcher/process_group.hpp>

#include "../support/test_support.hpp"

#include <chrono>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace wingman::launcher {
namespace {

using wingman::testing::TempDir;

ProcessSpec sh(const std::string& script, const std::string& name = "") {
  ProcessSpec spec;
  spec.name = name;
  spec.argv = {"/bin/sh", "-c", script};
  return spec;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

bool alive(pid_t pid) { return ::kill(pid, 0) == 0; }

TEST(ProcessGroup, ReportsExitCodesAsAShellDoes) {
  ProcessGroup group;
  EXPECT_EQ(group.run(sh("exit 0")), 0);
  EXPECT_EQ(group.run(sh("exit 3")), 3);
  EXPECT_EQ(group.run(sh("kill -KILL $$")), 128 + SIGKILL);
  EXPECT_EQ(group.size(), 3u);
  EXPECT_EQ(group.poll(1), std::optional<int>(3));  // ended children keep their code
}

TEST(ProcessGroup, SendsOutputToFilesOrInheritsIt) {
  TempDir dir;
  ProcessSpec spec = sh("echo out; echo err >&2");
  spec.stdout_path = dir.file("o.txt");
  spec.stderr_path = dir.file("e.txt");
  ProcessGroup group;
  ASSERT_EQ(group.run(spec), 0);
  EXPECT_EQ(read_file(dir.file("o.txt")), "out\n");
  EXPECT_EQ(read_file(dir.file("e.txt")), "err\n");
}

TEST(OutputTail, TheLastLinesOfAProcesssOutputOrNothing) {
  TempDir dir;
  ProcessGroup group;
  ProcessSpec spec = process("seq", {"sh", "-c", "seq 1 30"});
  spec.stdout_path = dir.file("out.txt");
  ASSERT_EQ(group.run(spec), 0);
  EXPECT_EQ(output_tail(dir.file("out.txt"), 3), "28\n29\n30\n");
  EXPECT_EQ(output_tail(dir.file("out.txt"), 100).size(),
            std::string("1\n").size() * 9 + std::string("10\n").size() * 21);
  EXPECT_EQ(output_tail(dir.file("missing.txt"), 3), "");
}

TEST(ProcessGroup, GivesTheChildItsEnvironmentWithTheSpecsEntriesOver) {
  TempDir dir;
  ::setenv("WINGMAN_TEST_KEPT", "kept", 1);
  ::setenv("WINGMAN_TEST_REPLACED", "old", 1);
  ProcessSpec spec = sh("echo $WINGMAN_TEST_KEPT $WINGMAN_TEST_REPLACED $WINGMAN_TEST_ADDED");
  spec.env = {"WINGMAN_TEST_REPLACED=new", "WINGMAN_TEST_ADDED=a=b"};
  spec.stdout_path = dir.file("o.txt");
  ProcessGroup group;
  ASSERT_EQ(group.run(spec), 0);
  EXPECT_EQ(read_file(dir.file("o.txt")), "kept new a=b\n");
}

TEST(ProcessGroup, StderrCanFollowStdoutIntoOneFileInOrder) {
  TempDir dir;
  ProcessSpec spec = sh("echo one; echo two >&2; echo three");
  spec.stdout_path = dir.file("both.txt");
  spec.stderr_to_stdout = true;
  ProcessGroup group;
  ASSERT_EQ(group.run(spec), 0);
  EXPECT_EQ(read_file(dir.file("both.txt")), "one\ntwo\nthree\n");
}

TEST(RunInForeground, TheChildGetsCtrlCAndThisProcessOnlyItsExit) {
  struct sigaction before {};
  ::sigaction(SIGINT, nullptr, &before);
  // The child sends SIGINT to its parent (this test), then waits to be interrupted itself: the parent ignores it
  // while the child runs, so the test survives; the child ends on its own SIGINT.
  EXPECT_EQ(run_in_foreground(sh("kill -INT $PPID; kill -INT $$; sleep 5")), 128 + SIGINT);
  struct sigaction after {};
  ::sigaction(SIGINT, nullptr, &after);
  EXPECT_EQ(after.sa_handler, before.sa_handler);  // restored
  EXPECT_EQ(run_in_foreground(sh("exit 7")), 7);
  ProcessSpec missing;
  missing.argv = {"/nonexistent/program"};
  EXPECT_THROW(run_in_foreground(missing), std::runtime_error);
}

TEST(ProcessGroup, AProgramThatCannotStartIsAnErrorNamingIt) {
  ProcessGroup group;
  ProcessSpec missing;
  missing.name = "wingman-nothing";
  missing.argv = {"/nonexistent/wingman-nothing", "--x"};
  try {
    group.start(missing);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/wingman-nothing"), std::string::npos) << e.what();
  }
  EXPECT_EQ(group.size(), 0u);
  EXPECT_THROW(group.start(ProcessSpec{}), std::invalid_argument);
}

TEST(ProcessGroup, AnOutputFileThatCannotBeCreatedIsAnErrorNamingIt) {
  ProcessSpec spec = sh("true", "writer");
  spec.stdout_path = "/nonexistent-dir/out.txt";
  ProcessGroup group;
  try {
    group.start(spec);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("writer"), std::string::npos) << what;
    EXPECT_NE(what.find("/nonexistent-dir/out.txt"), std::string::npos) << what;
  }
}

TEST(ProcessGroup, StopTerminatesThenKillsWhatIgnoresTheTerminate) {
  ProcessGroup group;
  TempDir dir;
  // The first ends on SIGTERM; the second ignores it (it says so once the trap is set) and must be killed.
  const size_t polite = group.start(sh("exec sleep 30"));
  const size_t stubborn =
      group.start(sh("trap '' TERM; echo ready > " + dir.file("ready") + "; while :; do sleep 0.05; done"));
  for (int i = 0; i < 400 && read_file(dir.file("ready")).empty(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_EQ(read_file(dir.file("ready")), "ready\n");
  const auto t0 = std::chrono::steady_clock::now();
  group.stop({polite, stubborn}, 0.3);
  const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(group.poll(polite), std::optional<int>(128 + SIGTERM));
  EXPECT_EQ(group.poll(stubborn), std::optional<int>(128 + SIGKILL));
  EXPECT_GE(took_s, 0.3);  // the grace was given before the kill
}

TEST(ProcessGroup, WaitAnyReturnsTheFirstToEndOrNothingWhenAskedToStop) {
  ProcessGroup group;
  const size_t slow = group.start(sh("exec sleep 30"));
  const size_t quick = group.start(sh("sleep 0.1; exit 4"));
  const std::optional<size_t> first = group.wait_any({slow, quick}, [] { return false; });
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(*first, quick);
  EXPECT_EQ(group.poll(quick), std::optional<int>(4));
  EXPECT_FALSE(group.wait_any({slow}, [] { return true; }).has_value());
  EXPECT_FALSE(group.poll(slow).has_value());
  EXPECT_THROW(group.wait_any({}, nullptr), std::invalid_argument);
}

TEST(ProcessGroup, NoChildOutlivesTheGroup) {
  pid_t pid = -1;
  {
    ProcessGroup group;
    pid = group.pid(group.start(sh("exec sleep 30")));
    ASSERT_TRUE(alive(pid));
  }
  EXPECT_FALSE(alive(pid));  // stopped and reaped by the destructor
}

TEST(ProcessGroup, CommandLineQuotesWhatAShellWould) {
  ProcessSpec spec;
  spec.argv = {"/bin/wingman-sim", "--set", "sync={mode: lockstep}", "it's", "plain-1.0,x=y"};
  EXPECT_EQ(spec.command_line(), "/bin/wingman-sim --set 'sync={mode: lockstep}' 'it'\\''s' plain-1.0,x=y");
  EXPECT_EQ(spec.label(), "/bin/wingman-sim");
  spec.name = "sim";
  EXPECT_EQ(spec.label(), "sim");
}

TEST(StopSignals, TurnsAStopSignalIntoARequestAndRestoresTheHandlerAfter) {
  struct sigaction before {};
  ::sigaction(SIGTERM, nullptr, &before);
  {
    StopSignals signals;
    EXPECT_FALSE(signals.requested());
    ::raise(SIGTERM);  // would end the test binary without the handler
    EXPECT_TRUE(signals.requested());
    EXPECT_EQ(signals.signal(), SIGTERM);
    EXPECT_THROW(StopSignals another, std::logic_error);  // one at a time
  }
  struct sigaction after {};
  ::sigaction(SIGTERM, nullptr, &after);
  EXPECT_EQ(after.sa_handler, before.sa_handler);
  StopSignals again;  // a new one starts without a request
  EXPECT_FALSE(again.requested());
}

TEST(StopSignals, ChildrenStartWithTheDefaultHandlers) {
  StopSignals signals;  // this process catches SIGTERM; a child must still end on it
  ProcessGroup group;
  const size_t child = group.start(sh("exec sleep 30"));
  group.stop({child}, 5.0);
  EXPECT_EQ(group.poll(child), std::optional<int>(128 + SIGTERM));
  EXPECT_FALSE(signals.requested());
}

}  // namespace
}  // namespace wingman::launcher
