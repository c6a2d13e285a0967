// SPDX-License-Identifier: MIT
// The common runtime as the real process binaries use it: configs, exit codes, signals, file I/O, bad messages.
// No network: these tests use file:// and memq:// LCM URLs only.
#include "test_support.hpp"
#include "test_video.hpp"

#include <gtest/gtest.h>
#include <wingman/common/runtime.hpp>
#include <wingman/detections_t.hpp>
#include <wingman/image_t.hpp>
#include <wingman/status_t.hpp>
#include <wingman/track_windows_t.hpp>

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iostream>
#include <regex>
#include <thread>

namespace {

using namespace std::chrono_literals;
using wingman::testing::bin_path;
using wingman::testing::Child;
using wingman::testing::run;
using wingman::testing::source_path;
using wingman::testing::stop_latency_bound;
using wingman::testing::TempDir;

struct ProcessCase {
  std::string executable;
  std::string config;   // config/<name>.yaml
  std::string bad_key;  // a key that exists, to give a bad value
};

const std::vector<ProcessCase> kProcesses = {
    {"wingman-camera-driver", "camera_driver", "output.camera_id"},
    {"wingman-detector", "detector", "input.max_image_width"},
    {"wingman-localizer", "localizer", "output.channel"},
    {"wingman-follower-ctrl", "follower_ctrl", "output.channel"},
};

std::string first_line(const std::string& s) { return s.substr(0, s.find('\n')); }

/// The most a file-to-file detector run may take: model load, the auto backend's timing, a second network for the
/// test's 8x4 frames; about 3 s here, 19 s under ThreadSanitizer beside a build (a bound, not a timing assertion).
constexpr auto kDetectorRunLimit = std::chrono::seconds(60);

wingman::image_t gray_image(int64_t seq) {
  wingman::image_t m{};
  m.utime = 1700000000000000 + seq * 33333;
  m.seq = seq;
  m.width = 8;
  m.height = 4;
  m.stride = 8;
  m.pixel_format = wingman::image_t::GRAY8;
  m.data.assign(32, static_cast<uint8_t>(seq));
  m.size = 32;
  return m;
}

TEST(ProcessConfig, ShippedConfigFileEqualsTheBuiltInDefaults) {
  for (const auto& p : kProcesses) {
    SCOPED_TRACE(p.executable);
    const auto defaults = run({bin_path(p.executable), "--print-config"});
    ASSERT_EQ(defaults.exit_code, 0) << defaults.err;
    const auto from_file =
        run({bin_path(p.executable), "--print-config", "--config", source_path("config/" + p.config + ".yaml")});
    ASSERT_EQ(from_file.exit_code, 0) << from_file.err;
    // Same keys and values; only the header line (which names the source) differs.
    EXPECT_EQ(defaults.out.substr(defaults.out.find('\n')), from_file.out.substr(from_file.out.find('\n')));
  }
}

TEST(ProcessConfig, EveryKeyInTheShippedConfigHasACommentAbove) {
  for (const auto& p : kProcesses) {
    SCOPED_TRACE(p.config);
    std::ifstream in(source_path("config/" + p.config + ".yaml"));
    ASSERT_TRUE(in.good());
    std::string prev, line;
    int keys = 0;
    while (std::getline(in, line)) {
      const auto colon = line.find(':');
      const bool is_key = colon != std::string::npos && line.find('#') == std::string::npos && colon + 1 < line.size();
      if (is_key) {
        ++keys;
        EXPECT_NE(prev.find('#'), std::string::npos) << "key without a comment: " << line;
      }
      prev = line;
    }
    EXPECT_GT(keys, 0);
  }
}

TEST(ProcessConfig, BadConfigExitsNonZeroWithOneLineNamingFileAndEveryBadKey) {
  TempDir dir;
  for (const auto& p : kProcesses) {
    SCOPED_TRACE(p.executable);
    const std::string path = dir.file(p.config + ".yaml");
    const auto dot = p.bad_key.find('.');
    std::ofstream(path) << p.bad_key.substr(0, dot) << ":\n  " << p.bad_key.substr(dot + 1) << ": [not, a, scalar]\n"
                        << "nonsense_section:\n  nonsense_key: 1\n";
    const auto r = run({bin_path(p.executable), "--config", path}, 10s);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line expected: " << r.err;
    EXPECT_NE(r.err.find(p.executable + ": error: 2 problems"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(path + ":2: " + p.bad_key), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("nonsense_section.nonsense_key: unknown key"), std::string::npos) << r.err;
  }
}

// Issue 33, finding 6: every process ran on its defaults with exit 0 when --config named a directory.
TEST(ProcessConfig, ADirectoryAsConfigIsAnErrorForEveryProcess) {
  TempDir dir;
  for (const char* exe :
       {"wingman-camera-driver", "wingman-detector", "wingman-localizer", "wingman-follower-ctrl", "wingman-recorder",
#ifdef WINGMAN_WITH_SIM
        "wingman-sim"
#endif
       }) {
    const auto r = run({bin_path(exe), "--config", dir.path(), "--print-config"}, 10s);
    EXPECT_EQ(r.exit_code, 2) << exe;
    EXPECT_EQ(first_line(r.err), std::string(exe) + ": error: " + dir.path() + ": is a directory, not a config file");
  }
}

// Issue 34: every executable answers --version with the project's version and the commit it was built from, the
// same for all (one build), on stdout, exit 0.
TEST(ProcessCli, EveryExecutableAnswersVersionWithTheSameBuildsVersion) {
  const std::regex line(R"(^(\S+) ([0-9]+\.[0-9]+\.[0-9]+ \(git [^)\s]+\))$)");
  std::string first;
  for (const char* exe : {"wingman-camera-driver", "wingman-detector", "wingman-localizer", "wingman-follower-ctrl",
                          "wingman-recorder", "wingman-mavlink", "wingman",
#ifdef WINGMAN_WITH_SIM
                          "wingman-sim"
#endif
       }) {
    const auto r = run({bin_path(exe), "--version"}, 10s);
    EXPECT_EQ(r.exit_code, 0) << exe << ": " << r.err;
    std::smatch m;
    const std::string out = first_line(r.out);
    ASSERT_TRUE(std::regex_match(out, m, line)) << exe << ": '" << out << "'";
    EXPECT_EQ(m[1].str(), exe);
    if (first.empty()) first = m[2].str();
    EXPECT_EQ(m[2].str(), first) << exe;
  }
}

TEST(ProcessConfig, MissingConfigFileAndBadOptionAreOneLineErrors) {
  const auto r = run({bin_path("wingman-detector"), "--config", "/nonexistent.yaml"}, 10s);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(first_line(r.err), "wingman-detector: error: /nonexistent.yaml: cannot open config file");
  const auto r2 = run({bin_path("wingman-localizer"), "--lcm-out", "file:///tmp/x.lcmlog"}, 10s);
  EXPECT_EQ(r2.exit_code, 2);
  EXPECT_NE(r2.err.find("--lcm-out"), std::string::npos) << r2.err;
  const auto r3 = run({bin_path("wingman-detector"), "--lcm-url", "file:///tmp/x.lcmlog?mode=w"}, 10s);
  EXPECT_EQ(r3.exit_code, 2);
  EXPECT_NE(r3.err.find("use --lcm-out"), std::string::npos) << r3.err;
}

TEST(ProcessSignals, SigtermAndSigintEndEveryProcessWithExitZeroWithinOneSecond) {
  TempDir dir;
  const std::string video = dir.file("v.avi");
  wingman::testing::write_test_video(video, 10, 64, 48, 30.0);
  const std::string cam_cfg = dir.file("cam.yaml");
  std::ofstream(cam_cfg) << "source:\n  kind: file\nfile:\n  path: " << video << "\n  mode: realtime\n  loop: true\n";
  for (int sig : {SIGTERM, SIGINT}) {
    for (const auto& p : kProcesses) {
      SCOPED_TRACE(p.executable + " signal " + std::to_string(sig));
      std::vector<std::string> argv = {bin_path(p.executable), "--lcm-url", "memq://"};
      if (p.config == "camera_driver") argv.insert(argv.end(), {"--config", cam_cfg});
      Child c(argv);
      // Running: it has logged that it started (bounded wait), and has not exited.
      const auto deadline = std::chrono::steady_clock::now() + 10s;
      while (c.err().find("started") == std::string::npos && std::chrono::steady_clock::now() < deadline &&
             c.running()) {
        std::this_thread::sleep_for(10ms);
      }
      ASSERT_TRUE(c.running()) << c.err();
      const auto t0 = std::chrono::steady_clock::now();
      c.signal(sig);
      const int rc = c.wait(5s);
      const auto elapsed = std::chrono::steady_clock::now() - t0;
      EXPECT_EQ(rc, 0) << c.err();
      EXPECT_LT(elapsed, stop_latency_bound()) << "took " << std::chrono::duration<double>(elapsed).count() << " s";
    }
  }
}

// Issue 33, Deliver 2: a handler that never returns (a livelock) left a process alive and useless, and nothing
// restarted it. With --watchdog S the runtime exits 1 with one line once the loop has made no progress for S.
TEST(ProcessWatchdog, AStuckHandlerEndsTheProcessWithExitOneWithinTheBound) {
  TempDir dir;
  std::vector<wingman::testing::LogEvent> events;
  for (int i = 0; i < 4; ++i) events.push_back(wingman::testing::make_event("IMAGE_CAM0", gray_image(i), 1000 + i));
  wingman::testing::write_log(dir.file("in.lcmlog"), events);
  const std::string cfg = dir.file("stage.yaml");
  std::ofstream(cfg) << "test: {hang_on_seq: 2}\n";
  const std::vector<std::string> cmd = {wingman::testing::test_bin_path("wingman-test-blob-stage"),
                                        "--config",
                                        cfg,
                                        "--lcm-in",
                                        "file://" + dir.file("in.lcmlog") + "?speed=0",
                                        "--lcm-out",
                                        "file://" + dir.file("out.lcmlog") + "?mode=w"};
  std::vector<std::string> watched = cmd;
  watched.insert(watched.end(), {"--watchdog", "1"});
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = run(watched, 10s);
  const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("wingman-test-blob-stage: error: watchdog: the main loop made no progress for 1."),
            std::string::npos)
      << r.err;
  EXPECT_LT(took_s, 5.0);
  std::cout << "watchdog: stuck handler ended after " << took_s << " s (bound 1 s)\n";
  // Without it the process stays stuck (killed here by the test's bound).
  const auto stuck = run(cmd, 3s);
  EXPECT_EQ(stuck.exit_code, -1) << "timed out";
  const auto bad = run({wingman::testing::test_bin_path("wingman-test-blob-stage"), "--watchdog", "0.01"}, 10s);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--watchdog = 0.01: must be 0 (off) or in [0.1, 3600] seconds"), std::string::npos) << bad.err;
}

/// The datagrams a unix socket receives within `for_time` (each as text), read until `enough` says so.
std::vector<std::string> notifications(int fd, std::chrono::milliseconds for_time,
                                       const std::function<bool(const std::vector<std::string>&)>& enough) {
  std::vector<std::string> got;
  const auto end = std::chrono::steady_clock::now() + for_time;
  while (std::chrono::steady_clock::now() < end && !enough(got)) {
    pollfd p{fd, POLLIN, 0};
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now());
    if (poll(&p, 1, static_cast<int>(std::max<int64_t>(0, left.count()))) <= 0) continue;
    char buf[512];
    const ssize_t n = recv(fd, buf, sizeof buf, 0);
    if (n > 0) got.emplace_back(buf, static_cast<size_t>(n));
  }
  return got;
}

