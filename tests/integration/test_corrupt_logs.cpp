// SPDX-License-Identifier: MIT
// Corrupt LCM logs on file:// inputs (issue 33, finding 4): a process and a tool verb stop with exit 1 and one line
// naming the corrupt event's byte offset, or (--skip-corrupt-log) skip it, count it and read on. LCM 1.3.1's own
// reader crashed (SIGSEGV) on an event claiming 2^31 - 1 data bytes, and ended silently at a corrupt length.
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <wingman/own_pose_t.hpp>
#include <wingman/setpoint_t.hpp>
#include <wingman/status_t.hpp>

#include <sys/stat.h>

#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace {

using namespace std::chrono_literals;
using wingman::testing::bin_path;
using wingman::testing::LogEvent;
using wingman::testing::run;
using wingman::testing::TempDir;

constexpr int64_t kT0 = 1700000000000000;

std::vector<uint8_t> slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// own poses k = from..to-1 at 50 Hz as an LCM log, as bytes.
std::vector<uint8_t> poses_log(const TempDir& dir, int from, int to) {
  std::vector<LogEvent> events;
  for (int k = from; k < to; ++k) {
    wingman::own_pose_t p{};
    p.utime = kT0 + k * 20000;
    p.frame = wingman::own_pose_t::FRAME_ENU;
    p.q_body_to_world[0] = 1.0;
    events.push_back(wingman::testing::make_event("OWN_POSE", p, p.utime));
  }
  const std::string path = dir.file("part.lcmlog");
  wingman::testing::write_log(path, events);
  return slurp(path);
}

/// 50 own poses, one event whose header claims 2^31 - 1 data bytes, 50 more own poses. Returns the path; `bad_at`:
/// the corrupt event's byte offset.
std::string corrupt_log(const TempDir& dir, size_t* bad_at) {
  std::vector<uint8_t> bytes = poses_log(dir, 0, 50);
  *bad_at = bytes.size();
  const uint8_t header[] = {0xED, 0xA1, 0xDA, 0x01, 0, 0, 0, 0, 0, 0, 0,    50,   0,    0,
                            0,    0,    0,    0,    0, 0, 0, 0, 0, 8, 0x7F, 0xFF, 0xFF, 0xFF};
  bytes.insert(bytes.end(), std::begin(header), std::end(header));
  const std::string channel = "OWN_POSE";
  bytes.insert(bytes.end(), channel.begin(), channel.end());
  bytes.insert(bytes.end(), 16, 0);  // a little of the 2^31 - 1 bytes it claims
  const std::vector<uint8_t> rest = poses_log(dir, 50, 100);
  bytes.insert(bytes.end(), rest.begin(), rest.end());
  const std::string path = dir.file("corrupt.lcmlog");
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return path;
}

TEST(CorruptLog, AProcessStopsWithExitOneNamingTheOffsetOrSkipsAndCountsOnRequest) {
  TempDir dir;
  size_t bad_at = 0;
  const std::string in = corrupt_log(dir, &bad_at);
  const std::string expected =
      in + ": corrupt event at byte " + std::to_string(bad_at) + ": data length 2147483647: must be 0..1073741824";
  const auto strict = run({bin_path("wingman-follower-ctrl"), "--lcm-in", "file://" + in + "?speed=0", "--lcm-out",
                           "file://" + dir.file("strict.lcmlog") + "?mode=w"},
                          30s);
  EXPECT_EQ(strict.exit_code, 1) << strict.err;
  EXPECT_NE(strict.err.find("wingman-follower-ctrl: error: " + expected), std::string::npos) << strict.err;

  const std::string out = dir.file("skip.lcmlog");
  const auto skip = run({bin_path("wingman-follower-ctrl"), "--skip-corrupt-log", "--lcm-in",
                         "file://" + in + "?speed=0", "--lcm-out", "file://" + out + "?mode=w"},
                        30s);
  ASSERT_EQ(skip.exit_code, 0) << skip.err;
  int holds = 0;
  wingman::status_t status;
  for (const auto& e : wingman::testing::read_log(out)) {
    if (e.channel == "SETPOINT") ++holds;
    if (e.channel == "STATUS_FOLLOWER_CTRL") status.decode(e.data.data(), 0, static_cast<int>(e.data.size()));
  }
  // Every own pose more than hold.timeout_s (0.5 s) after the first gives a hold: the 50 after the corrupt
  // event were read too.
  EXPECT_EQ(holds, 100 - 26);
  EXPECT_EQ(status.drops_total, 1) << status.last_error;
  EXPECT_NE(status.last_error.find(expected + " (skipped: --skip-corrupt-log; 1 corrupt stretch(es), 52 bytes"),
            std::string::npos)
      << status.last_error;
}

TEST(CorruptLog, TheRecorderReadingALogStopsNamingTheOffsetOrSkipsOnRequest) {
  TempDir dir;
  size_t bad_at = 0;
  const std::string in = corrupt_log(dir, &bad_at);
  const std::string rec_dir = dir.file("rec");
  ASSERT_EQ(::mkdir(rec_dir.c_str(), 0755), 0);
  const std::string cfg = dir.file("recorder.yaml");
  std::ofstream(cfg) << "output: {directory: " << rec_dir << "}\n";
  const std::vector<std::string> cmd = {bin_path("wingman-recorder"), "--config",  cfg,      "--lcm-in",
                                        "file://" + in + "?speed=0",  "--lcm-out", "memq://"};
  const auto strict = run(cmd, 30s);
  EXPECT_EQ(strict.exit_code, 1) << strict.err;
  EXPECT_NE(strict.err.find("wingman-recorder: error: " + in + ": corrupt event at byte " + std::to_string(bad_at)),
            std::string::npos)
      << strict.err;
  std::vector<std::string> skipping = cmd;
  skipping.push_back("--skip-corrupt-log");
  const auto skip = run(skipping, 30s);
  EXPECT_EQ(skip.exit_code, 0) << skip.err;
  EXPECT_NE(skip.err.find("recorded 100 events"), std::string::npos) << skip.err;
}

TEST(CorruptLog, ToolVerbsStopWithANonZeroExitNamingTheOffset) {
  TempDir dir;
  size_t bad_at = 0;
  const std::string in = corrupt_log(dir, &bad_at);
  const auto info = run({bin_path("wingman"), "loginfo", in}, 30s);
  EXPECT_NE(info.exit_code, 0);
  EXPECT_NE(info.err.find(in + ": corrupt event at byte " + std::to_string(bad_at)), std::string::npos) << info.err;
  const auto skipped = run({bin_path("wingman"), "loginfo", "--skip-corrupt", in}, 30s);
  EXPECT_EQ(skipped.exit_code, 0) << skipped.err;
  EXPECT_NE(skipped.out.find("corrupt: 1 stretch(es), 52 bytes skipped; the first: " + in + ": corrupt event at byte " +
                             std::to_string(bad_at)),
            std::string::npos)
      << skipped.out;
  EXPECT_NE(skipped.out.find("OWN_POSE             own_pose_t                 100"), std::string::npos) << skipped.out;
}

}  // namespace
