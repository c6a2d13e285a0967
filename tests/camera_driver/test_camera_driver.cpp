// SPDX-License-Identifier: MIT
// CameraDriver: frame -> image_t conversion (padded stride, MJPEG), drops, limits, source factory.
#include "fake_clock.hpp"
#include "fake_v4l2_device.hpp"
#include "test_support.hpp"
#include "test_video.hpp"
#include "wingman/camera_driver/camera_driver.hpp"

#include <wingman/common/message_validation.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <deque>
#include <memory>

namespace wingman::camera_driver {
namespace {

using testing::FakeClock;
using testing::FakeDeviceConfig;
using testing::FakeEvent;
using testing::FakeV4l2Device;
using ::testing::HasSubstr;
using wingman::testing::TempDir;

/// A FrameSource that plays back a scripted list of results.
class ScriptedSource : public FrameSource {
 public:
  struct Item {
    ReadResult result;
    Frame frame;
  };
  std::deque<Item> items;
  void open() override {}
  ReadResult read(Frame& out, int) override {
    if (items.empty()) return ReadResult{ReadStatus::kEnd, 0, "", false};
    Item it = items.front();
    items.pop_front();
    if (it.result.status == ReadStatus::kFrame) out = it.frame;
    return it.result;
  }
  std::string describe() const override { return "scripted"; }
  const SourceStats& stats() const override { return stats_; }

 private:
  SourceStats stats_;
};

Frame gray_frame(int64_t seq, int width, int height) {
  Frame f;
  f.seq = seq;
  f.utime = 1'700'000'000'000'000 + seq;
  f.width = width;
  f.height = height;
  f.stride = width;
  f.format = PixelFormat::kGray8;
  f.data.assign(static_cast<size_t>(width) * static_cast<size_t>(height), 9);
  return f;
}

struct V4l2Rig {
  std::shared_ptr<FakeClock> clock = std::make_shared<FakeClock>();
  std::shared_ptr<FakeV4l2Device> device;
  std::unique_ptr<CameraDriver> driver;
  V4l2Rig(V4l2SourceOptions v4l2, OutputOptions output, FakeDeviceConfig config = {}) {
    device = std::make_shared<FakeV4l2Device>(std::move(config), clock.get());
    driver = std::make_unique<CameraDriver>(output, std::make_unique<V4l2Source>(v4l2, device, clock));
    driver->open();
  }
};

TEST(CameraDriver, PublishedYuyvImageKeepsTheDriversPaddedStrideRowByRow) {
  V4l2SourceOptions v4l2;
  v4l2.width = 100;  // rounded to a multiple of 16: 96
  v4l2.height = 75;  // rounded to a multiple of 8: 72
  FakeDeviceConfig padded;
  padded.stride_align = 128;  // 96 * 2 = 192 bytes per row padded to 256
  V4l2Rig rig(v4l2, OutputOptions{}, padded);
  rig.device->push_frame(3);
  const DriverStep step = rig.driver->step(100);
  ASSERT_EQ(step.status, ReadStatus::kFrame) << step.reason;
  const wingman::image_t& img = step.image;
  EXPECT_EQ(img.width, 96);
  EXPECT_EQ(img.height, 72);
  EXPECT_EQ(img.stride, 256) << "stride == bytesperline";
  EXPECT_EQ(img.pixel_format, int8_t{wingman::image_t::YUYV});
  EXPECT_EQ(img.size, 256 * 72);
  ASSERT_EQ(img.data.size(), size_t{256} * 72);
  EXPECT_EQ(common::validate_message(img), "");
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width * 2; ++x) {
      ASSERT_EQ(img.data[static_cast<size_t>(y) * 256 + x], testing::fake_pixel(3, y, x))
          << "row " << y << " byte " << x;
    }
  }
  EXPECT_EQ(img.seq, 3);
  EXPECT_EQ(img.camera_id, 0);
}

