// SPDX-License-Identifier: MIT
// Test videos written with OpenCV's built-in AVI writer. Apart from test_support: only the tests that write a video
// link opencv_videoio, whose dependencies (ffmpeg, GStreamer: about 240 shared libraries) cost each test process
// about 0.2 s of dynamic loading at start-up.
#include "test_video.hpp"

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <stdexcept>

namespace wingman::testing {

void write_test_video(const std::string& path, int frames, int width, int height, double fps) {
  cv::VideoWriter writer(path, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps,
                         cv::Size(width, height));
  if (!writer.isOpened()) throw std::runtime_error(path + ": cannot open video writer");
  for (int i = 0; i < frames; ++i) {
    cv::Mat img(height, width, CV_8UC3);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        img.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uchar>((x * 3) & 0xff), static_cast<uchar>((y * 5) & 0xff), 90);
      }
    }
    const int s = std::max(4, width / 10);
    const int x0 = (i * 7) % std::max(1, width - s), y0 = (i * 3) % std::max(1, height - s);
    cv::rectangle(img, cv::Rect(x0, y0, s, s), cv::Scalar(255, 255, 255), cv::FILLED);
    writer.write(img);
  }
}

}  // namespace wingman::testing
