// SPDX-License-Identifier: MIT
// wingman-camera-driver as a process: file playback into an LCM log, signals, and one-line errors.
#include "test_support.hpp"
#include "test_video.hpp"

#include <wingman/common/message_validation.hpp>
#include <wingman/image_t.hpp>
#include <wingman/status_t.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <signal.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace wingman::camera_driver {
namespace {

using ::testing::HasSubstr;
using testing::kStartUtime;
using wingman::testing::Child;
using wingman::testing::TempDir;
using SteadyClock = std::chrono::steady_clock;

constexpr auto kProcessTimeout = std::chrono::seconds(30);  // generous bound for a loaded machine

std::vector<std::string> nonempty_lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream ss(text);
  for (std::string l; std::getline(ss, l);) {
    if (!l.empty()) out.push_back(l);
  }
  return out;
}

/// Runs the driver on `yaml`, publishing into dir/out.lcmlog.
wingman::testing::RunResult run_driver(const TempDir& dir, const std::string& yaml,
                                       const std::vector<std::string>& extra = {}) {
  const std::string config = dir.file("config.yaml");
  std::ofstream(config) << yaml;
  std::vector<std::string> args = {wingman::testing::bin_path("wingman-camera-driver"), "--config", config, "--lcm-out",
                                   "file://" + dir.file("out.lcmlog") + "?mode=w"};
  args.insert(args.end(), extra.begin(), extra.end());
  return wingman::testing::run(args, kProcessTimeout);
}

struct LogContents {
  std::vector<wingman::image_t> images;
  std::vector<wingman::image_t> previews;  ///< PREVIEW_CAM0
  std::vector<wingman::status_t> statuses;
};

LogContents decode_log(const std::string& path) {
  LogContents out;
  for (const auto& ev : wingman::testing::read_log(path)) {
    const int size = static_cast<int>(ev.data.size());
    if (ev.channel == "IMAGE_CAM0") {
      wingman::image_t img;
      EXPECT_GE(img.decode(ev.data.data(), 0, size), 0);
      out.images.push_back(img);
    } else if (ev.channel == "PREVIEW_CAM0") {
      wingman::image_t img;
      EXPECT_GE(img.decode(ev.data.data(), 0, size), 0);
      out.previews.push_back(img);
    } else if (ev.channel == "STATUS_CAMERA_DRIVER") {
      wingman::status_t s;
      EXPECT_GE(s.decode(ev.data.data(), 0, size), 0);
      out.statuses.push_back(s);
    }
  }
  return out;
}

std::string file_config(const std::string& path, const std::string& file_keys, const std::string& output_keys = "") {
  return "source: {kind: file}\nfile: {path: '" + path + "', " + file_keys + "}\n" +
         (output_keys.empty() ? "" : "output: {" + output_keys + "}\n");
}

