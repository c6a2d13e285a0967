// SPDX-License-Identifier: MIT
// FileSource on videos and image folders written by the tests: timing modes, loop, drops, errors.
#include "fake_clock.hpp"
#include "test_support.hpp"
#include "test_video.hpp"
#include "wingman/camera_driver/file_source.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <memory>
#include <numeric>
#include <stdexcept>

namespace wingman::camera_driver {
namespace {

using testing::FakeClock;
using ::testing::HasSubstr;
using testing::kStartUtime;
using testing::level_of;
using wingman::testing::TempDir;

constexpr int kMaxFileReads = 1000;  // bounds every read loop

/// Mean of all bytes of a raw frame's pixels (padding excluded).
double mean_level(const Frame& f) {
  const int row_bytes = f.width * bytes_per_pixel(f.format);
  double sum = 0;
  for (int y = 0; y < f.height; ++y) {
    const uint8_t* row = f.data.data() + static_cast<size_t>(y) * f.stride;
    sum = std::accumulate(row, row + row_bytes, sum);
  }
  return sum / (static_cast<double>(row_bytes) * f.height);
}

FileSourceOptions fast(const std::string& path) {
  FileSourceOptions o;
  o.path = path;
  o.mode = "fast";
  o.start_utime = kStartUtime;
  return o;
}

std::string open_error(const FileSourceOptions& options) {
  FileSource source(options, std::make_shared<FakeClock>());
  try {
    source.open();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(FileSource, VideoInFastModeHasDeterministicUtimesAndFrameOrder) {
  TempDir dir;
  const std::string video = dir.file("clip.avi");
  testing::write_gray_video(video, 5, 64, 48, 10.0);

  auto play = [&](std::vector<Frame>& frames) {
    FileSource source(fast(video), std::make_shared<FakeClock>());
    source.open();
    EXPECT_DOUBLE_EQ(source.fps(), 10.0) << "file.fps 0 takes the video's rate";
    Frame f;
    for (int i = 0; i < kMaxFileReads; ++i) {
      const ReadResult r = source.read(f, 0);
      if (r.status == ReadStatus::kEnd) break;
      ASSERT_EQ(r.status, ReadStatus::kFrame) << r.reason;
      frames.push_back(f);
    }
    EXPECT_EQ(source.read(f, 0).status, ReadStatus::kEnd) << "the end stays the end";
    EXPECT_EQ(source.stats().frames, 5);
  };
  std::vector<Frame> a, b;
  play(a);
  play(b);
  ASSERT_EQ(a.size(), 5u);
  for (size_t i = 0; i < a.size(); ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    EXPECT_EQ(a[i].seq, static_cast<int64_t>(i));
    EXPECT_EQ(a[i].utime, kStartUtime + static_cast<int64_t>(i) * 100'000) << "start_utime + i * 1e6 / fps";
    EXPECT_EQ(a[i].width, 64);
    EXPECT_EQ(a[i].height, 48);
    EXPECT_EQ(a[i].format, PixelFormat::kBgr8);
    EXPECT_EQ(a[i].stride, 64 * 3);
    EXPECT_EQ(check_frame(a[i]), "");
    EXPECT_NEAR(mean_level(a[i]), level_of(static_cast<int>(i)), 6.0) << "JPEG error on a flat image is a few levels";
    EXPECT_EQ(a[i].utime, b[i].utime);
    EXPECT_EQ(a[i].data, b[i].data) << "same file, same frames";
  }
}

TEST(FileSource, ConfiguredFpsOverridesTheVideosRateAndGray8IsOneBytePerPixel) {
  TempDir dir;
  const std::string video = dir.file("clip.avi");
  testing::write_gray_video(video, 2, 32, 16, 10.0);
  FileSourceOptions o = fast(video);
  o.fps = 20.0;
  o.pixel_format = "GRAY8";
  FileSource source(o, std::make_shared<FakeClock>());
  source.open();
  Frame f;
  ASSERT_EQ(source.read(f, 0).status, ReadStatus::kFrame);
  ASSERT_EQ(source.read(f, 0).status, ReadStatus::kFrame);
  EXPECT_EQ(f.utime, kStartUtime + 50'000);
  EXPECT_EQ(f.format, PixelFormat::kGray8);
  EXPECT_EQ(f.stride, 32);
  EXPECT_EQ(f.data.size(), size_t{32} * 16);
  EXPECT_NEAR(mean_level(f), level_of(1), 6.0);
}

TEST(FileSource, LoopRestartsTheFileWhileSeqAndUtimeKeepIncreasing) {
  TempDir dir;
  const std::string video = dir.file("clip.avi");
  testing::write_gray_video(video, 3, 32, 16, 10.0);
  FileSourceOptions o = fast(video);
  o.loop = true;
  FileSource source(o, std::make_shared<FakeClock>());
  source.open();
  Frame f;
  for (int i = 0; i < 8; ++i) {
    const ReadResult r = source.read(f, 0);
    ASSERT_EQ(r.status, ReadStatus::kFrame) << "read " << i << ": " << r.reason;
    EXPECT_EQ(f.seq, i);
    EXPECT_EQ(f.utime, kStartUtime + i * 100'000);
    EXPECT_NEAR(mean_level(f), level_of(i % 3), 6.0) << "read " << i;
  }
}

TEST(FileSource, ImageFolderPlaysInNameOrderAndSkipsOtherFiles) {
  TempDir dir;
  const cv::Mat a = testing::pattern_image(40, 30, 0), b = testing::pattern_image(40, 30, 100);
  cv::imwrite(dir.file("frame_002.png"), b);
  cv::imwrite(dir.file("frame_001.png"), a);
  testing::write_text(dir.file("notes.txt"), "not an image");
  FileSource source(fast(dir.path()), std::make_shared<FakeClock>());
  source.open();
  ASSERT_EQ(source.images().size(), 2u);
  EXPECT_THAT(source.images()[0], HasSubstr("frame_001.png"));
  EXPECT_DOUBLE_EQ(source.fps(), 30.0) << "images have no rate: 30 fps";
  Frame f;
  for (const cv::Mat* expected : {&a, &b}) {
    ASSERT_EQ(source.read(f, 0).status, ReadStatus::kFrame);
    ASSERT_EQ(f.width, 40);
    ASSERT_EQ(f.stride, 120);
    const cv::Mat got(f.height, f.width, CV_8UC3, f.data.data(), static_cast<size_t>(f.stride));
    EXPECT_EQ(cv::norm(got, *expected, cv::NORM_INF), 0.0) << "PNG is lossless";
  }
  EXPECT_EQ(f.utime, kStartUtime + 33'333) << "round(1e6 / 30)";
  EXPECT_EQ(source.read(f, 0).status, ReadStatus::kEnd);
}

TEST(FileSource, UndecodableImageIsACountedDropThatLeavesASeqGap) {
  TempDir dir;
  cv::imwrite(dir.file("a.png"), testing::pattern_image(16, 16, 1));
  testing::write_text(dir.file("b.png"), "this is not a PNG");
  cv::imwrite(dir.file("c.png"), testing::pattern_image(16, 16, 2));
  FileSource source(fast(dir.path()), std::make_shared<FakeClock>());
  source.open();
  Frame f;
  ASSERT_EQ(source.read(f, 0).status, ReadStatus::kFrame);
  EXPECT_EQ(f.seq, 0);
  const ReadResult r = source.read(f, 0);
  EXPECT_EQ(r.status, ReadStatus::kDropped);
  EXPECT_EQ(r.lost, 1);
  EXPECT_THAT(r.reason, HasSubstr("b.png"));
  ASSERT_EQ(source.read(f, 0).status, ReadStatus::kFrame);
  EXPECT_EQ(f.seq, 2);
  EXPECT_EQ(source.stats().dropped, 1);
  EXPECT_EQ(source.stats().frames, 2);
}

TEST(FileSource, AFolderWhereNothingDecodesIsAnErrorWithOrWithoutLoop) {
  TempDir dir;
  testing::write_text(dir.file("broken.jpg"), "garbage");
  for (bool loop : {false, true}) {
    SCOPED_TRACE(loop ? "loop" : "no loop");
    FileSourceOptions o = fast(dir.path());
    o.loop = loop;
    FileSource source(o, std::make_shared<FakeClock>());
    source.open();
    Frame f;
    EXPECT_EQ(source.read(f, 0).status, ReadStatus::kDropped) << "one bad frame is a drop";
    try {
      source.read(f, 0);
      FAIL() << "expected an error at the end of a pass without one decoded frame";
    } catch (const std::runtime_error& e) {
      EXPECT_THAT(e.what(), HasSubstr("none of its 1 image decodes"));
      EXPECT_THAT(e.what(), HasSubstr(dir.path()));
    }
  }
}

TEST(FileSource, SingleImageFileIsAOneFrameSource) {
  TempDir dir;
  cv::imwrite(dir.file("one.bmp"), testing::pattern_image(8, 4, 3));
  FileSource source(fast(dir.file("one.bmp")), std::make_shared<FakeClock>());
  source.open();
  Frame f;
  EXPECT_EQ(source.read(f, 0).status, ReadStatus::kFrame);
  EXPECT_EQ(source.read(f, 0).status, ReadStatus::kEnd);
}

TEST(FileSource, BadPathsFailToOpenNamingThePath) {
  TempDir dir;
  const std::string missing = dir.file("missing.avi");
  EXPECT_THAT(open_error(fast(missing)), HasSubstr("file " + missing + ": does not exist"));

  const std::string bad_video = dir.file("bad.avi");
  testing::write_text(bad_video, "RIFF? no, just text pretending to be a video");
  const std::string err = open_error(fast(bad_video));
  EXPECT_THAT(err, HasSubstr(bad_video));
  EXPECT_THAT(err, HasSubstr("cannot open as a video"));

  std::filesystem::create_directories(dir.file("empty"));
  EXPECT_THAT(open_error(fast(dir.file("empty"))), HasSubstr("folder holds no images"));
}

TEST(FileSource, RealtimeModePacesFramesWithTheClockAndStampsTheSchedule) {
  TempDir dir;
  const std::string video = dir.file("clip.avi");
  testing::write_gray_video(video, 3, 32, 16, 10.0);
  FileSourceOptions o;
  o.path = video;
  o.mode = "realtime";
  auto clock = std::make_shared<FakeClock>();
  FileSource source(o, clock);
  source.open();
  const int64_t open_real = clock->realtime_utime();
  const int64_t open_mono = clock->monotonic_utime();
  Frame f;
  std::vector<int64_t> arrival_us;
  for (int i = 0; i < kMaxFileReads && arrival_us.size() < 3; ++i) {
    const ReadResult r = source.read(f, 30);  // waits at most 30 ms per call
    if (r.status == ReadStatus::kTimeout) continue;
    ASSERT_EQ(r.status, ReadStatus::kFrame) << r.reason;
    const int64_t k = static_cast<int64_t>(arrival_us.size());
    EXPECT_EQ(f.utime, open_real + k * 100'000) << "frame " << k;
    arrival_us.push_back(clock->monotonic_utime() - open_mono);
  }
  EXPECT_EQ(arrival_us, (std::vector<int64_t>{0, 100'000, 200'000}));
  for (int64_t s : clock->sleeps_us()) EXPECT_LE(s, 30'000);
}

TEST(FileSourceOptions, DefaultsAreValidWhenThePathIsNotRequired) {
  EXPECT_THAT(FileSourceOptions{}.validate(false), ::testing::IsEmpty());
  EXPECT_THAT(FileSourceOptions{}.validate(true), ::testing::ElementsAre(HasSubstr("file.path")));
  FileSourceOptions bad;
  bad.path = "x";
  bad.mode = "slow";
  bad.fps = -1;
  bad.start_utime = -5;
  bad.pixel_format = "RGB8";
  const auto p = bad.validate();
  ASSERT_EQ(p.size(), 4u);
  EXPECT_THAT(p[0], HasSubstr("file.mode = 'slow'"));
  EXPECT_THAT(p[1], HasSubstr("file.fps = -1"));
  EXPECT_THAT(p[2], HasSubstr("file.start_utime = -5"));
  EXPECT_THAT(p[3], HasSubstr("file.pixel_format = 'RGB8'"));
}

}  // namespace
}  // namespace wingman::camera_driver
