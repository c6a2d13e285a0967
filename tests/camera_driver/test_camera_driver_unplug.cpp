// SPDX-License-Identifier: MIT
// The camera driver's process loop (run_driver_loop) with the fake V4L2 device unplugged mid-stream: the heartbeat
// turns ERROR at once with the device's reason, nothing is published while it is gone, and after the replug frames
// resume with increasing seq and utime, the heartbeat OK again counting the reconnect. Output: a real LCM log file.
#include "fake_clock.hpp"
#include "fake_v4l2_device.hpp"
#include "test_support.hpp"
#include "wingman/camera_driver/camera_driver.hpp"
#include "wingman/camera_driver/driver_loop.hpp"

#include <wingman/image_t.hpp>
#include <wingman/status_t.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>

namespace wingman::camera_driver {
namespace {

using testing::FakeClock;
using testing::FakeEvent;
using testing::FakeV4l2Device;
using ::testing::HasSubstr;
using wingman::testing::read_log;
using wingman::testing::TempDir;

struct Published {
  std::vector<std::string> kinds;  ///< "image" or the status state: "ok", "error", "stopping", ...
  std::vector<wingman::image_t> images;
  std::vector<wingman::status_t> statuses;
};

Published read_output(const std::string& path) {
  Published p;
  for (const auto& e : read_log(path)) {
    if (e.channel == "IMAGE_CAM0") {
      wingman::image_t img;
      EXPECT_GE(img.decode(e.data.data(), 0, static_cast<int>(e.data.size())), 0);
      p.images.push_back(img);
      p.kinds.push_back("image");
    } else if (e.channel == "STATUS_CAMERA_DRIVER") {
      wingman::status_t s;
      EXPECT_GE(s.decode(e.data.data(), 0, static_cast<int>(e.data.size())), 0);
      p.statuses.push_back(s);
      p.kinds.push_back(s.state == wingman::status_t::STATE_OK         ? "ok"
                        : s.state == wingman::status_t::STATE_ERROR    ? "error"
                        : s.state == wingman::status_t::STATE_STOPPING ? "stopping"
                                                                       : "other");
    }
  }
  return p;
}

/// A frame with driver sequence `sequence` stamped `t_mono_us` by the driver (the fake clock only moves when the
/// source sleeps, so frames dequeued back to back would otherwise share one time).
void push_timed_frame(FakeV4l2Device& device, uint32_t sequence, int64_t t_mono_us) {
  FakeEvent e;
  e.sequence = sequence;
  e.timestamp_us = t_mono_us;
  device.push_event(std::move(e));
}

constexpr int64_t kMono0 = FakeClock::kStartMonotonicUs;
constexpr int64_t kFrameUs = 33'333;

/// Runs the loop over `device` until output.max_frames frames were published; the output goes to `log`.
int64_t run_loop(const std::string& log, const std::shared_ptr<FakeClock>& clock,
                 const std::shared_ptr<FakeV4l2Device>& device, int64_t max_frames, int64_t* reconnects) {
  V4l2SourceOptions v4l2;
  v4l2.reconnect_initial_s = 0.1;
  v4l2.reconnect_max_s = 0.4;
  v4l2.stall_timeout_s = 0;
  OutputOptions output;
  output.max_frames = max_frames;
  CameraDriver driver(output, std::make_unique<V4l2Source>(v4l2, device, clock));
  driver.open();
  common::RuntimeOptions ro;
  ro.lcm_in = "memq://";  // never opened: the loop only publishes
  ro.lcm_out = "file://" + log + "?mode=w";
  ro.status_period_s = 60;  // only the heartbeats the loop sends on state changes (the fake clock is not the wall's)
  {
    common::Runtime rt({"camera_driver", "wingman-camera-driver", "test"}, ro);
    EXPECT_EQ(run_driver_loop(rt, driver, output.channel), 0);
  }
  *reconnects = driver.source().stats().reconnects;
  return driver.frames_out();
}

TEST(CameraDriverLoop, UnplugIsAnErrorHeartbeatUntilTheReplugThenFramesResumeInOrder) {
  TempDir dir;
  auto clock = std::make_shared<FakeClock>();
  auto device = std::make_shared<FakeV4l2Device>(testing::FakeDeviceConfig{}, clock.get());
  for (uint32_t i = 0; i < 4; ++i) push_timed_frame(*device, i, kMono0 - (4 - i) * kFrameUs);
  device->push_unplug(/*failing_opens=*/5);
  // The driver restarts its count after the replug; the back-off (0.1, 0.2, 0.4, 0.4, 0.4, 0.4 s) took 1.9 s.
  for (uint32_t i = 0; i < 4; ++i) push_timed_frame(*device, i, kMono0 + 1'900'000 + (i + 1) * kFrameUs);
  int64_t reconnects = 0;
  EXPECT_EQ(run_loop(dir.file("out.lcmlog"), clock, device, 8, &reconnects), 8);
  EXPECT_EQ(reconnects, 1);

  const Published p = read_output(dir.file("out.lcmlog"));
  const std::vector<std::string> expected = {"ok", "image", "image", "image", "image", "error",
                                             "ok", "image", "image", "image", "image", "stopping"};
  EXPECT_EQ(p.kinds, expected) << "nothing is published while the camera is gone";
  ASSERT_EQ(p.statuses.size(), 4u);
  const wingman::status_t& error = p.statuses[1];
  EXPECT_THAT(error.detail, HasSubstr("/dev/video0"));
  EXPECT_THAT(error.detail, HasSubstr("ENODEV"));
  EXPECT_EQ(error.last_error, error.detail);
  EXPECT_EQ(error.last_processed_seq, 3);
  const wingman::status_t& back = p.statuses[2];
  EXPECT_THAT(back.detail, HasSubstr("1 disconnect(s), 1 reconnect(s)"));
  EXPECT_THAT(back.last_error, HasSubstr("/dev/video0")) << "the last error stays visible after the recovery";
  ASSERT_EQ(p.images.size(), 8u);
  for (size_t i = 0; i < p.images.size(); ++i) {
    EXPECT_EQ(p.images[i].seq, static_cast<int64_t>(i)) << "seq keeps increasing across the replug";
    if (i > 0) {
      EXPECT_GT(p.images[i].utime, p.images[i - 1].utime) << "utime is monotonic across the replug";
    }
  }
  EXPECT_EQ(p.images[4].utime - p.images[3].utime, 1'900'000 + 2 * kFrameUs) << "the gap is the time unplugged";
  EXPECT_EQ(p.statuses.back().drops_total, 0) << "an unplug loses no counted frame in this script";
}

TEST(CameraDriverLoop, ACameraMissingAtStartIsAnErrorHeartbeatUntilItAppears) {
  TempDir dir;
  auto clock = std::make_shared<FakeClock>();
  testing::FakeDeviceConfig config;
  config.absent_opens = 3;  // the open() and two attempts fail (0.1 and 0.2 s later)
  auto device = std::make_shared<FakeV4l2Device>(config, clock.get());
  for (uint32_t i = 0; i < 3; ++i) push_timed_frame(*device, i, kMono0 + 300'000 + (i + 1) * kFrameUs);
  int64_t reconnects = 0;
  EXPECT_EQ(run_loop(dir.file("out.lcmlog"), clock, device, 3, &reconnects), 3);
  EXPECT_EQ(reconnects, 0);

  const Published p = read_output(dir.file("out.lcmlog"));
  const std::vector<std::string> expected = {"error", "ok", "image", "image", "image", "stopping"};
  EXPECT_EQ(p.kinds, expected) << "the first heartbeat already says the camera is missing; never OK before it is there";
  ASSERT_EQ(p.statuses.size(), 3u);
  EXPECT_THAT(p.statuses[0].detail, HasSubstr("device /dev/video0"));
  EXPECT_THAT(p.statuses[0].detail, HasSubstr("ENOENT"));
  EXPECT_EQ(p.statuses[0].last_error, p.statuses[0].detail);
  EXPECT_THAT(p.statuses[1].detail, HasSubstr("v4l2 /dev/video0 YUYV")) << "OK with the negotiated format";
  EXPECT_THAT(p.statuses[1].detail, ::testing::Not(HasSubstr("disconnect")));
}

TEST(CameraDriverLoop, FramesLostAroundAnUnplugAreCountedAsDrops) {
  TempDir dir;
  auto clock = std::make_shared<FakeClock>();
  auto device = std::make_shared<FakeV4l2Device>(testing::FakeDeviceConfig{}, clock.get());
  push_timed_frame(*device, 0, kMono0 - 3 * kFrameUs);
  push_timed_frame(*device, 1, kMono0 - 2 * kFrameUs);
  push_timed_frame(*device, 4, kMono0 - kFrameUs);  // frames 2 and 3 never arrived before the unplug
  device->push_unplug(/*failing_opens=*/2);
  push_timed_frame(*device, 0, kMono0 + 1'000'000);
  push_timed_frame(*device, 1, kMono0 + 1'000'000 + kFrameUs);
  int64_t reconnects = 0;
  EXPECT_EQ(run_loop(dir.file("out.lcmlog"), clock, device, 5, &reconnects), 5);
  const Published p = read_output(dir.file("out.lcmlog"));
  ASSERT_FALSE(p.statuses.empty());
  EXPECT_EQ(p.statuses.back().drops_total, 2);
  EXPECT_EQ(reconnects, 1);
  for (size_t i = 1; i < p.images.size(); ++i) {
    EXPECT_GT(p.images[i].seq, p.images[i - 1].seq);
    EXPECT_GT(p.images[i].utime, p.images[i - 1].utime);
  }
}

}  // namespace
}  // namespace wingman::camera_driver
