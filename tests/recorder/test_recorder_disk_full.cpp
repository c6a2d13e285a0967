// SPDX-License-Identifier: MIT
// wingman-recorder under a real full disk: a 1 MiB tmpfs in a private mount and network namespace (see
// CMakeLists.txt). The disk fills mid-run: the recorder keeps running, reports ERROR naming the file and the reason
// once, counts its drops, and the localizer keeps publishing targets; when space frees, recording resumes in a new
// segment and every segment reads back.
#include "test_support.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>
#include <lcm/lcm-cpp.hpp>
#include <wingman/detections_t.hpp>
#include <wingman/own_pose_t.hpp>
#include <wingman/status_t.hpp>
#include <wingman/targets_t.hpp>

#include <algorithm>

#include <dirent.h>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <thread>

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using wingman::testing::bin_path;
using wingman::testing::Child;
using wingman::testing::read_log;
using wingman::testing::TempDir;

constexpr int8_t kOk = wingman::status_t::STATE_OK;  // copies: EXPECT_EQ takes references
constexpr int8_t kError = wingman::status_t::STATE_ERROR;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

int count_lines_with(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

/// Publishes a steady stream (records for the recorder, detections and poses for the localizer) and watches the
/// recorder's heartbeat and the localizer's targets.
class Bus {
 public:
  explicit Bus(const std::string& url) : lcm_(url) {
    if (!lcm_.good()) throw std::runtime_error("cannot open " + url);
    lcm_.subscribe("STATUS_RECORDER", &Bus::on_status, this);
    lcm_.subscribe("TARGETS", &Bus::on_targets, this);
  }

  /// Runs for up to `seconds`, publishing every 5 ms, until `done()` holds; returns whether it did.
  bool pump(
      double seconds, const std::function<bool()>& done = [] { return false; }) {
    const auto t0 = Clock::now();
    while (seconds_since(t0) < seconds) {
      publish_tick();
      lcm_.handleTimeout(5);
      if (done()) return true;
    }
    return false;
  }

  void publish_raw(const std::string& channel, size_t size) {
    std::vector<uint8_t> payload(size, static_cast<uint8_t>(tick_));
    lcm_.publish(channel, payload.data(), static_cast<unsigned>(payload.size()));
  }

  wingman::status_t status;  ///< newest STATUS_RECORDER
  int statuses = 0;
  int targets = 0;
  int64_t published = 0;  ///< SPAM messages published

 private:
  void publish_tick() {
    ++tick_;
    publish_raw("SPAM", 1000);  // 1 kB at up to 200 Hz: the recorder alone would fill 1 MiB in about 5 s
    ++published;
    if (tick_ % 10 != 0) return;  // 20 Hz detections and poses
    const int64_t utime = 1700000000000000 + tick_ * 5000;
    wingman::own_pose_t p{};
    p.utime = utime;
    p.frame = wingman::own_pose_t::FRAME_ENU;
    p.q_body_to_world[0] = 1.0;
    lcm_.publish("OWN_POSE", &p);
    wingman::detections_t d{};
    d.utime = utime;
    d.seq = tick_ / 10;
    d.image_width = 1280;
    d.image_height = 720;
    d.detections.push_back({640.0f, 360.0f, 40.0f, 40.0f, 0.9f, 0, 0, 0.9f});
    d.num_detections = 1;
    lcm_.publish("DETECTIONS_CAM0", &d);
  }
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const wingman::status_t* s) {
    status = *s;
    ++statuses;
  }
  void on_targets(const lcm::ReceiveBuffer*, const std::string&, const wingman::targets_t*) { ++targets; }

  lcm::LCM lcm_;
  int64_t tick_ = 0;
};

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

/// Fills the file system of `dir` with one file until write() says ENOSPC; returns its path.
std::string fill_disk(const std::string& dir) {
  const std::string path = dir + "/filler";
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw std::runtime_error("cannot create " + path);
  std::vector<char> block(4096, 'x');
  for (int i = 0; i < 100000; ++i) {
    if (::write(fd, block.data(), block.size()) < 0) {
      const int err = errno;
      ::close(fd);
      if (err != ENOSPC) throw std::runtime_error(path + ": unexpected error " + std::to_string(err));
      return path;
    }
  }
  ::close(fd);
  throw std::runtime_error(path + ": the disk never filled (is it the 1 MiB tmpfs?)");
}

