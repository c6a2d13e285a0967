// SPDX-License-Identifier: MIT
// PreviewMaker: rate-limited (message time), downscaled JPEG previews of camera frames.
#include "wingman/camera_driver/preview.hpp"

#include <wingman/common/config.hpp>
#include <wingman/detector/preprocess.hpp>

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
  // The detector's conversion (every pixel format, each field checked): an impossible frame gives an empty Mat.
  return encode(detector::image_to_bgr(f, nullptr), f.utime, f.seq, f.camera_id);
}

}  // namespace wingman::camera_driver
