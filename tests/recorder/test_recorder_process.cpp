// SPDX-License-Identifier: MIT
// wingman-recorder as a process, file to file (no multicast): shipped config = defaults, a log input recorded
// completely without images, a missing directory as exit 1 or as counted drops, SIGTERM within a second.
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <wingman/status_t.hpp>

#include <algorithm>

#include <dirent.h>
#include <csignal>
#include <fstream>
#include <sstream>
#include <thread>

namespace {

using namespace std::chrono_literals;
using wingman::testing::bin_path;
using wingman::testing::Child;
using wingman::testing::LogEvent;
using wingman::testing::read_log;
using wingman::testing::run;
using wingman::testing::source_path;
using wingman::testing::stop_latency_bound;
using wingman::testing::TempDir;

std::vector<std::string> segments(const std::string& dir) {
  std::vector<std::string> files;
  if (DIR* d = opendir(dir.c_str())) {
    while (dirent* e = readdir(d)) {
      const std::string name = e->d_name;
      if (name.rfind("wingman-", 0) == 0) files.push_back(dir + "/" + name);
    }
    closedir(d);
  }
  std::sort(files.begin(), files.end());
  return files;
}

/// 30 events on three channels, one of them images (excluded by default).
std::vector<LogEvent> input_events() {
  std::vector<LogEvent> events;
  for (int i = 0; i < 30; ++i) {
    const std::string channel = i % 3 == 0 ? "IMAGE_CAM0" : (i % 3 == 1 ? "DETECTIONS_CAM0" : "STATUS_DETECTOR");
    events.push_back({1700000000000000 + i * 1000, channel, std::vector<uint8_t>(100 + i, static_cast<uint8_t>(i))});
  }
  return events;
}

std::string config(const TempDir& dir, const std::string& directory, bool require) {
  const std::string path = dir.file("recorder.yaml");
  std::ofstream(path) << "output: {directory: " << directory
                      << "}\nerrors: {require_directory_at_start: " << (require ? "true" : "false") << "}\n";
  return path;
}

std::vector<std::string> recorder_argv(const TempDir& dir, const std::string& cfg) {
  const std::string in = dir.file("in.lcmlog");
  wingman::testing::write_log(in, input_events());
  return {bin_path("wingman-recorder"),
          "--config",
          cfg,
          "--lcm-in",
          "file://" + in + "?speed=0",
          "--lcm-out",
          "file://" + dir.file("out.lcmlog") + "?mode=w"};
}

std::string without_first_line(const std::string& s) { return s.substr(s.find('\n') + 1); }

TEST(RecorderProcess, ShippedConfigFileEqualsTheBuiltInDefaults) {
  const auto defaults = run({bin_path("wingman-recorder"), "--print-config"});
  const auto shipped =
      run({bin_path("wingman-recorder"), "--print-config", "--config", source_path("config/recorder.yaml")});
  ASSERT_EQ(defaults.exit_code, 0) << defaults.err;
  ASSERT_EQ(shipped.exit_code, 0) << shipped.err;
  EXPECT_EQ(without_first_line(defaults.out), without_first_line(shipped.out));
  std::ifstream f(source_path("config/recorder.yaml"));
  std::stringstream file;
  file << f.rdbuf();
  EXPECT_EQ(without_first_line(file.str()), without_first_line(defaults.out)) << "config/recorder.yaml is stale";
}

TEST(RecorderProcess, RecordsALogInputCompletelyAsReceivedWithoutImages) {
  TempDir dir;
  ASSERT_EQ(::mkdir(dir.file("rec").c_str(), 0755), 0);
  const auto wall_us = [] {
    return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
        .count();
  };
  const int64_t t_start = wall_us();
  const auto r = run(recorder_argv(dir, config(dir, dir.file("rec"), true)), 30s);
  const int64_t t_end = wall_us();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<LogEvent> expected;
  for (const auto& e : input_events()) {
    if (e.channel != "IMAGE_CAM0") expected.push_back(e);
  }
  const auto files = segments(dir.file("rec"));
  ASSERT_EQ(files.size(), 1u);
  const auto recorded = read_log(files[0]);
  ASSERT_EQ(recorded.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(recorded[i].channel, expected[i].channel);
    EXPECT_EQ(recorded[i].data, expected[i].data) << "payloads are stored as received";
    // The event time is LCM's receive time (LCM 1.3.1's file provider delivers at the wall clock's now), as
    // lcm-logger writes it; the messages' own utime is inside the unchanged payload.
    EXPECT_GE(recorded[i].timestamp, i == 0 ? t_start : recorded[i - 1].timestamp);
    EXPECT_LE(recorded[i].timestamp, t_end);
  }
}

TEST(RecorderProcess, MissingDirectoryWithRequireExitsOneWithOneLineNamingPathAndReason) {
  TempDir dir;
  const auto r = run(recorder_argv(dir, config(dir, dir.file("absent"), true)), 30s);
  EXPECT_EQ(r.exit_code, 1);
  std::istringstream err(r.err);
  std::vector<std::string> errors;
  for (std::string l; std::getline(err, l);) {
    if (l.find(" info: ") == std::string::npos && !l.empty()) errors.push_back(l);
  }
  ASSERT_EQ(errors.size(), 1u) << r.err;
  EXPECT_EQ(errors[0].rfind("wingman-recorder: error: recording directory " + dir.file("absent"), 0), 0u) << errors[0];
  EXPECT_NE(errors[0].find("No such file or directory"), std::string::npos) << errors[0];
}

TEST(RecorderProcess, MissingDirectoryWithoutRequireRunsReportsOnceAndCountsEveryEventAsDropped) {
  TempDir dir;
  const auto r = run(recorder_argv(dir, config(dir, dir.file("absent"), false)), 30s);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  size_t error_lines = 0;
  for (size_t p = r.err.find("error: "); p != std::string::npos; p = r.err.find("error: ", p + 1)) ++error_lines;
  EXPECT_EQ(error_lines, 1u) << r.err;
  wingman::status_t last{};
  for (const auto& e : read_log(dir.file("out.lcmlog"))) {
    if (e.channel == "STATUS_RECORDER") {
      ASSERT_GE(last.decode(e.data.data(), 0, static_cast<int>(e.data.size())), 0);
    }
  }
  EXPECT_NE(last.last_error.find(dir.file("absent")), std::string::npos) << last.last_error;
  EXPECT_NE(last.last_error.find("No such file or directory"), std::string::npos) << last.last_error;
  EXPECT_EQ(last.drops_total, 20) << "every wanted event is counted as dropped";
}

TEST(RecorderProcess, SigtermEndsItWithExitZeroWithinOneSecond) {
  TempDir dir;
  ASSERT_EQ(::mkdir(dir.file("rec").c_str(), 0755), 0);
  Child c({bin_path("wingman-recorder"), "--config", config(dir, dir.file("rec"), true), "--lcm-url", "memq://"});
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (c.err().find("recording to") == std::string::npos && std::chrono::steady_clock::now() < deadline &&
         c.running()) {
    std::this_thread::sleep_for(10ms);
  }
  ASSERT_TRUE(c.running()) << c.err();
  const auto t0 = std::chrono::steady_clock::now();
  c.signal(SIGTERM);
  EXPECT_EQ(c.wait(5s), 0) << c.err();
  EXPECT_LT(std::chrono::steady_clock::now() - t0, stop_latency_bound());
}

}  // namespace
