// SPDX-License-Identifier: MIT
// `wingman loginfo` (summarize_log): channels, types by fingerprint, undecodable messages, each process's last
// status, and the last image as a snapshot, on a real LCM log file.
#include <wingman/image_t.hpp>
#include <wingman/status_t.hpp>
#include <wingman/tools/log_info.hpp>

#include "test_support.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <stdexcept>
#include <string>
#include <vector>

namespace wingman::tools {
namespace {

using wingman::testing::LogEvent;
using wingman::testing::make_event;

image_t bgr_image(int64_t utime, int width, int height, cv::Vec3b colour) {
  image_t img{};
  img.utime = utime;
  img.width = width;
  img.height = height;
  img.pixel_format = image_t::BGR8;
  img.stride = width * 3;
  for (int i = 0; i < width * height; ++i) img.data.insert(img.data.end(), {colour[0], colour[1], colour[2]});
  img.size = static_cast<int32_t>(img.data.size());
  return img;
}

status_t detector_status(int64_t utime, int64_t handled) {
  status_t s{};
  s.utime = utime;
  s.process = "detector";
  s.pid = 42;
  s.state = status_t::STATE_OK;
  s.detail = "opencl";
  s.messages_handled = handled;
  s.last_processed_seq = handled - 1;
  s.latency_p50_ms = 8.5f;
  return s;
}

TEST(LogInfo, CountsChannelsNamesTypesAndSnapshotsTheLastImage) {
  testing::TempDir dir;
  std::vector<LogEvent> events;
  events.push_back(make_event("IMAGE_CAM0", bgr_image(1000, 32, 24, {10, 20, 30}), 1000));
  events.push_back(make_event("STATUS_DETECTOR", detector_status(1500, 1), 1500));
  // An image whose data is cut short: its fingerprint says image_t, but it does not decode.
  LogEvent cut = make_event("IMAGE_CAM0", bgr_image(2000, 32, 24, {0, 0, 0}), 2000);
  cut.data.resize(cut.data.size() / 2);
  events.push_back(cut);
  // One that decodes but is impossible (stride below width x 3): counted as undecodable, never drawn.
  image_t bad = bgr_image(2500, 32, 24, {0, 0, 0});
  bad.stride = 10;
  events.push_back(make_event("IMAGE_CAM0", bad, 2500));
  events.push_back(LogEvent{2600, "SOMETHING_ELSE", {1, 2, 3, 4, 5, 6, 7, 8, 9}});
  events.push_back(make_event("IMAGE_CAM0", bgr_image(3000, 40, 30, {200, 100, 50}), 3000));
  events.push_back(make_event("STATUS_DETECTOR", detector_status(3500, 2), 3500));
  wingman::testing::write_log(dir.file("a.lcmlog"), events);

  const LogSummary s = summarize_log(dir.file("a.lcmlog"), dir.file("last.png"));
  ASSERT_EQ(s.channels.size(), 3u);
  const ChannelSummary& images = s.channels[0];
  EXPECT_EQ(images.channel, "IMAGE_CAM0");
  EXPECT_EQ(images.type, "image_t");
  EXPECT_EQ(images.count, 4);
  EXPECT_EQ(images.undecodable, 2);
  EXPECT_EQ(images.first_utime, 1000);
  EXPECT_EQ(images.last_utime, 3000);
  EXPECT_EQ(s.channels[1].channel, "STATUS_DETECTOR");
  EXPECT_EQ(s.channels[1].count, 2);
  EXPECT_EQ(s.channels[2].type, "?");
  EXPECT_EQ(s.channels[2].bytes, 9);
  EXPECT_EQ(s.images_with_pixels, 1);  // only the last image is decoded
  ASSERT_EQ(s.statuses.count("detector"), 1u);
  EXPECT_NE(s.statuses.at("detector").find("OK 'opencl', handled 2"), std::string::npos) << s.statuses.at("detector");
  EXPECT_NE(s.report().find("IMAGE_CAM0"), std::string::npos) << s.report();
  // The snapshot is the last good image, pixel for pixel.
  const cv::Mat png = cv::imread(dir.file("last.png"), cv::IMREAD_COLOR);
  ASSERT_EQ(png.size(), cv::Size(40, 30));
  EXPECT_EQ(png.at<cv::Vec3b>(29, 39), cv::Vec3b(200, 100, 50));
}

TEST(LogInfo, AMissingLogIsNamed) {
  testing::TempDir dir;
  try {
    summarize_log(dir.file("none.lcmlog"));
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("none.lcmlog: cannot open LCM log for reading"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace wingman::tools