TEST(CameraDriverProcess, PlaysAVideoInFastModeIntoALogAndExitsZero) {
  TempDir dir;
  testing::write_gray_video(dir.file("clip.avi"), 6, 32, 24, 10.0);
  const auto r =
      run_driver(dir, file_config(dir.file("clip.avi"), "mode: fast, start_utime: " + std::to_string(kStartUtime)));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const LogContents log = decode_log(dir.file("out.lcmlog"));
  ASSERT_EQ(log.images.size(), 6u);
  for (size_t i = 0; i < log.images.size(); ++i) {
    const auto& img = log.images[i];
    SCOPED_TRACE("image " + std::to_string(i));
    EXPECT_EQ(img.seq, static_cast<int64_t>(i));
    EXPECT_EQ(img.utime, kStartUtime + static_cast<int64_t>(i) * 100'000);
    EXPECT_EQ(img.width, 32);
    EXPECT_EQ(img.height, 24);
    EXPECT_EQ(img.stride, 96);
    EXPECT_EQ(img.pixel_format, int8_t{wingman::image_t::BGR8});
    EXPECT_EQ(common::validate_message(img), "");
  }
  ASSERT_FALSE(log.statuses.empty());
  EXPECT_EQ(log.statuses.back().state, int8_t{wingman::status_t::STATE_STOPPING});
  EXPECT_EQ(log.statuses.back().last_processed_seq, 5);
}

TEST(CameraDriverProcess, PublishesAPreviewOnceASecondOfMessageTimeOnItsOwnChannel) {
  TempDir dir;
  testing::write_gray_video(dir.file("clip.avi"), 25, 640, 480, 10.0);  // 2.5 s at 10 frames/s
  const auto r =
      run_driver(dir, file_config(dir.file("clip.avi"), "mode: fast, start_utime: " + std::to_string(kStartUtime)));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const LogContents log = decode_log(dir.file("out.lcmlog"));
  ASSERT_EQ(log.images.size(), 25u);
  ASSERT_EQ(log.previews.size(), 3u) << "at 0, 1 and 2 s";
  for (size_t i = 0; i < log.previews.size(); ++i) {
    const auto& p = log.previews[i];
    EXPECT_EQ(p.utime, kStartUtime + static_cast<int64_t>(i) * 1'000'000);
    EXPECT_EQ(p.seq, static_cast<int64_t>(i) * 10);
    EXPECT_EQ(p.pixel_format, int8_t{wingman::image_t::MJPEG});
    EXPECT_EQ(p.width, 320);
    EXPECT_EQ(p.height, 240);
    EXPECT_EQ(common::validate_message(p), "");
  }
  EXPECT_THAT(r.err, HasSubstr("3 previews on PREVIEW_CAM0"));
  // Off: none.
  TempDir off;
  testing::write_gray_video(off.file("clip.avi"), 5, 64, 48, 10.0);
  ASSERT_EQ(run_driver(off, file_config(off.file("clip.avi"), "mode: fast") + "preview: {enabled: false}\n").exit_code,
            0);
  EXPECT_TRUE(decode_log(off.file("out.lcmlog")).previews.empty());
}

TEST(CameraDriverProcess, MaxFramesStopsALoopingSource) {
  TempDir dir;
  testing::write_gray_video(dir.file("clip.avi"), 2, 16, 16, 10.0);
  const auto r = run_driver(dir, file_config(dir.file("clip.avi"), "mode: fast, loop: true", "max_frames: 5"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(decode_log(dir.file("out.lcmlog")).images.size(), 5u);
}

TEST(CameraDriverProcess, SigtermAndSigintExitZeroWithinOneSecond) {
  for (int sig : {SIGTERM, SIGINT}) {
    SCOPED_TRACE(sig == SIGTERM ? "SIGTERM" : "SIGINT");
    TempDir dir;
    testing::write_gray_video(dir.file("clip.avi"), 3, 16, 16, 10.0);
    std::ofstream(dir.file("config.yaml")) << file_config(dir.file("clip.avi"), "mode: realtime, loop: true");
    Child child({wingman::testing::bin_path("wingman-camera-driver"), "--config", dir.file("config.yaml"), "--lcm-out",
                 "file://" + dir.file("out.lcmlog") + "?mode=w"});
    // Ready once the source has logged its description (the capture loop starts right after).
    const auto deadline = SteadyClock::now() + kProcessTimeout;
    while (child.err().find("realtime loop") == std::string::npos && SteadyClock::now() < deadline) {
      ASSERT_EQ(child.wait(std::chrono::milliseconds(10)), -1) << "exited early: " << child.err();
    }
    ASSERT_THAT(child.err(), HasSubstr("realtime loop"));
    const auto t0 = SteadyClock::now();
    child.signal(sig);
    const int rc = child.wait(std::chrono::seconds(5));
    const double exit_s = std::chrono::duration<double>(SteadyClock::now() - t0).count();
    EXPECT_EQ(rc, 0) << child.err();
    EXPECT_LT(exit_s, 1.0);
  }
}

TEST(CameraDriverProcess, BadConfigExitsTwoWithOneLineNamingTheKey) {
  TempDir dir;
  const auto r = run_driver(dir, "v4l2: {width: -3}\n");
  EXPECT_EQ(r.exit_code, 2);
  const auto lines = nonempty_lines(r.err);
  ASSERT_EQ(lines.size(), 1u) << r.err;
  EXPECT_THAT(lines[0], HasSubstr("v4l2.width = -3"));
}

TEST(CameraDriverProcess, MissingOrUnreadableInputsExitOneWithOneLineNamingThem) {
  TempDir dir;
  struct Case {
    std::string what, yaml, expected;
  };
  const std::string missing = dir.file("nope.avi"), bad = dir.file("bad.avi");
  testing::write_text(bad, "not a video");
  const std::vector<Case> cases = {
      {"missing video", file_config(missing, "mode: fast"), "file " + missing + ": does not exist"},
      {"unreadable video (OpenCV's backend noise must not reach stderr)", file_config(bad, "mode: fast"),
       "file " + bad + ": cannot open as a video"},
      {"missing camera, not waited for", "v4l2: {device: /dev/video-wingman-test-missing, wait_for_device: false}\n",
       "device /dev/video-wingman-test-missing: cannot open: ENOENT"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const auto r = run_driver(dir, c.yaml, {"--log-level", "warn"});
    EXPECT_EQ(r.exit_code, 1);
    const auto lines = nonempty_lines(r.err);
    ASSERT_EQ(lines.size(), 1u) << r.err;
    EXPECT_THAT(lines[0], HasSubstr(c.expected));
  }
}

TEST(CameraDriverProcess, AMissingCameraIsWaitedForWithAnErrorHeartbeatAndSigtermExitsZero) {
  TempDir dir;
  std::ofstream(dir.file("config.yaml")) << "v4l2: {device: /dev/video-wingman-test-missing, reconnect_initial_s: 0.1, "
                                            "reconnect_max_s: 0.2}\n";
  Child child({wingman::testing::bin_path("wingman-camera-driver"), "--config", dir.file("config.yaml"), "--lcm-out",
               "file://" + dir.file("out.lcmlog") + "?mode=w"});
  // Up and waiting once it has retried twice (0.1 s, then 0.2 s after the failed open).
  const auto deadline = SteadyClock::now() + kProcessTimeout;
  auto retries = [&child] {
    size_t n = 0;
    for (size_t at = 0; (at = child.err().find("next attempt in", at)) != std::string::npos; ++at) ++n;
    return n;
  };
  while (retries() < 3 && SteadyClock::now() < deadline) {
    ASSERT_EQ(child.wait(std::chrono::milliseconds(10)), -1) << "exited instead of waiting: " << child.err();
  }
  ASSERT_GE(retries(), 3u) << child.err();
  child.signal(SIGTERM);
  EXPECT_EQ(child.wait(std::chrono::seconds(5)), 0) << child.err();
  EXPECT_THAT(child.err(), HasSubstr("waiting for the device (v4l2.wait_for_device)"));

  const LogContents log = decode_log(dir.file("out.lcmlog"));
  EXPECT_TRUE(log.images.empty());
  ASSERT_GE(log.statuses.size(), 2u) << "a heartbeat at start and one at the stop";
  EXPECT_EQ(log.statuses.front().state, int8_t{wingman::status_t::STATE_ERROR}) << "never OK without the camera";
  EXPECT_THAT(log.statuses.front().detail, HasSubstr("device /dev/video-wingman-test-missing: cannot open: ENOENT"));
  EXPECT_EQ(log.statuses.back().state, int8_t{wingman::status_t::STATE_STOPPING});
}

}  // namespace
}  // namespace wingman::camera_driver