TEST(RecorderDiskFull, KeepsRunningReportsErrorOnceCountsDropsAndRecoversWhileThePipelineRuns) {
  // Mounting is only ever done in the private mount namespace the test is registered with (CMakeLists.txt).
  ASSERT_STREQ(std::getenv("WINGMAN_PRIVATE_MOUNTS"), "1") << "run through ctest: it mounts a tmpfs";
  const std::string url = wingman::testing::netns_lcm_url();
  TempDir work;
  const std::string disk = work.file("disk");
  ASSERT_EQ(::mkdir(disk.c_str(), 0755), 0);
  const auto mount = wingman::testing::run({"mount", "-t", "tmpfs", "-o", "size=1M", "tmpfs", disk}, 10s);
  ASSERT_EQ(mount.exit_code, 0) << mount.err;
  struct Unmount {
    std::string dir;
    ~Unmount() { wingman::testing::run({"umount", dir}, 10s); }
  } unmount{disk};

  const std::string cfg = work.file("recorder.yaml");
  std::ofstream(cfg) << "output: {directory: " << disk << ", max_segment_mib: 0.25}\nerrors: {retry_period_s: 0.5}\n";
  Child recorder({bin_path("wingman-recorder"), "--config", cfg, "--lcm-url", url, "--status-period", "0.2"});
  Child localizer({bin_path("wingman-localizer"), "--lcm-url", url, "--status-period", "0.2"});
  Bus bus(url);

  // 1. Recording.
  ASSERT_TRUE(bus.pump(20.0, [&] { return bus.statuses > 0 && bus.status.state == kOk && bus.targets > 5; }))
      << recorder.err() << localizer.err();
  bus.pump(0.5);
  EXPECT_EQ(bus.status.state, kOk) << bus.status.detail;

  // 2. The disk fills: ERROR with the file and the reason, drops counted, the localizer unaffected.
  const std::string filler = fill_disk(disk);
  const auto t_full = Clock::now();
  const int64_t published_at_full = bus.published;
  ASSERT_TRUE(bus.pump(20.0, [&] { return bus.status.state == kError; })) << bus.status.detail << "\n"
                                                                          << recorder.err();
  const double to_error_s = seconds_since(t_full);
  EXPECT_NE(bus.status.last_error.find("No space left on device"), std::string::npos) << bus.status.last_error;
  EXPECT_NE(bus.status.last_error.find(disk + "/wingman-"), std::string::npos) << bus.status.last_error;
  EXPECT_NE(bus.status.detail.find("No space left on device"), std::string::npos) << bus.status.detail;
  const int64_t drops_at_error = bus.status.drops_total;
  const int targets_at_error = bus.targets;
  bus.pump(3.0);
  EXPECT_TRUE(recorder.running()) << recorder.err();
  EXPECT_TRUE(localizer.running()) << localizer.err();
  EXPECT_EQ(bus.status.state, kError) << bus.status.detail;
  EXPECT_GT(bus.status.drops_total, drops_at_error + 100) << "drops are counted while the disk is full";
  EXPECT_GT(bus.targets, targets_at_error + 20) << "the localizer keeps publishing while the disk is full";
  const int64_t drops_full = bus.status.drops_total;
  const double full_s = seconds_since(t_full);

  // 3. Space frees: recording resumes in a new segment.
  ASSERT_EQ(::unlink(filler.c_str()), 0);
  const auto t_free = Clock::now();
  ASSERT_TRUE(bus.pump(20.0, [&] { return bus.status.state == kOk; })) << bus.status.detail << "\n" << recorder.err();
  const double to_recover_s = seconds_since(t_free);
  bus.pump(0.5);
  for (int i = 0; i < 5; ++i) bus.publish_raw("MARK_AFTER_RECOVERY", 10);
  bus.pump(0.5);
  recorder.signal(SIGTERM);
  ASSERT_EQ(recorder.wait(5s), 0) << recorder.err();
  EXPECT_TRUE(localizer.running());

  const std::string err = recorder.err();
  EXPECT_EQ(count_lines_with(err, "No space left on device"), 1) << "one error line, not one per message:\n" << err;
  EXPECT_EQ(count_lines_with(err, "recording resumed in"), 1) << err;
  int marks = 0;
  int64_t spam = 0;
  for (const auto& f : segments(disk)) {
    for (const auto& e : read_log(f)) {  // throws if a segment does not read back
      marks += e.channel == "MARK_AFTER_RECOVERY";
      spam += e.channel == "SPAM";
    }
  }
  EXPECT_EQ(marks, 5);
  std::cout << "[figures] disk full -> ERROR heartbeat " << to_error_s << " s; " << (drops_full - drops_at_error)
            << " more drops counted over " << (full_s - to_error_s) << " s at ~"
            << (bus.published - published_at_full) / std::max(1e-3, seconds_since(t_full))
            << " msg/s published; space freed -> OK " << to_recover_s << " s (retry period 0.5 s); " << spam
            << " SPAM events recorded of " << bus.published << " published; " << segments(disk).size() << " segments\n";
}

}  // namespace
