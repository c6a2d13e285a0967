// SPDX-License-Identifier: MIT
// V4l2Source against the in-process fake device: negotiation, drops, gaps, timestamps, unplug.
#include "fake_clock.hpp"
#include "fake_v4l2_device.hpp"
#include "wingman/camera_driver/v4l2_source.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>
#include <string>

namespace wingman::camera_driver {
namespace {

using testing::FakeClock;
using testing::FakeDeviceConfig;
using testing::FakeEvent;
using testing::FakeV4l2Device;
using ::testing::HasSubstr;

/// Longest loop in these tests: a read never blocks (fake device), so this bounds each test.
constexpr int kMaxReads = 2000;

struct Rig {
  std::shared_ptr<FakeClock> clock = std::make_shared<FakeClock>();
  std::shared_ptr<FakeV4l2Device> device;
  std::unique_ptr<V4l2Source> source;

  explicit Rig(V4l2SourceOptions options = {}, FakeDeviceConfig config = {}) {
    device = std::make_shared<FakeV4l2Device>(std::move(config), clock.get());
    source = std::make_unique<V4l2Source>(std::move(options), device, clock);
  }
};

/// open()'s error with wait_for_device off (with it, open() does not throw: WaitsForADeviceMissingAtStart...).
std::string open_error(V4l2SourceOptions options, FakeDeviceConfig config) {
  options.wait_for_device = false;
  Rig rig(std::move(options), std::move(config));
  try {
    rig.source->open();
  } catch (const std::runtime_error& e) {
    EXPECT_FALSE(rig.device->is_open()) << "a failed open must close the device";
    EXPECT_EQ(rig.device->live_mappings(), 0);
    return e.what();
  }
  return "";
}

TEST(V4l2Source, AcceptsTheDriversRoundedSizeAndReadsBackThePaddedStride) {
  V4l2SourceOptions options;
  options.width = 650;   // the fake rounds to a multiple of 16: 656
  options.height = 491;  // ... and of 8: 488
  Rig rig(options);
  rig.source->open();
  EXPECT_EQ(rig.device->requested_width(), 650u);
  EXPECT_EQ(rig.source->width(), 656);
  EXPECT_EQ(rig.source->height(), 488);
  EXPECT_EQ(rig.source->stride(), 1344) << "656 * 2 = 1312 bytes rounded up to 64";
  EXPECT_THAT(rig.source->describe(), HasSubstr("YUYV 656x488 stride 1344"));

  rig.device->push_frame(7);
  Frame f;
  const ReadResult r = rig.source->read(f, 100);
  ASSERT_EQ(r.status, ReadStatus::kFrame) << r.reason;
  EXPECT_EQ(f.width, 656);
  EXPECT_EQ(f.height, 488);
  EXPECT_EQ(f.stride, 1344);
  EXPECT_EQ(f.format, PixelFormat::kYuyv);
  ASSERT_EQ(f.data.size(), size_t{1344} * 488);
  EXPECT_EQ(check_frame(f), "");
  for (int y : {0, 1, 243, 487}) {
    const uint8_t* row = f.data.data() + static_cast<size_t>(y) * 1344;
    for (int x : {0, 1, 2, 1311}) EXPECT_EQ(row[x], testing::fake_pixel(7, y, x)) << "row " << y << " byte " << x;
    EXPECT_EQ(row[1312], 0xEE) << "row " << y << ": padding starts after width * 2 bytes";
    EXPECT_EQ(row[1343], 0xEE) << "row " << y;
  }
}

TEST(V4l2Source, AcceptsTheFrameRateTheDriverGrants) {
  V4l2SourceOptions options;
  options.fps = 25.0;  // the fake offers 15 and 30
  Rig rig(options);
  rig.source->open();
  EXPECT_DOUBLE_EQ(rig.source->fps(), 30.0);

  FakeDeviceConfig fixed;
  fixed.supports_timeperframe = false;
  Rig rig2(options, fixed);
  EXPECT_NO_THROW(rig2.source->open());
  EXPECT_DOUBLE_EQ(rig2.source->fps(), 30.0) << "the driver's own rate, from VIDIOC_G_PARM";
}

TEST(V4l2Source, GrantsFewerBuffersThanAskedWhenTheDriverSaysSo) {
  V4l2SourceOptions options;
  options.buffers = 16;
  Rig rig(options);  // the fake grants at most 8
  rig.source->open();
  EXPECT_EQ(rig.source->buffer_count(), 8);
  EXPECT_EQ(rig.device->live_mappings(), 8);
}

TEST(V4l2Source, MissingDeviceFailsToOpenNamingIt) {
  FakeDeviceConfig config;
  config.present = false;
  const std::string err = open_error({}, config);
  EXPECT_THAT(err, HasSubstr("device /dev/video0"));
  EXPECT_THAT(err, HasSubstr("ENOENT"));
}

TEST(V4l2Source, WaitsForADeviceMissingAtStartThenStreamsWithoutCountingAReconnect) {
  V4l2SourceOptions options;  // wait_for_device: true by default
  options.reconnect_initial_s = 0.5;
  options.reconnect_max_s = 1.0;
  options.stall_timeout_s = 0;
  FakeDeviceConfig config;
  config.absent_opens = 4;  // the open() and three attempts fail: the camera appears at the fourth
  Rig rig(options, config);
  ASSERT_NO_THROW(rig.source->open());
  EXPECT_THAT(rig.source->waiting_reason(), HasSubstr("device /dev/video0"));
  EXPECT_THAT(rig.source->waiting_reason(), HasSubstr("ENOENT"));
  EXPECT_EQ(rig.source->describe(), "v4l2 /dev/video0 (waiting for the device)");
  EXPECT_FALSE(rig.source->streaming());
  rig.device->push_frames(0, 2);

  Frame f;
  std::vector<int64_t> seqs;
  int waiting_results = 0;
  bool first_frame_flagged = false;
  for (int i = 0; i < kMaxReads && seqs.size() < 2; ++i) {
    const ReadResult r = rig.source->read(f, 100);
    if (r.status == ReadStatus::kDisconnected) {
      ++waiting_results;
      EXPECT_THAT(r.reason, HasSubstr("/dev/video0"));
    }
    if (r.status == ReadStatus::kFrame) {
      if (seqs.empty()) first_frame_flagged = r.reconnected;
      seqs.push_back(f.seq);
    }
  }
  EXPECT_EQ(seqs, (std::vector<int64_t>{0, 1}));
  EXPECT_GT(waiting_results, 0);
  EXPECT_TRUE(first_frame_flagged) << "the first frame says the source came up (the loop's heartbeat turns OK)";
  EXPECT_TRUE(rig.source->waiting_reason().empty());
  EXPECT_TRUE(rig.source->streaming());
  EXPECT_EQ(rig.source->stats().disconnects, 0) << "it never streamed before: not a disconnect";
  EXPECT_EQ(rig.source->stats().reconnects, 0);
  // The attempts back off as after an unplug: 0.5, 1, 1 (capped), 1 s after the failed open().
  const auto& attempts = rig.device->open_attempts_us();
  ASSERT_EQ(attempts.size(), 5u);
  std::vector<int64_t> gaps_us;
  for (size_t i = 1; i < attempts.size(); ++i) gaps_us.push_back(attempts[i] - attempts[i - 1]);
  EXPECT_EQ(gaps_us, (std::vector<int64_t>{500'000, 1'000'000, 1'000'000, 1'000'000}));
}

TEST(V4l2Source, WaitingForTheDeviceAlsoRetriesANegotiationThatFailsAndSaysWhy) {
  FakeDeviceConfig config;
  config.formats = {v4l2_fourcc('H', '2', '6', '4')};
  Rig rig({}, config);
  ASSERT_NO_THROW(rig.source->open());
  EXPECT_THAT(rig.source->waiting_reason(), HasSubstr("pixel format 'YUYV' not supported"));
  EXPECT_FALSE(rig.device->is_open()) << "the failed negotiation closed the device";
  Frame f;
  for (int i = 0; i < 50; ++i) {
    const ReadResult r = rig.source->read(f, 100);
    ASSERT_EQ(r.status, ReadStatus::kDisconnected);
    EXPECT_THAT(r.reason, HasSubstr("not supported"));
  }
  EXPECT_GE(rig.device->open_calls(), 3);
}

TEST(V4l2Source, UnsupportedPixelFormatFailsNamingWhatTheDriverOffers) {
  FakeDeviceConfig config;
  config.formats = {v4l2_fourcc('H', '2', '6', '4')};
  const std::string err = open_error({}, config);
  EXPECT_THAT(err, HasSubstr("device /dev/video0: pixel format 'YUYV' not supported"));
  EXPECT_THAT(err, HasSubstr("H264"));
  EXPECT_THAT(err, HasSubstr("expected YUYV or MJPG"));
}

TEST(V4l2Source, DeviceWithoutCaptureOrStreamingIsRejected) {
  FakeDeviceConfig output_only;
  output_only.capabilities = V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING;
  EXPECT_THAT(open_error({}, output_only), HasSubstr("is not a single-planar video capture device"));

  FakeDeviceConfig read_only;
  read_only.capabilities = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_READWRITE;
  EXPECT_THAT(open_error({}, read_only), HasSubstr("does not support streaming I/O"));
}

TEST(V4l2Source, TooFewBuffersIsAnError) {
  FakeDeviceConfig config;
  config.max_buffers = 1;
  EXPECT_THAT(open_error({}, config), HasSubstr("driver granted 1 buffers, need at least 2"));
}

TEST(V4l2Source, SequenceGapsAreReportedOnTheNextFrameAndCounted) {
  Rig rig;
  rig.source->open();
  for (uint32_t s : {10u, 11u, 14u, 15u, 20u}) rig.device->push_frame(s);
  Frame f;
  std::vector<int64_t> seqs, lost;
  for (int i = 0; i < 5; ++i) {
    const ReadResult r = rig.source->read(f, 100);
    ASSERT_EQ(r.status, ReadStatus::kFrame) << i;
    seqs.push_back(f.seq);
    lost.push_back(r.lost);
    if (r.lost > 0) {
      EXPECT_THAT(r.reason, HasSubstr("lost before seq"));
    }
  }
  EXPECT_EQ(seqs, (std::vector<int64_t>{10, 11, 14, 15, 20}));
  EXPECT_EQ(lost, (std::vector<int64_t>{0, 0, 2, 0, 4}));
  EXPECT_EQ(rig.source->stats().lost_in_gaps, 6);
  EXPECT_EQ(rig.source->stats().frames, 5);
  EXPECT_EQ(rig.source->stats().dropped, 0);
}

TEST(V4l2Source, ErrorFlaggedBufferIsACountedDropAndNotCountedAgainAsAGap) {
  Rig rig;
  rig.source->open();
  // 20 frames through 4 buffers: dropped buffers must be queued again or capture would stall.
  for (uint32_t s = 0; s < 20; ++s) rig.device->push_frame(s, s % 3 == 1 ? V4L2_BUF_FLAG_ERROR : 0);
  Frame f;
  int frames = 0, drops = 0;
  for (int i = 0; i < 20; ++i) {
    const ReadResult r = rig.source->read(f, 100);
    if (r.status == ReadStatus::kDropped) {
      ++drops;
      EXPECT_EQ(r.lost, 1);
      EXPECT_THAT(r.reason, HasSubstr("V4L2_BUF_FLAG_ERROR"));
      EXPECT_THAT(r.reason, HasSubstr("/dev/video0"));
    } else {
      ASSERT_EQ(r.status, ReadStatus::kFrame) << "read " << i << ": " << r.reason;
      EXPECT_EQ(r.lost, 0) << "seq " << f.seq;
      ++frames;
    }
  }
  EXPECT_EQ(drops, 7);
  EXPECT_EQ(frames, 13);
  EXPECT_EQ(rig.source->stats().dropped, 7);
  EXPECT_EQ(rig.source->stats().lost_in_gaps, 0);
  EXPECT_EQ(rig.device->pending_events(), 0u);
}

TEST(V4l2Source, EmptyAndTruncatedBuffersAreCountedDrops) {
  Rig rig;
  rig.source->open();
  const int64_t full = int64_t{rig.source->stride()} * rig.source->height();
  const int64_t last_row_padding = rig.source->stride() - rig.source->width() * 2;
  rig.device->push_frame(0, 0, 0);                        // bytesused 0
  rig.device->push_frame(1, 0, full / 2);                 // truncated
  rig.device->push_frame(2, 0, full - last_row_padding);  // last row without padding: fine
  Frame f;
  ReadResult r = rig.source->read(f, 100);
  EXPECT_EQ(r.status, ReadStatus::kDropped);
  EXPECT_THAT(r.reason, HasSubstr("bytesused 0"));
  r = rig.source->read(f, 100);
  EXPECT_EQ(r.status, ReadStatus::kDropped);
  EXPECT_THAT(r.reason, HasSubstr("truncated"));
  r = rig.source->read(f, 100);
  ASSERT_EQ(r.status, ReadStatus::kFrame) << r.reason;
  EXPECT_EQ(f.seq, 2);
  EXPECT_EQ(f.data.size(), static_cast<size_t>(full));
  EXPECT_EQ(rig.source->stats().dropped, 2);
}

TEST(V4l2Source, MjpegFramesKeepTheJpegStreamAndRejectNonJpeg) {
  V4l2SourceOptions options;
  options.pixel_format = "MJPEG";
  Rig rig(options);
  rig.source->open();
  EXPECT_EQ(rig.source->stride(), 0);
  FakeEvent good;
  good.sequence = 0;
  good.payload = {0xFF, 0xD8, 1, 2, 3, 4, 0xFF, 0xD9};
  rig.device->push_event(good);
  FakeEvent garbage;
  garbage.sequence = 1;
  garbage.payload = {0x00, 0x11, 0x22, 0x33, 0x44};
  rig.device->push_event(garbage);
  Frame f;
  ReadResult r = rig.source->read(f, 100);
  ASSERT_EQ(r.status, ReadStatus::kFrame) << r.reason;
  EXPECT_EQ(f.format, PixelFormat::kMjpeg);
  EXPECT_EQ(f.stride, 0);
  EXPECT_EQ(f.data, good.payload);
  r = rig.source->read(f, 100);
  EXPECT_EQ(r.status, ReadStatus::kDropped);
  EXPECT_THAT(r.reason, HasSubstr("not a JPEG image"));
}

TEST(V4l2Source, MonotonicBufferTimestampsBecomeEpochTime) {
  Rig rig;
  rig.source->open();
  const int64_t offset = FakeClock::kStartRealtimeUs - FakeClock::kStartMonotonicUs;
  FakeEvent e;
  e.sequence = 0;
  e.timestamp_us = rig.clock->monotonic_utime() - 20'000;  // exposed 20 ms before the dequeue
  rig.device->push_event(e);
  FakeEvent zero;
  zero.sequence = 1;
  zero.timestamp_us = 0;  // a driver without timestamps
  rig.device->push_event(zero);
  Frame f;
  ASSERT_EQ(rig.source->read(f, 100).status, ReadStatus::kFrame);
  EXPECT_EQ(f.utime, e.timestamp_us + offset) << "utime = t_mono + (realtime - monotonic)";
  EXPECT_EQ(f.utime, rig.clock->realtime_utime() - 20'000);
  ASSERT_EQ(rig.source->read(f, 100).status, ReadStatus::kFrame);
  EXPECT_EQ(f.utime, rig.clock->realtime_utime()) << "zero timestamp: stamped at dequeue";
}

// What the stamps mark, from the first buffer's V4L2_BUF_FLAG_TSTAMP_SRC_* flag, ends describe(): a user sees whether
// the camera stamps the start of exposure (UVC) or the end of the frame (then output.time_offset_s applies).
TEST(V4l2Source, DescribeSaysWhetherTheStampsMarkTheStartOfExposureOrTheEndOfTheFrame) {
  for (const bool eof : {false, true}) {
    FakeDeviceConfig config;
    config.timestamp_end_of_frame = eof;
    Rig rig({}, config);
    rig.source->open();
    EXPECT_THAT(rig.source->describe(), ::testing::Not(HasSubstr("stamps"))) << "not known before the first buffer";
    FakeEvent e;
    e.sequence = 0;
    rig.device->push_event(e);
    Frame f;
    ASSERT_EQ(rig.source->read(f, 100).status, ReadStatus::kFrame);
    EXPECT_THAT(rig.source->describe(),
                HasSubstr(eof ? ", stamps at the end of the frame" : ", stamps at the start of exposure"));
  }
}

TEST(V4l2Source, TimeoutWhenNoFrameIsReady) {
  Rig rig;
  rig.source->open();
  Frame f;
  EXPECT_EQ(rig.source->read(f, 50).status, ReadStatus::kTimeout);
  EXPECT_EQ(rig.source->stats().frames, 0);
}

TEST(V4l2Source, UnplugReconnectsWithExponentialBackoffAndSeqKeepsIncreasing) {
  V4l2SourceOptions options;
  options.reconnect_initial_s = 0.5;
  options.reconnect_max_s = 2.0;
  options.stall_timeout_s = 0;
  Rig rig(options);
  rig.source->open();
  rig.device->push_frames(0, 3);
  rig.device->push_unplug(/*failing_opens=*/4);
  rig.device->push_frames(0, 2);  // the driver restarts its count after the replug

  Frame f;
  std::vector<int64_t> seqs;
  int disconnected_results = 0;
  bool saw_reconnected = false;
  int64_t unplug_mono_us = -1;
  for (int i = 0; i < kMaxReads && seqs.size() < 5; ++i) {
    const ReadResult r = rig.source->read(f, 100);
    if (r.reconnected) saw_reconnected = true;
    if (r.status == ReadStatus::kFrame) seqs.push_back(f.seq);
    if (r.status == ReadStatus::kDisconnected) {
      if (disconnected_results++ == 0) {
        unplug_mono_us = rig.clock->monotonic_utime();
        EXPECT_THAT(r.reason, HasSubstr("device /dev/video0"));
        EXPECT_THAT(r.reason, HasSubstr("ENODEV"));
        EXPECT_FALSE(rig.source->streaming());
        EXPECT_EQ(rig.device->live_mappings(), 0) << "buffers unmapped at the unplug";
        EXPECT_FALSE(rig.device->is_open());
      }
    }
  }
  ASSERT_EQ(seqs, (std::vector<int64_t>{0, 1, 2, 3, 4}));
  EXPECT_TRUE(saw_reconnected);
  EXPECT_EQ(rig.source->stats().disconnects, 1);
  EXPECT_EQ(rig.source->stats().reconnects, 1);

  // Attempts after the unplug: 4 failures then success, spaced 0.5, 1, 2 (capped), 2, 2 s.
  const auto& attempts = rig.device->open_attempts_us();
  ASSERT_EQ(attempts.size(), 6u) << "initial open + 5 reconnection attempts";
  std::vector<int64_t> gaps_us;
  int64_t prev = unplug_mono_us;
  for (size_t i = 1; i < attempts.size(); ++i) {
    gaps_us.push_back(attempts[i] - prev);
    prev = attempts[i];
  }
  EXPECT_EQ(gaps_us, (std::vector<int64_t>{500'000, 1'000'000, 2'000'000, 2'000'000, 2'000'000}));
  for (int64_t s : rig.clock->sleeps_us()) EXPECT_LE(s, 100'000) << "a read sleeps at most its timeout";
}

TEST(V4l2Source, ReconnectionKeepsRetryingWhileTheDeviceIsGone) {
  V4l2SourceOptions options;
  options.reconnect_initial_s = 0.1;
  options.reconnect_max_s = 0.4;
  Rig rig(options);
  rig.source->open();
  rig.device->push_unplug(/*failing_opens=*/1000);
  Frame f;
  std::string last_reason;
  for (int i = 0; i < 200; ++i) {
    const ReadResult r = rig.source->read(f, 100);
    ASSERT_EQ(r.status, ReadStatus::kDisconnected);
    last_reason = r.reason;
  }
  EXPECT_THAT(last_reason, HasSubstr("/dev/video0"));
  EXPECT_EQ(rig.source->backoff_us(), 400'000);
  EXPECT_GE(rig.device->open_calls(), 40);
  EXPECT_EQ(rig.source->stats().disconnects, 1);
  EXPECT_EQ(rig.source->stats().reconnects, 0);
}

TEST(V4l2Source, NoFrameForTheStallTimeoutCountsAsADisconnect) {
  V4l2SourceOptions options;
  options.stall_timeout_s = 1.0;
  Rig rig(options);
  rig.source->open();
  Frame f;
  ReadResult r;
  int reads = 0;
  do {
    r = rig.source->read(f, 100);  // each timed-out poll advances the fake clock by 100 ms
  } while (r.status == ReadStatus::kTimeout && ++reads < kMaxReads);
  EXPECT_EQ(r.status, ReadStatus::kDisconnected);
  EXPECT_THAT(r.reason, HasSubstr("stalled"));
  EXPECT_EQ(reads, 10);

  // The device comes back on the next attempt.
  rig.device->push_frames(0, 1);
  for (int i = 0; i < kMaxReads && r.status != ReadStatus::kFrame; ++i) r = rig.source->read(f, 100);
  EXPECT_EQ(r.status, ReadStatus::kFrame);
  EXPECT_EQ(rig.source->stats().reconnects, 1);
}

TEST(V4l2Source, TeardownStopsStreamingUnmapsAndCloses) {
  auto clock = std::make_shared<FakeClock>();
  auto device = std::make_shared<FakeV4l2Device>(FakeDeviceConfig{}, clock.get());
  {
    V4l2Source source({}, device, clock);
    source.open();
    EXPECT_TRUE(device->streaming());
    EXPECT_EQ(device->live_mappings(), 4);
  }
  EXPECT_FALSE(device->streaming());
  EXPECT_EQ(device->live_mappings(), 0);
  EXPECT_FALSE(device->is_open());
}

TEST(V4l2Source, ReadBeforeOpenIsAProgrammingError) {
  Rig rig;
  Frame f;
  EXPECT_THROW(rig.source->read(f, 0), std::logic_error);
}

TEST(V4l2SourceOptions, DefaultsAreValidAndBadValuesNameTheirKey) {
  EXPECT_THAT(V4l2SourceOptions{}.validate(), ::testing::IsEmpty());
  V4l2SourceOptions bad;
  bad.pixel_format = "H264";
  bad.width = 0;
  bad.buffers = 1;
  bad.reconnect_initial_s = 2.0;
  bad.reconnect_max_s = 1.0;
  const auto p = bad.validate();
  ASSERT_EQ(p.size(), 4u);
  EXPECT_THAT(p[0], HasSubstr("v4l2.pixel_format = 'H264'"));
  EXPECT_THAT(p[1], HasSubstr("v4l2.width = 0"));
  EXPECT_THAT(p[2], HasSubstr("v4l2.buffers = 1"));
  EXPECT_THAT(p[3], HasSubstr("v4l2.reconnect_max_s = 1"));
}

}  // namespace
}  // namespace wingman::camera_driver
