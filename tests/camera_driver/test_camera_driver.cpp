// SPDX-License-Identifier: MIT
// CameraDriver: frame -> image_t conversion (padded stride, MJPEG), drops, limits, source factory.
#include "fake_clock.hpp"
#include "fake_v4l2_device.hpp"
#include "test_support.hpp"
#include "test_video.hpp"
#include "wingman/camera_driver/camera_driver.hpp"

#include <wingman/common/message_validation.hpp>
#include <wingman/detector/preprocess.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdio>
#include <cstring>
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

/// `img` as a frame of `format` (BGR8 or GRAY8) with `padding` bytes at the end of every row.
Frame frame_of(const cv::Mat& img, PixelFormat format, int padding, int64_t seq) {
  Frame f;
  f.seq = seq;
  f.utime = 1'700'000'000'000'000 + seq * 33'333;
  f.width = img.cols;
  f.height = img.rows;
  f.format = format;
  f.stride = img.cols * bytes_per_pixel(format) + padding;
  f.data.assign(static_cast<size_t>(f.stride) * static_cast<size_t>(f.height), 0xAB);  // padding that must not show
  for (int r = 0; r < img.rows; ++r)
    std::memcpy(f.data.data() + static_cast<size_t>(r) * static_cast<size_t>(f.stride), img.ptr(r),
                static_cast<size_t>(img.cols) * static_cast<size_t>(bytes_per_pixel(format)));
  return f;
}

/// One frame through a CameraDriver with output.encoding mjpeg at `quality`.
DriverStep encode_through_driver(Frame frame, int quality) {
  auto src = std::make_unique<ScriptedSource>();
  src->items.push_back({ReadResult{ReadStatus::kFrame, 0, "", false}, std::move(frame)});
  OutputOptions out;
  out.camera_id = 3;
  out.encoding = "mjpeg";
  out.jpeg_quality = quality;
  CameraDriver driver(out, std::move(src));
  return driver.step(0);
}

// The load test's transport (output.encoding mjpeg, quality 90): the driver's MJPEG frame is what the detector's
// preprocessing (detector::image_to_bgr, the only image_t -> pixels path) turns back into the same size and close
// pixels. Tolerances: baseline JPEG at quality 90 with 4:2:0 chroma on this scene measured mean |difference| 1.6-1.7
// levels and PSNR 38.5-40.4 dB (1280x720 and 333x187); the bounds (mean <= 2.5, PSNR >= 34 dB) leave room for another
// libjpeg's rounding while a wrong channel order, a lost stride or a half-size image misses them by far.
TEST(CameraDriver, MjpegEncodingDecodesInTheDetectorToTheSameSizeAndClosePixels) {
  struct Case {
    int width, height, padding;
  };
  for (const Case c : {Case{1280, 720, 0}, Case{333, 187, 7}}) {
    SCOPED_TRACE(::testing::Message() << c.width << "x" << c.height << " BGR8, " << c.padding << " bytes of padding");
    const cv::Mat scene = testing::seeded_scene(c.width, c.height, 31);
    const DriverStep step = encode_through_driver(frame_of(scene, PixelFormat::kBgr8, c.padding, 7), 90);
    ASSERT_EQ(step.status, ReadStatus::kFrame) << step.reason;
    EXPECT_EQ(step.image.pixel_format, int8_t{wingman::image_t::MJPEG});
    EXPECT_EQ(step.image.stride, 0);
    EXPECT_EQ(step.image.width, c.width);
    EXPECT_EQ(step.image.height, c.height);
    EXPECT_EQ(step.image.seq, 7);
    EXPECT_EQ(step.image.utime, 1'700'000'000'000'000 + 7 * 33'333);
    EXPECT_EQ(step.image.camera_id, 3);
    EXPECT_EQ(step.image.size, static_cast<int32_t>(step.image.data.size()));
    EXPECT_LT(step.image.data.size(), scene.total() * 3 / 4) << "compressed";
    EXPECT_EQ(common::validate_message(step.image), "");
    std::string error;
    const cv::Mat decoded = detector::image_to_bgr(step.image, &error);
    ASSERT_EQ(error, "");
    ASSERT_EQ(decoded.size(), scene.size());
    ASSERT_EQ(decoded.type(), CV_8UC3);
    const double mean_abs = cv::norm(decoded, scene, cv::NORM_L1) / static_cast<double>(scene.total() * 3);
    const double psnr = cv::PSNR(decoded, scene);
    EXPECT_LE(mean_abs, 2.5);
    EXPECT_GE(psnr, 34.0);
    std::printf("[ measured ] %dx%d q90: %zu bytes (%.1f %% of BGR8), mean |difference| %.2f levels, PSNR %.1f dB\n",
                c.width, c.height, step.image.data.size(), 100.0 * step.image.data.size() / (scene.total() * 3.0),
                mean_abs, psnr);
  }
}