// The systemd side of the watchdog (units with Type=notify and WatchdogSec=): the runtime speaks sd_notify's
// datagram protocol itself. A unix datagram socket stands in for systemd's $NOTIFY_SOCKET (no systemd runs here):
// READY=1 once start-up is over, then WATCHDOG=1 while the loop progresses, none while the process is stopped
// (SIGSTOP: what systemd's watchdog then kills and restarts), again after SIGCONT.
TEST(ProcessWatchdog, SdNotifyReadyThenPingsThatStopWhileTheProcessIsStopped) {
  TempDir dir;
  const std::string path = dir.file("notify.sock");
  const int fd = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  ASSERT_LT(path.size(), sizeof addr.sun_path);
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  ASSERT_EQ(bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr), 0) << std::strerror(errno);
  setenv("NOTIFY_SOCKET", path.c_str(), 1);
  setenv("WATCHDOG_USEC", "400000", 1);  // 0.4 s: pings every 0.2 s
  // memq://: an in-process LCM bus, no network; the stage idles in its loop.
  Child c({wingman::testing::test_bin_path("wingman-test-blob-stage"), "--lcm-url", "memq://"});
  unsetenv("NOTIFY_SOCKET");
  unsetenv("WATCHDOG_USEC");
  const auto count = [](const std::vector<std::string>& v, const std::string& what) {
    return std::count(v.begin(), v.end(), what);
  };
  const auto started = notifications(fd, 10s, [&](const auto& v) { return count(v, "WATCHDOG=1") >= 3; });
  ASSERT_FALSE(started.empty()) << c.err();
  EXPECT_EQ(started.front(), "READY=1");
  EXPECT_GE(count(started, "WATCHDOG=1"), 3);
  c.signal(SIGSTOP);
  (void)notifications(fd, 300ms, [](const auto&) { return false; });  // one already on its way
  const auto stopped = notifications(fd, 1500ms, [](const auto&) { return false; });
  EXPECT_EQ(count(stopped, "WATCHDOG=1"), 0) << "pings while stopped";
  c.signal(SIGCONT);
  const auto resumed = notifications(fd, 5s, [&](const auto& v) { return count(v, "WATCHDOG=1") >= 2; });
  EXPECT_GE(count(resumed, "WATCHDOG=1"), 2);
  c.signal(SIGTERM);
  EXPECT_EQ(c.wait(5s), 0) << c.err();
  close(fd);
}

