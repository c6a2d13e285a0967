// SPDX-License-Identifier: MIT
// Synthetic test clips.
#include "wingman/tools/make_video.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <wingman/common/config.hpp>

#include <cmath>
#include <stdexcept>

namespace wingman::tools {

std::vector<std::string> MakeVideoOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (output.empty()) p.emplace_back("output.file: give the file to write (OUTPUT, or the key)");
  if (frames < 1 || frames > 100000) p.push_back(problem("video.frames", frames, "must be 1..100000"));
  if (width < 16 || width > 8192) p.push_back(problem("video.width", width, "must be 16..8192"));
  if (height < 16 || height > 8192) p.push_back(problem("video.height", height, "must be 16..8192"));
  if (!(fps > 0 && fps <= 1000)) p.push_back(problem("video.fps", fps, "must be in (0, 1000]"));
  return p;
}

void make_video(const MakeVideoOptions& o) {
  if (const auto bad = o.validate(); !bad.empty()) throw std::runtime_error(fmt::format("{}", fmt::join(bad, "; ")));
  cv::VideoWriter writer(o.output, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), o.fps,
                         cv::Size(o.width, o.height));
  if (!writer.isOpened()) throw std::runtime_error(fmt::format("{}: cannot write a video here", o.output));
  cv::Mat sky(o.height, o.width, CV_8UC3);
  for (int y = 0; y < o.height; ++y) {
    const double t = static_cast<double>(y) / o.height;  // light blue at the top, paler at the horizon
    sky.row(y).setTo(cv::Scalar(235 - 20 * t, 200 + 30 * t, 150 + 80 * t));
  }
  cv::Mat frame;
  for (int i = 0; i < o.frames; ++i) {
    sky.copyTo(frame);
    const double phase = 2.0 * M_PI * i / o.frames;
    const cv::Point2d c(o.width * (0.5 + 0.35 * std::cos(phase)), o.height * (0.45 + 0.2 * std::sin(2 * phase)));
    const double arm = 0.04 * o.width;
    const cv::Scalar dark(40, 40, 40);
    for (int k = 0; k < 4; ++k) {  // X-frame quadcopter: arms, rotor discs, body
      const double a = M_PI / 4 + k * M_PI / 2;
      const cv::Point2d tip(c.x + arm * std::cos(a), c.y + 0.4 * arm * std::sin(a));
      cv::line(frame, c, tip, dark, std::max(1, o.width / 320), cv::LINE_AA);
      cv::ellipse(frame, tip, cv::Size2d(0.5 * arm, 0.12 * arm), 0, 0, 360, cv::Scalar(90, 90, 90), cv::FILLED,
                  cv::LINE_AA);
    }
    cv::ellipse(frame, c, cv::Size2d(0.35 * arm, 0.2 * arm), 0, 0, 360, dark, cv::FILLED, cv::LINE_AA);
    cv::putText(frame, fmt::format("wingman synthetic clip  frame {}", i), cv::Point(8, o.height - 10),
                cv::FONT_HERSHEY_SIMPLEX, 0.4 * o.width / 640.0 + 0.1, cv::Scalar(30, 30, 30), 1, cv::LINE_AA);
    writer.write(frame);
  }
}

}  // namespace wingman::tools