TEST(CameraDriver, MjpegIsPublishedUndecodedByDefault) {
  V4l2SourceOptions v4l2;
  v4l2.pixel_format = "MJPEG";
  v4l2.width = 64;
  v4l2.height = 48;
  OutputOptions out;
  out.camera_id = 2;
  V4l2Rig rig(v4l2, out);
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", testing::pattern_image(64, 48, 5), jpeg);
  FakeEvent e;
  e.payload = jpeg;
  rig.device->push_event(e);
  const DriverStep step = rig.driver->step(100);
  ASSERT_EQ(step.status, ReadStatus::kFrame) << step.reason;
  EXPECT_EQ(step.image.pixel_format, int8_t{wingman::image_t::MJPEG});
  EXPECT_EQ(step.image.stride, 0);
  EXPECT_EQ(step.image.camera_id, 2);
  EXPECT_EQ(step.image.data, jpeg);
  EXPECT_EQ(step.image.size, static_cast<int32_t>(jpeg.size()));
  EXPECT_EQ(common::validate_message(step.image), "");
}

TEST(CameraDriver, DecodeMjpegPublishesBgr8AndDropsCorruptStreams) {
  V4l2SourceOptions v4l2;
  v4l2.pixel_format = "MJPEG";
  v4l2.width = 64;
  v4l2.height = 48;
  OutputOptions out;
  out.decode_mjpeg = true;
  V4l2Rig rig(v4l2, out);
  cv::Mat original(48, 64, CV_8UC3);  // smooth ramps: JPEG (4:2:0 chroma) keeps them within a few levels
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) original.at<cv::Vec3b>(y, x) = cv::Vec3b(x * 2, y * 3, 128);
  }
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", original, jpeg, {cv::IMWRITE_JPEG_QUALITY, 100});
  FakeEvent good;
  good.payload = jpeg;
  rig.device->push_event(good);
  FakeEvent corrupt;
  corrupt.sequence = 1;
  corrupt.payload = {0xFF, 0xD8, 0x00, 0x01, 0x02, 0xFF, 0xD9};  // SOI, then nonsense
  rig.device->push_event(corrupt);

  DriverStep step = rig.driver->step(100);
  ASSERT_EQ(step.status, ReadStatus::kFrame) << step.reason;
  EXPECT_EQ(step.image.pixel_format, int8_t{wingman::image_t::BGR8});
  EXPECT_EQ(step.image.stride, 64 * 3);
  EXPECT_EQ(step.image.size, 64 * 3 * 48);
  const cv::Mat got(48, 64, CV_8UC3, step.image.data.data());
  EXPECT_LE(cv::norm(got, original, cv::NORM_INF), 8.0);

  step = rig.driver->step(100);
  EXPECT_EQ(step.status, ReadStatus::kDropped);
  EXPECT_EQ(step.lost, 1);
  EXPECT_THAT(step.reason, HasSubstr("does not decode"));
  EXPECT_EQ(rig.driver->driver_drops(), 1);
  EXPECT_EQ(rig.driver->frames_out(), 1);
}

TEST(CameraDriver, ZeroSizeFramesAreCountedDrops) {
  auto src = std::make_unique<ScriptedSource>();
  src->items.push_back({ReadResult{ReadStatus::kFrame, 0, "", false}, gray_frame(0, 0, 0)});
  src->items.push_back({ReadResult{ReadStatus::kFrame, 0, "", false}, gray_frame(1, 4, 2)});
  CameraDriver driver(OutputOptions{}, std::move(src));
  DriverStep step = driver.step(0);
  EXPECT_EQ(step.status, ReadStatus::kDropped);
  EXPECT_EQ(step.lost, 1);
  EXPECT_THAT(step.reason, HasSubstr("zero size"));
  step = driver.step(0);
  ASSERT_EQ(step.status, ReadStatus::kFrame);
  EXPECT_EQ(step.image.seq, 1);
  EXPECT_EQ(step.image.pixel_format, int8_t{wingman::image_t::GRAY8});
  EXPECT_EQ(driver.driver_drops(), 1);
}

