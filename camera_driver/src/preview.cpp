// SPDX-License-Identifier: MIT
// PreviewMaker: rate-limited (message time), downscaled JPEG previews of camera frames.
#include "wingman/camera_driver/preview.hpp"

#include <wingman/common/config.hpp>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>

namespace wingman::camera_driver {

std::vector<std::string> PreviewOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (!(std::isfinite(rate_hz) && rate_hz > 0)) p.push_back(problem("preview.rate_hz", rate_hz, "must be > 0"));
  if (max_width < 16 || max_width > 4096) p.push_back(problem("preview.max_width", max_width, "must be in 16..4096"));
  if (jpeg_quality < 1 || jpeg_quality > 100)
    p.push_back(problem("preview.jpeg_quality", jpeg_quality, "must be in 1..100"));
  return p;
}

std::string PreviewOptions::channel_for(const std::string& image_channel) const {
  if (!channel.empty()) return channel;
  if (image_channel.rfind("IMAGE", 0) == 0) return "PREVIEW" + image_channel.substr(5);
  return "PREVIEW_" + image_channel;
}

PreviewMaker::PreviewMaker(PreviewOptions options)
    : o_(std::move(options)), period_us_(static_cast<int64_t>(std::llround(1e6 / o_.rate_hz))) {}

bool PreviewMaker::due(int64_t utime) {
  if (!o_.enabled) return false;
  if (last_utime_ && utime >= *last_utime_ && utime - *last_utime_ < period_us_) return false;
  return true;
}

std::optional<wingman::image_t> PreviewMaker::encode(const cv::Mat& bgr, int64_t utime, int64_t seq,
                                                     int32_t camera_id) {
  if (bgr.empty() || bgr.type() != CV_8UC3) {
    ++failures_;
    return std::nullopt;
  }
  cv::Mat small = bgr;
  if (bgr.cols > o_.max_width) {
    const int h = std::max(1, static_cast<int>(std::lround(static_cast<double>(bgr.rows) * o_.max_width / bgr.cols)));
    cv::resize(bgr, small, cv::Size(o_.max_width, h), 0, 0, cv::INTER_AREA);
  }
  std::vector<uint8_t> jpeg;
  if (!cv::imencode(".jpg", small, jpeg, {cv::IMWRITE_JPEG_QUALITY, o_.jpeg_quality})) {
    ++failures_;
    return std::nullopt;
  }
  wingman::image_t m{};
  m.utime = utime;
  m.seq = seq;
  m.camera_id = camera_id;
  m.width = small.cols;
  m.height = small.rows;
  m.stride = 0;
  m.pixel_format = wingman::image_t::MJPEG;
  m.size = static_cast<int32_t>(jpeg.size());
  m.data = std::move(jpeg);
  last_utime_ = utime;
  ++made_;
  return m;
}

std::optional<wingman::image_t> PreviewMaker::offer_bgr(const cv::Mat& bgr, int64_t utime, int64_t seq,
                                                        int32_t camera_id) {
  if (!due(utime)) return std::nullopt;
  return encode(bgr, utime, seq, camera_id);
}

std::optional<wingman::image_t> PreviewMaker::offer(const wingman::image_t& f) {
  if (!due(f.utime)) return std::nullopt;
  cv::Mat bgr;
  const auto bytes = const_cast<uint8_t*>(f.data.data());
  const size_t n = f.data.size();
  const bool rows_fit =
      f.width > 0 && f.height > 0 && f.stride > 0 && static_cast<size_t>(f.stride) * static_cast<size_t>(f.height) <= n;
  switch (f.pixel_format) {
    case wingman::image_t::MJPEG:
      // Decoded at a quarter or an eighth of its size when that is still wider than the preview: cheaper.
      if (n > 0) {
        const int flag = f.width >= 8 * o_.max_width   ? cv::IMREAD_REDUCED_COLOR_8
                         : f.width >= 4 * o_.max_width ? cv::IMREAD_REDUCED_COLOR_4
                         : f.width >= 2 * o_.max_width ? cv::IMREAD_REDUCED_COLOR_2
                                                       : cv::IMREAD_COLOR;
        bgr = cv::imdecode(cv::Mat(1, static_cast<int>(n), CV_8UC1, bytes), flag);
      }
      break;
    case wingman::image_t::BGR8:
      if (rows_fit && f.stride >= 3 * f.width) bgr = cv::Mat(f.height, f.width, CV_8UC3, bytes, f.stride);
      break;
    case wingman::image_t::GRAY8:
      if (rows_fit && f.stride >= f.width)
        cv::cvtColor(cv::Mat(f.height, f.width, CV_8UC1, bytes, f.stride), bgr, cv::COLOR_GRAY2BGR);
      break;
    case wingman::image_t::YUYV:
      if (rows_fit && f.width % 2 == 0 && f.stride >= 2 * f.width)
        cv::cvtColor(cv::Mat(f.height, f.width, CV_8UC2, bytes, f.stride), bgr, cv::COLOR_YUV2BGR_YUYV);
      break;
    default:
      break;
  }
  return encode(bgr, f.utime, f.seq, f.camera_id);
}

}  // namespace wingman::camera_driver
