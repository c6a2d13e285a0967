// SPDX-License-Identifier: MIT
// Test media written on the fly: an MJPG AVI whose frame i is uniformly gray at level_of(i), images.
// (tests/support has a moving-square video for pipeline tests; flat frames here make decoded content checkable.)
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <fstream>
#include <stdexcept>
#include <string>

namespace wingman::camera_driver::testing {

/// Gray level of frame i in write_gray_video (spaced 20 apart so JPEG error cannot confuse them).
inline int level_of(int i) { return 20 + 20 * (i % 11); }

/// Writes `count` frames of `width` x `height` BGR at `fps` into an MJPG AVI at `path` (OpenCV's
/// built-in AVI writer, no external codec needed). Throws if the writer cannot be opened.
inline void write_gray_video(const std::string& path, int count, int width, int height, double fps) {
  cv::VideoWriter writer(path, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps,
                         cv::Size(width, height), true);
  if (!writer.isOpened()) throw std::runtime_error("cannot write test video " + path);
  for (int i = 0; i < count; ++i) {
    writer.write(cv::Mat(height, width, CV_8UC3, cv::Scalar::all(level_of(i))));
  }
}

/// An image with a deterministic pattern: pixel (x, y) channel c = (x * 5 + y * 11 + c * 50 + seed) mod 256.
inline cv::Mat pattern_image(int width, int height, int seed) {
  cv::Mat img(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c)
        img.at<cv::Vec3b>(y, x)[c] = static_cast<uint8_t>((x * 5 + y * 11 + c * 50 + seed) & 0xff);
    }
  }
  return img;
}

/// Writes `text` to `path` (garbage "media" for error tests).
inline void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

}  // namespace wingman::camera_driver::testing