/// The detector (shipped model) run file to file over `events` (written to DIR/in.lcmlog): what it wrote, and its
/// last heartbeat. Fails the calling test (ASSERT) when it does not exit 0 or writes nothing.
void run_detector_file_to_file(const TempDir& dir, const std::vector<wingman::testing::LogEvent>& events,
                               std::vector<wingman::testing::LogEvent>* out, wingman::status_t* last) {
  wingman::testing::write_log(dir.file("in.lcmlog"), events);
  const auto r = run({bin_path("wingman-detector"), "--lcm-in", "file://" + dir.file("in.lcmlog") + "?speed=0",
                      "--lcm-out", "file://" + dir.file("out.lcmlog") + "?mode=w"},
                     kDetectorRunLimit);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  *out = wingman::testing::read_log(dir.file("out.lcmlog"));
  ASSERT_FALSE(out->empty());
  ASSERT_GE(last->decode(out->back().data.data(), 0, static_cast<int>(out->back().data.size())), 0);
}

TEST(ProcessFileIo, DetectorCountsFramesMissingFromTheSequenceAsDropsButNotThoseThatArrivedBroken) {
  // seq 0 1 2 (3 and 4 never arrive) 5, garbage in place of 6, 7: two frames lost upstream, one dropped here.
  TempDir dir;
  std::vector<wingman::testing::LogEvent> events;
  for (int i : {0, 1, 2, 5}) events.push_back(wingman::testing::make_event("IMAGE_CAM0", gray_image(i), 1000 + i));
  events.push_back({1006, "IMAGE_CAM0", {1, 2, 3}});
  events.push_back(wingman::testing::make_event("IMAGE_CAM0", gray_image(7), 1007));
  std::vector<wingman::testing::LogEvent> out;
  wingman::status_t last;
  ASSERT_NO_FATAL_FAILURE(run_detector_file_to_file(dir, events, &out, &last));
  EXPECT_EQ(last.messages_handled, 6);
  EXPECT_EQ(last.drops_total, 3);  // 3 and 4 (missing), the garbage (arrived, does not decode)
  int detections = 0;
  for (const auto& e : out) detections += e.channel == "DETECTIONS_CAM0";
  EXPECT_EQ(detections, 5);
}