// GRAY8 and YUYV are encoded from what the detector reads of them (the same conversion). The 320x240 scene has more
// edges per pixel than the 720p one: measured mean |difference| 0.5 (GRAY8) and 3.1 (YUYV, whose subsampled chroma
// JPEG subsamples again) levels; bound 4.5.
TEST(CameraDriver, MjpegEncodingTakesGrayAndYuyvFrames) {
  const cv::Mat scene = testing::seeded_scene(320, 240, 32);
  cv::Mat gray;
  cv::cvtColor(scene, gray, cv::COLOR_BGR2GRAY);
  DriverStep step = encode_through_driver(frame_of(gray, PixelFormat::kGray8, 3, 1), 90);
  ASSERT_EQ(step.status, ReadStatus::kFrame) << step.reason;
  std::string error;
  cv::Mat decoded = detector::image_to_bgr(step.image, &error);
  ASSERT_EQ(error, "");
  ASSERT_EQ(decoded.size(), gray.size());
  cv::Mat gray_expected;
  cv::cvtColor(gray, gray_expected, cv::COLOR_GRAY2BGR);
  const double gray_mean_abs = cv::norm(decoded, gray_expected, cv::NORM_L1) / static_cast<double>(gray.total() * 3);
  EXPECT_LE(gray_mean_abs, 4.5);

  // YUYV: the camera's own layout, made from the scene (Y per pixel, U and V per pair), then what the detector reads
  // from the raw YUYV frame is what it reads from the encoded one, within the JPEG bound.
  Frame yuyv;
  yuyv.width = 320;
  yuyv.height = 240;
  yuyv.stride = 640;
  yuyv.format = PixelFormat::kYuyv;
  cv::Mat yuv;
  cv::cvtColor(scene, yuv, cv::COLOR_BGR2YUV);
  yuyv.data.resize(640 * 240);
  for (int y = 0; y < 240; ++y) {
    for (int x = 0; x < 320; x += 2) {
      const cv::Vec3b a = yuv.at<cv::Vec3b>(y, x), b = yuv.at<cv::Vec3b>(y, x + 1);
      uint8_t* d = yuyv.data.data() + y * 640 + x * 2;
      d[0] = a[0];
      d[1] = static_cast<uint8_t>((a[1] + b[1]) / 2);
      d[2] = b[0];
      d[3] = static_cast<uint8_t>((a[2] + b[2]) / 2);
    }
  }
  const cv::Mat raw_in_detector = detector::image_to_bgr(to_image_message(yuyv, 0), &error);
  ASSERT_EQ(error, "");
  step = encode_through_driver(yuyv, 90);
  ASSERT_EQ(step.status, ReadStatus::kFrame) << step.reason;
  decoded = detector::image_to_bgr(step.image, &error);
  ASSERT_EQ(error, "");
  ASSERT_EQ(decoded.size(), raw_in_detector.size());
  const double yuyv_mean_abs =
      cv::norm(decoded, raw_in_detector, cv::NORM_L1) / static_cast<double>(decoded.total() * 3);
  EXPECT_LE(yuyv_mean_abs, 4.5);
  std::printf("[ measured ] 320x240 q90: mean |difference| GRAY8 %.2f, YUYV %.2f levels\n", gray_mean_abs,
              yuyv_mean_abs);
}

