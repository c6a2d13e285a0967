// SPDX-License-Identifier: MIT
// Test media written on the fly: an MJPG AVI whose frame i is uniformly gray at level_of(i), images.
// (tests/support has a moving-square video for pipeline tests; flat frames here make decoded content checkable.)
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <stdexcept>
#include <string>

namespace wingman::camera_driver::testing {

/// A fixed start time for file sources (utime, microseconds): fast mode is then deterministic.
constexpr int64_t kStartUtime = 1'700'000'000'000'000;

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

/// A camera-like test image, fixed seed: seeded random colours at 1/16 of the size, upscaled smoothly (textures and
/// gradients), with dark sharp-edged boxes (targets against the sky) on top.
inline cv::Mat seeded_scene(int width, int height, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat coarse(std::max(2, height / 16), std::max(2, width / 16), CV_8UC3);
  rng.fill(coarse, cv::RNG::UNIFORM, 0, 256);
  cv::Mat scene;
  cv::resize(coarse, scene, cv::Size(width, height), 0, 0, cv::INTER_CUBIC);
  for (int i = 0; i < 6; ++i) {
    const int w = rng.uniform(8, std::max(9, width / 8));
    const int h = rng.uniform(6, std::max(7, height / 8));
    const cv::Rect box(rng.uniform(0, width - w), rng.uniform(0, height - h), w, h);
    cv::rectangle(scene, box, cv::Scalar(rng.uniform(0, 60), rng.uniform(0, 60), rng.uniform(0, 60)), cv::FILLED);
  }
  return scene;
}

/// Writes `text` to `path` (garbage "media" for error tests).
inline void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

}  // namespace wingman::camera_driver::testing
