// SPDX-License-Identifier: MIT
// PreviewMaker: rate by message time, downscaled JPEG of every pixel format, channel names, options; and the
// camera driver's process publishing previews on PREVIEW_CAM0.
#include <wingman/camera_driver/preview.hpp>
#include <wingman/common/message_validation.hpp>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace wingman::camera_driver {
namespace {

constexpr int64_t kT0 = 1'700'000'000'000'000;

/// A 1280x720 BGR frame: a left half of (40, 80, 160), a right half of (200, 200, 200).
cv::Mat test_bgr() {
  cv::Mat m(720, 1280, CV_8UC3, cv::Scalar(40, 80, 160));
  m(cv::Rect(640, 0, 640, 720)).setTo(cv::Scalar(200, 200, 200));
  return m;
}

wingman::image_t image_of(const cv::Mat& bgr, int8_t format, int64_t utime) {
  wingman::image_t m{};
  m.utime = utime;
  m.seq = 7;
  m.camera_id = 2;
  m.width = bgr.cols;
  m.height = bgr.rows;
  m.pixel_format = format;
  cv::Mat px;
  switch (format) {
    case wingman::image_t::BGR8:
      px = bgr;
      m.stride = bgr.cols * 3;
      break;
    case wingman::image_t::GRAY8:
      cv::cvtColor(bgr, px, cv::COLOR_BGR2GRAY);
      m.stride = bgr.cols;
      break;
    case wingman::image_t::YUYV: {
      // Packed 4:2:2, BT.601 studio range (what cameras send and OpenCV's YUV2BGR_YUYV reads), by the textbook
      // formulas: each pixel pair shares the mean of its U and V.
      px.create(bgr.rows, bgr.cols, CV_8UC2);
      const auto yuv = [](const cv::Vec3b& p) {
        const double b = p[0], g = p[1], r = p[2];
        return cv::Vec3d(16 + (65.481 * r + 128.553 * g + 24.966 * b) / 255,
                         128 + (-37.797 * r - 74.203 * g + 112.0 * b) / 255,
                         128 + (112.0 * r - 93.786 * g - 18.214 * b) / 255);
      };
      const auto u8 = [](double v) { return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0, 255.0))); };
      for (int r = 0; r < bgr.rows; ++r)
        for (int c = 0; c < bgr.cols; c += 2) {
          const cv::Vec3d a = yuv(bgr.at<cv::Vec3b>(r, c)), b = yuv(bgr.at<cv::Vec3b>(r, c + 1));
          px.at<cv::Vec2b>(r, c) = {u8(a[0]), u8((a[1] + b[1]) / 2)};
          px.at<cv::Vec2b>(r, c + 1) = {u8(b[0]), u8((a[2] + b[2]) / 2)};
        }
      m.stride = bgr.cols * 2;
      break;
    }
    case wingman::image_t::MJPEG: {
      std::vector<uint8_t> jpeg;
      cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95});
      m.stride = 0;
      m.data = jpeg;
      m.size = static_cast<int32_t>(jpeg.size());
      return m;
    }
  }
  m.data.assign(px.data, px.data + px.total() * px.elemSize());
  m.size = static_cast<int32_t>(m.data.size());
  return m;
}

cv::Mat decode(const wingman::image_t& p) {
  return cv::imdecode(cv::Mat(1, static_cast<int>(p.data.size()), CV_8UC1, const_cast<uint8_t*>(p.data.data())),
                      cv::IMREAD_COLOR);
}

TEST(Preview, EveryPixelFormatGivesADownscaledJpegOfTheSameScene) {
  const cv::Mat bgr = test_bgr();
  for (const int8_t format :
       {wingman::image_t::BGR8, wingman::image_t::GRAY8, wingman::image_t::YUYV, wingman::image_t::MJPEG}) {
    SCOPED_TRACE("pixel format " + std::to_string(format));
    PreviewMaker maker(PreviewOptions{});
    const auto p = maker.offer(image_of(bgr, format, kT0));
    ASSERT_TRUE(p.has_value());
    EXPECT_EQ(common::validate_message(*p), "");
    EXPECT_EQ(p->pixel_format, int8_t{wingman::image_t::MJPEG});
    EXPECT_EQ(p->width, 320);
    EXPECT_EQ(p->height, 180);
    EXPECT_EQ(p->stride, 0);
    EXPECT_EQ(p->utime, kT0);
    EXPECT_EQ(p->seq, 7);
    EXPECT_EQ(p->camera_id, 2);
    EXPECT_LT(p->data.size(), 60000u) << "one UDP datagram: lcm-spy (Java LCM) receives it";
    const cv::Mat d = decode(*p);
    ASSERT_EQ(d.cols, 320);
    // The scene: the left half dark, the right half light (gray for GRAY8), within JPEG's error.
    const cv::Scalar left = cv::mean(d(cv::Rect(20, 20, 100, 140))), right = cv::mean(d(cv::Rect(200, 20, 100, 140)));
    const cv::Scalar want_left = format == wingman::image_t::GRAY8
                                     ? cv::Scalar::all(0.114 * 40 + 0.587 * 80 + 0.299 * 160)
                                     : cv::Scalar(40, 80, 160);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(left[c], want_left[c], 6.0) << "channel " << c;
      EXPECT_NEAR(right[c], 200.0, 6.0) << "channel " << c;
    }
  }
}

