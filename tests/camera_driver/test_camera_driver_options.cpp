// SPDX-License-Identifier: MIT
// CameraDriverOptions: defaults, the shipped YAML file, and messages that name the bad key.
#include "wingman/camera_driver/camera_driver_options.hpp"

#include <wingman/common/config.hpp>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace wingman::camera_driver {
namespace {

using ::testing::HasSubstr;

std::string load_error(const std::string& yaml) {
  try {
    common::load_options_from_string<CameraDriverOptions>(yaml, "test.yaml");
  } catch (const common::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(CameraDriverOptions, DefaultsAreValid) { EXPECT_THAT(CameraDriverOptions{}.validate(), ::testing::IsEmpty()); }

TEST(CameraDriverOptions, ShippedConfigFileEqualsTheDefaults) {
  // ctest sets WINGMAN_SOURCE_DIR; run by hand, find the file from this source file's place.
  const char* src = std::getenv("WINGMAN_SOURCE_DIR");
  const std::filesystem::path root =
      src ? std::filesystem::path(src) : std::filesystem::path(__FILE__).parent_path().parent_path().parent_path();
  const std::string path = (root / "config" / "camera_driver.yaml").string();
  const auto loaded = common::load_options<CameraDriverOptions>(path);
  EXPECT_EQ(common::print_options(loaded), common::print_options(CameraDriverOptions{}));
}

TEST(CameraDriverOptions, EveryBadValueIsReportedNamingItsKey) {
  const std::string err = load_error(
      "source: {kind: webcam}\n"
      "v4l2: {width: 0, pixel_format: H264, fps: -2}\n"
      "file: {mode: slow}\n"
      "output: {channel: 'has space', max_frames: -1}\n");
  for (const char* key : {"source.kind = 'webcam'", "v4l2.width = 0", "v4l2.pixel_format = 'H264'", "v4l2.fps = -2",
                          "file.mode = 'slow'", "output.channel = 'has space'", "output.max_frames = -1"}) {
    EXPECT_THAT(err, HasSubstr(key));
  }
  EXPECT_THAT(err, HasSubstr("7 problems"));
}

TEST(CameraDriverOptions, EncodingIsRawOrMjpegAtAQualityAndNotWithDecodeMjpeg) {
  EXPECT_EQ(load_error("output: {encoding: mjpeg, jpeg_quality: 75}\n"), "");
  const std::string err = load_error("output: {encoding: h264, jpeg_quality: 0}\n");
  EXPECT_THAT(err, HasSubstr("output.encoding = 'h264': must be raw or mjpeg"));
  EXPECT_THAT(err, HasSubstr("output.jpeg_quality = 0: must be in 1..100"));
  EXPECT_THAT(load_error("output: {encoding: mjpeg, decode_mjpeg: true}\n"), HasSubstr("output.decode_mjpeg"));
  EXPECT_EQ(load_error("output: {encoding: raw, decode_mjpeg: true}\n"), "");
}

TEST(CameraDriverOptions, TimeOffsetIsFiniteAndWithinOneSecond) {
  EXPECT_EQ(load_error("output: {time_offset_s: -0.13}\n"), "");
  EXPECT_THAT(load_error("output: {time_offset_s: 1.5}\n"),
              HasSubstr("output.time_offset_s = 1.5: must be finite, within [-1, 1] s"));
  EXPECT_THAT(load_error("output: {time_offset_s: .nan}\n"), HasSubstr("output.time_offset_s"));
}

TEST(CameraDriverOptions, FileSourceNeedsAPathButTheCameraDoesNot) {
  EXPECT_EQ(load_error("source: {kind: v4l2}\n"), "");
  EXPECT_THAT(load_error("source: {kind: file}\n"), HasSubstr("file.path"));
  EXPECT_EQ(load_error("source: {kind: file}\nfile: {path: /tmp/x.avi, mode: fast, start_utime: 5}\n"), "");
}

TEST(CameraDriverOptions, UnknownKeysAndWrongTypesAreErrors) {
  EXPECT_THAT(load_error("v4l2: {widht: 640}\n"), HasSubstr("v4l2.widht: unknown key"));
  EXPECT_THAT(load_error("v4l2: {width: wide}\n"), HasSubstr("v4l2.width: expected an integer"));
}

TEST(CameraDriverOptions, ReconnectMaxMustNotBeBelowTheInitialWait) {
  EXPECT_THAT(load_error("v4l2: {reconnect_initial_s: 4, reconnect_max_s: 1}\n"),
              HasSubstr("v4l2.reconnect_max_s = 1"));
}

}  // namespace
}  // namespace wingman::camera_driver