TEST(CameraDriver, MaxWidthDownscalesRawFramesKeepingTheAspectBeforeEncoding) {
  const cv::Mat scene = testing::seeded_scene(1280, 720, 33);
  auto src = std::make_unique<ScriptedSource>();
  src->items.push_back({ReadResult{ReadStatus::kFrame, 0, "", false}, frame_of(scene, PixelFormat::kBgr8, 4, 1)});
  src->items.push_back({ReadResult{ReadStatus::kFrame, 0, "", false}, frame_of(scene, PixelFormat::kBgr8, 0, 2)});
  OutputOptions out;
  out.max_width = 640;
  CameraDriver raw_driver(out, std::move(src));
  DriverStep step = raw_driver.step(0);
  ASSERT_EQ(step.status, ReadStatus::kFrame) << step.reason;
  EXPECT_EQ(step.image.pixel_format, int8_t{wingman::image_t::BGR8});
  EXPECT_EQ(step.image.width, 640);
  EXPECT_EQ(step.image.height, 360);
  EXPECT_EQ(step.image.stride, 640 * 3);
  EXPECT_EQ(step.image.seq, 1);
  cv::Mat expected;
  cv::resize(scene, expected, cv::Size(640, 360), 0, 0, cv::INTER_AREA);
  std::string error;
  EXPECT_EQ(cv::norm(detector::image_to_bgr(step.image, &error), expected, cv::NORM_INF), 0.0) << error;

  Frame small = frame_of(scene, PixelFormat::kBgr8, 0, 3);
  auto src2 = std::make_unique<ScriptedSource>();
  src2->items.push_back({ReadResult{ReadStatus::kFrame, 0, "", false}, small});
  out.encoding = "mjpeg";
  CameraDriver jpeg_driver(out, std::move(src2));
  step = jpeg_driver.step(0);
  ASSERT_EQ(step.status, ReadStatus::kFrame) << step.reason;
  EXPECT_EQ(step.image.pixel_format, int8_t{wingman::image_t::MJPEG});
  const cv::Mat decoded = detector::image_to_bgr(step.image, &error);
  ASSERT_EQ(decoded.size(), cv::Size(640, 360)) << error;
  EXPECT_LE(cv::norm(decoded, expected, cv::NORM_L1) / static_cast<double>(expected.total() * 3), 4.5);
}

TEST(CameraDriver, MjpegEncodingPassesAnMjpegCamerasStreamThroughUntouched) {
  V4l2SourceOptions v4l2;
  v4l2.pixel_format = "MJPEG";
  v4l2.width = 64;
  v4l2.height = 48;
  OutputOptions out;
  out.encoding = "mjpeg";
  out.jpeg_quality = 20;  // would change the bytes, were the stream re-encoded
  V4l2Rig rig(v4l2, out);
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", testing::pattern_image(64, 48, 5), jpeg, {cv::IMWRITE_JPEG_QUALITY, 95});
  FakeEvent e;
  e.payload = jpeg;
  rig.device->push_event(e);
  const DriverStep step = rig.driver->step(100);
  ASSERT_EQ(step.status, ReadStatus::kFrame) << step.reason;
  EXPECT_EQ(step.image.pixel_format, int8_t{wingman::image_t::MJPEG});
  EXPECT_EQ(step.image.data, jpeg);
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

// output.time_offset_s moves every published stamp by the same amount (a camera that stamps 0.13 s after its
// exposure: -0.13 s), to the microsecond, keeping their order; a bad offset is refused at construction naming the key.
TEST(CameraDriver, TimeOffsetMovesEveryStampToTheExposure) {
  auto src = std::make_unique<ScriptedSource>();
  for (int i = 0; i < 3; ++i) src->items.push_back({ReadResult{ReadStatus::kFrame, 0, "", false}, gray_frame(i, 4, 2)});
  OutputOptions out;
  out.time_offset_s = -0.1300004;  // rounds to -130000 us
  CameraDriver driver(out, std::move(src));
  EXPECT_THAT(driver.describe(), HasSubstr(", stamps moved by -0.13 s (output.time_offset_s)"));
  for (int64_t i = 0; i < 3; ++i) {
    const DriverStep step = driver.step(0);
    ASSERT_EQ(step.status, ReadStatus::kFrame) << step.reason;
    EXPECT_EQ(step.image.utime, gray_frame(i, 4, 2).utime - 130'000);
    EXPECT_EQ(step.image.seq, i);
  }
  OutputOptions bad;
  bad.time_offset_s = 2.0;
  try {
    CameraDriver refused(bad, std::make_unique<ScriptedSource>());
    FAIL() << "an offset of 2 s was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("output.time_offset_s = 2"));
  }
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