TEST(Preview, AtMostRateHzOfMessageTimeTheFirstFrameAlwaysAndATimeStepBackRestarts) {
  PreviewOptions o;
  o.rate_hz = 2.0;  // every 0.5 s
  PreviewMaker maker(o);
  const cv::Mat bgr = test_bgr();
  std::vector<int64_t> made;
  for (int k = 0; k < 20; ++k) {  // 2 s at 10 Hz
    const int64_t t = kT0 + k * 100'000;
    if (maker.offer_bgr(bgr, t, k, 0)) made.push_back(k);
  }
  EXPECT_EQ(made, (std::vector<int64_t>{0, 5, 10, 15})) << "frames 0, 0.5, 1.0 and 1.5 s";
  // At 30 Hz (33 333 us): the first frame 0.5 s or more after the previous preview (0.533, 1.067, 1.6 s).
  PreviewMaker at30(o);
  made.clear();
  for (int k = 0; k < 60; ++k)
    if (at30.offer_bgr(bgr, kT0 + k * 33'333, k, 0)) made.push_back(k);
  EXPECT_EQ(made, (std::vector<int64_t>{0, 16, 32, 48})) << "each 0.5 s or more after the previous preview";
  // A frame dated before the last preview (a replay started again) restarts the clock.
  EXPECT_TRUE(maker.offer_bgr(bgr, kT0, 0, 0).has_value());
  EXPECT_FALSE(maker.offer_bgr(bgr, kT0 + 100'000, 1, 0).has_value());
  EXPECT_EQ(maker.made(), 5);
}

TEST(Preview, DisabledNarrowAndUnreadableFrames) {
  PreviewOptions off;
  off.enabled = false;
  EXPECT_FALSE(PreviewMaker(off).offer_bgr(test_bgr(), kT0, 0, 0).has_value());

  PreviewMaker maker(PreviewOptions{});
  cv::Mat narrow(60, 100, CV_8UC3, cv::Scalar(1, 2, 3));  // narrower than max_width: kept at its size
  const auto p = maker.offer_bgr(narrow, kT0, 0, 0);
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(p->width, 100);
  EXPECT_EQ(p->height, 60);

  PreviewMaker broken_maker(PreviewOptions{});
  wingman::image_t broken = image_of(test_bgr(), wingman::image_t::BGR8, kT0);
  broken.data.resize(100);  // fewer bytes than its rows
  broken.size = 100;
  EXPECT_FALSE(broken_maker.offer(broken).has_value());
  wingman::image_t junk = image_of(test_bgr(), wingman::image_t::MJPEG, kT0 + 1);
  std::memset(junk.data.data(), 0, junk.data.size());
  EXPECT_FALSE(broken_maker.offer(junk).has_value());
  EXPECT_EQ(broken_maker.failures(), 2);
  EXPECT_EQ(broken_maker.made(), 0);
}

TEST(Preview, ChannelNamesAndOptionChecks) {
  PreviewOptions o;
  EXPECT_EQ(o.channel_for("IMAGE_CAM0"), "PREVIEW_CAM0");
  EXPECT_EQ(o.channel_for("IMAGE_CAM3"), "PREVIEW_CAM3");
  EXPECT_EQ(o.channel_for("FRONT"), "PREVIEW_FRONT");
  o.channel = "MY_PREVIEW";
  EXPECT_EQ(o.channel_for("IMAGE_CAM0"), "MY_PREVIEW");
  EXPECT_TRUE(PreviewOptions{}.validate().empty());
  PreviewOptions bad;
  bad.rate_hz = 0;
  bad.max_width = 8;
  bad.jpeg_quality = 101;
  const auto p = bad.validate();
  ASSERT_EQ(p.size(), 3u);
  EXPECT_NE(p[0].find("preview.rate_hz"), std::string::npos);
  EXPECT_NE(p[1].find("preview.max_width"), std::string::npos);
  EXPECT_NE(p[2].find("preview.jpeg_quality"), std::string::npos);
}

}  // namespace
}  // namespace wingman::camera_driver