TEST(CameraDriver, SourceLossesPassThroughWithTheFrame) {
  auto src = std::make_unique<ScriptedSource>();
  src->items.push_back({ReadResult{ReadStatus::kFrame, 3, "3 frames lost", false}, gray_frame(9, 4, 2)});
  src->items.push_back({ReadResult{ReadStatus::kDisconnected, 0, "device gone", false}, Frame{}});
  CameraDriver driver(OutputOptions{}, std::move(src));
  DriverStep step = driver.step(0);
  EXPECT_EQ(step.status, ReadStatus::kFrame);
  EXPECT_EQ(step.lost, 3);
  EXPECT_EQ(step.reason, "3 frames lost");
  step = driver.step(0);
  EXPECT_EQ(step.status, ReadStatus::kDisconnected);
  EXPECT_EQ(step.reason, "device gone");
  EXPECT_FALSE(driver.done());
  EXPECT_EQ(driver.step(0).status, ReadStatus::kEnd);
  EXPECT_TRUE(driver.done());
}

TEST(CameraDriver, MaxFramesEndsTheRun) {
  auto src = std::make_unique<ScriptedSource>();
  for (int i = 0; i < 5; ++i) src->items.push_back({ReadResult{ReadStatus::kFrame, 0, "", false}, gray_frame(i, 4, 2)});
  OutputOptions out;
  out.max_frames = 2;
  CameraDriver driver(out, std::move(src));
  int steps = 0;
  while (!driver.done() && steps < 10) {
    driver.step(0);
    ++steps;
  }
  EXPECT_EQ(steps, 2);
  EXPECT_EQ(driver.frames_out(), 2);
}

TEST(CameraDriver, MakeSourceBuildsTheSelectedKind) {
  TempDir dir;
  testing::write_gray_video(dir.file("clip.avi"), 1, 16, 16, 10.0);
  CameraDriverOptions o;
  o.source_kind = "file";
  o.file.path = dir.file("clip.avi");
  auto clock = std::make_shared<FakeClock>();
  auto device = std::make_shared<FakeV4l2Device>(FakeDeviceConfig{}, clock.get());
  auto file = make_source(o, device, clock);
  EXPECT_NE(dynamic_cast<FileSource*>(file.get()), nullptr);
  o.source_kind = "v4l2";
  auto cam = make_source(o, device, clock);
  EXPECT_NE(dynamic_cast<V4l2Source*>(cam.get()), nullptr);
  EXPECT_EQ(device->open_calls(), 0) << "make_source does not open";
  o.v4l2.buffers = 0;
  try {
    make_source(o, device, clock);
    FAIL() << "expected invalid options to throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("v4l2.buffers"));
  }
}

TEST(Frame, CheckFrameNamesTheBrokenInvariant) {
  Frame f = gray_frame(4, 6, 3);
  EXPECT_EQ(check_frame(f), "");
  f.stride = 5;
  EXPECT_THAT(check_frame(f), HasSubstr("stride 5 < width"));
  f = gray_frame(4, 6, 3);
  f.data.pop_back();
  EXPECT_THAT(check_frame(f), HasSubstr("expected stride * height = 18"));
  f = gray_frame(4, 0, 3);
  EXPECT_THAT(check_frame(f), HasSubstr("zero size"));
  f.format = PixelFormat::kYuyv;
  f.width = 3;
  f.stride = 6;
  f.data.assign(18, 0);
  EXPECT_THAT(check_frame(f), HasSubstr("odd"));
  EXPECT_EQ(pixel_format_name(PixelFormat::kMjpeg), "MJPEG");
  EXPECT_EQ(static_cast<int8_t>(PixelFormat::kYuyv), int8_t{wingman::image_t::YUYV})
      << "values equal image_t's constants";
}

}  // namespace
}  // namespace wingman::camera_driver