TEST(ProcessFileIo, DetectorDropsAnImageDatedAheadOrOutOfOrderBeforeDetectingIt) {
  // Issue 33: the detector passed a future frame's time on to its detections (the localizer dropped them). Frames
  // 0..5 in order, one copy of frame 6 dated 1 h ahead, one of frame 7 dated before frame 5, then 8 and 9: the two
  // lies are dropped and counted naming image_t.utime, no detections_t is dated after frame 9, and the clock is not
  // moved by the lie (frames 8 and 9 are detected).
  TempDir dir;
  std::vector<wingman::testing::LogEvent> events;
  for (int i = 0; i < 6; ++i) events.push_back(wingman::testing::make_event("IMAGE_CAM0", gray_image(i), 1000 + i));
  auto ahead = gray_image(6);
  ahead.utime += 3600LL * 1000000;
  events.push_back(wingman::testing::make_event("IMAGE_CAM0", ahead, 1006));
  auto behind = gray_image(7);
  behind.utime = gray_image(4).utime;
  events.push_back(wingman::testing::make_event("IMAGE_CAM0", behind, 1007));
  for (int i : {8, 9}) events.push_back(wingman::testing::make_event("IMAGE_CAM0", gray_image(i), 1000 + i));
  std::vector<wingman::testing::LogEvent> out;
  wingman::status_t last;
  ASSERT_NO_FATAL_FAILURE(run_detector_file_to_file(dir, events, &out, &last));
  EXPECT_EQ(last.messages_handled, 10);
  EXPECT_EQ(last.drops_total, 2);  // the two lies
  // The heartbeat's last error names the newer lie: before its input's previous image.
  EXPECT_NE(last.last_error.find("image_t.utime = " + std::to_string(behind.utime)), std::string::npos)
      << last.last_error;
  std::vector<int64_t> seqs;
  for (const auto& e : out) {
    if (e.channel != "DETECTIONS_CAM0") continue;
    wingman::detections_t d;
    ASSERT_GE(d.decode(e.data.data(), 0, static_cast<int>(e.data.size())), 0);
    EXPECT_LE(d.utime, gray_image(9).utime);
    seqs.push_back(d.seq);
  }
  EXPECT_EQ(seqs, (std::vector<int64_t>{0, 1, 2, 3, 4, 5, 8, 9}));
}

/// A track_windows_t of camera `camera` for 8x4 images, predicted for frame `seq`: one tiny window (far: below
/// windows.max_net_px in the single pass's network pixels) at the image centre.
wingman::track_windows_t far_window(int64_t seq, int32_t camera) {
  wingman::track_windows_t m{};
  m.utime = gray_image(seq - 1).utime;
  m.utime_predicted = gray_image(seq).utime;
  m.camera_id = camera;
  m.image_width = 8;
  m.image_height = 4;
  wingman::track_window_t w{};
  w.track_id = 1;
  w.confirmed = true;
  w.cx = 4;
  w.cy = 2;
  w.w = 0.1f;
  w.h = 0.1f;
  w.sigma_px = 1;
  w.range_m = 30;
  w.confidence = 0.5f;
  m.windows = {w};
  m.num_windows = 1;
  return m;
}

TEST(ProcessFileIo, DetectorSearchesTheWindowsOfItsCameraAndCountsAnotherCamerasAsADrop) {
  // Issue 31: with windows.enabled the detector reads the localizer's track_windows_t: frames 1 and 2 are searched in
  // the window predicted for frame 1 (frame 2 is 33 ms later, inside windows.max_age_s), frame 0 has none yet; a
  // windows message of camera 3 is dropped and counted naming the field, and the process goes on.
  TempDir dir;
  std::vector<wingman::testing::LogEvent> events;
  events.push_back(wingman::testing::make_event("IMAGE_CAM0", gray_image(0), 1000));
  events.push_back(wingman::testing::make_event("WINDOWS_CAM0", far_window(1, 0), 1001));
  events.push_back(wingman::testing::make_event("IMAGE_CAM0", gray_image(1), 1002));
  events.push_back(wingman::testing::make_event("WINDOWS_CAM0", far_window(2, 3), 1003));
  events.push_back(wingman::testing::make_event("IMAGE_CAM0", gray_image(2), 1004));
  wingman::testing::write_log(dir.file("in.lcmlog"), events);
  const auto r =
      run({bin_path("wingman-detector"), "--lcm-in", "file://" + dir.file("in.lcmlog") + "?speed=0", "--lcm-out",
           "file://" + dir.file("out.lcmlog") + "?mode=w", "--set", "windows.enabled=true", "--log-level", "info"},
          kDetectorRunLimit);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("windows: 2 searched in 2 crops"), std::string::npos) << r.err;
  const auto out = wingman::testing::read_log(dir.file("out.lcmlog"));
  ASSERT_FALSE(out.empty());
  wingman::status_t last;
  ASSERT_EQ(out.back().channel, "STATUS_DETECTOR");
  ASSERT_GE(last.decode(out.back().data.data(), 0, static_cast<int>(out.back().data.size())), 0);
  EXPECT_EQ(last.messages_handled, 5);
  EXPECT_EQ(last.drops_total, 1);
  EXPECT_NE(last.last_error.find("track_windows_t.camera_id = 3: the frames are camera 0"), std::string::npos)
      << last.last_error;
  int detections = 0;
  for (const auto& e : out) detections += e.channel == "DETECTIONS_CAM0";
  EXPECT_EQ(detections, 3);
}

TEST(ProcessFileIo, FileInputIsProcessedToItsEndWithExitZeroAndBadMessagesAreCountedNotFatal) {
  TempDir dir;
  std::vector<wingman::testing::LogEvent> events;
  for (int i = 0; i < 5; ++i) events.push_back(wingman::testing::make_event("IMAGE_CAM0", gray_image(i), 1000 + i));
  events.push_back({1100, "IMAGE_CAM0", {1, 2, 3}});  // garbage: does not decode
  auto bad = gray_image(6);
  bad.stride = 3;  // shorter than a row
  events.push_back(wingman::testing::make_event("IMAGE_CAM0", bad, 1101));
  events.push_back(wingman::testing::make_event("IMAGE_CAM0", gray_image(7), 1102));
  wingman::testing::write_log(dir.file("in.lcmlog"), events);

  const auto r = run({bin_path("wingman-detector"), "--lcm-in", "file://" + dir.file("in.lcmlog") + "?speed=0",
                      "--lcm-out", "file://" + dir.file("out.lcmlog") + "?mode=w"},
                     kDetectorRunLimit);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto out = wingman::testing::read_log(dir.file("out.lcmlog"));
  ASSERT_FALSE(out.empty());
  wingman::status_t last;
  ASSERT_EQ(out.back().channel, "STATUS_DETECTOR");
  ASSERT_GE(last.decode(out.back().data.data(), 0, static_cast<int>(out.back().data.size())), 0);
  EXPECT_EQ(last.state, int{wingman::status_t::STATE_STOPPING});
  EXPECT_EQ(last.detail, "end of input log");
  EXPECT_EQ(last.messages_handled, 8);
  EXPECT_EQ(last.drops_total, 2);
  EXPECT_EQ(last.last_processed_seq, 7);
  EXPECT_NE(last.last_error.find("image_t.stride = 3"), std::string::npos) << last.last_error;
  bool listed = false;
  for (const auto& c : last.channels) {
    if (c.channel == "IMAGE_CAM0") {
      listed = true;
      EXPECT_EQ(c.count, 8);
      EXPECT_EQ(c.drops, 2);
      EXPECT_EQ(c.last_utime, gray_image(7).utime);
    }
  }
  EXPECT_TRUE(listed);
}

TEST(ProcessFileIo, UnreadableInputLogIsAOneLineError) {
  const auto r =
      run({bin_path("wingman-localizer"), "--lcm-in", "file:///nonexistent/in.lcmlog?speed=0", "--lcm-out", "memq://"},
          10s);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("wingman-localizer: error: cannot open LCM input log 'file:///nonexistent/in.lcmlog?speed=0'"),
            std::string::npos)
      << r.err;
}

}  // namespace
