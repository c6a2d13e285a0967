// SPDX-License-Identifier: MIT
// Pixel-format conversion, Algorithm 2 geometry and network-input packing.
#include "wingman/detector/preprocess.hpp"

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace wingman::detector {

namespace {
cv::Mat fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return {};
}

/// The frame size in a JPEG's first SOF marker, without decoding it; false when the markers before it are not
/// well formed. cv::imdecode would allocate whatever size the header claims (a 300-byte JPEG can claim
/// 65535 x 65535 pixels), so the claim is checked against image_t's width and height first.
bool jpeg_frame_size(const uint8_t* d, size_t n, int* width, int* height) {
  if (n < 4 || d[0] != 0xFF || d[1] != 0xD8) return false;
  size_t pos = 2;
  while (pos + 4 <= n) {
    if (d[pos] != 0xFF) return false;
    const uint8_t marker = d[pos + 1];
    if (marker == 0xFF) {  // fill byte
      ++pos;
      continue;
    }
    if (marker == 0xD8 || marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) {  // no length
      pos += 2;
      continue;
    }
    if (marker == 0xD9 || marker == 0xDA) return false;  // end of image or scan data before any frame header
    const size_t length = (static_cast<size_t>(d[pos + 2]) << 8) | d[pos + 3];
    if (length < 2 || pos + 2 + length > n) return false;
    const bool sof = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (sof) {
      if (length < 7) return false;
      *height = (d[pos + 5] << 8) | d[pos + 6];
      *width = (d[pos + 7] << 8) | d[pos + 8];
      return true;
    }
    pos += 2 + length;
  }
  return false;
}
}  // namespace

cv::Mat image_to_bgr(const wingman::image_t& image, std::string* error) {
  if (error) error->clear();
  if (image.width < 1) return fail(error, fmt::format("image_t.width = {}: must be >= 1", image.width));
  if (image.height < 1) return fail(error, fmt::format("image_t.height = {}: must be >= 1", image.height));
  if (image.size < 0 || static_cast<size_t>(image.size) != image.data.size())
    return fail(error,
                fmt::format("image_t.size = {}: must equal the {} bytes of data", image.size, image.data.size()));
  int bpp = 0;
  switch (image.pixel_format) {
    case wingman::image_t::GRAY8:
      bpp = 1;
      break;
    case wingman::image_t::BGR8:
      bpp = 3;
      break;
    case wingman::image_t::YUYV:
      bpp = 2;
      if (image.width % 2 != 0)
        return fail(error, fmt::format("image_t.width = {}: must be even for YUYV", image.width));
      break;
    case wingman::image_t::MJPEG: {
      if (image.stride != 0) return fail(error, fmt::format("image_t.stride = {}: must be 0 for MJPEG", image.stride));
      if (image.data.empty()) return fail(error, "image_t.size = 0: an MJPEG frame needs data");
      int jpeg_width = 0;
      int jpeg_height = 0;
      if (!jpeg_frame_size(image.data.data(), image.data.size(), &jpeg_width, &jpeg_height))
        return fail(error, fmt::format("image_t.data ({} bytes): not a JPEG (no frame header)", image.size));
      if (jpeg_width != image.width || jpeg_height != image.height)
        return fail(error, fmt::format("image_t.width x height = {}x{}: the JPEG header says {}x{}", image.width,
                                       image.height, jpeg_width, jpeg_height));
      const cv::Mat encoded(1, image.size, CV_8UC1, const_cast<uint8_t*>(image.data.data()));
      cv::Mat bgr = cv::imdecode(encoded, cv::IMREAD_COLOR);
      if (bgr.empty()) return fail(error, fmt::format("image_t.data ({} bytes): not a decodable JPEG", image.size));
      if (bgr.cols != image.width || bgr.rows != image.height)
        return fail(error, fmt::format("image_t.width x height = {}x{}: the JPEG decodes to {}x{}", image.width,
                                       image.height, bgr.cols, bgr.rows));
      return bgr;
    }
    default:
      return fail(error, fmt::format("image_t.pixel_format = {}: must be GRAY8 (1), BGR8 (2), YUYV (3) or MJPEG (4)",
                                     static_cast<int>(image.pixel_format)));
  }
  const int64_t min_stride = static_cast<int64_t>(image.width) * bpp;
  if (image.stride < min_stride)
    return fail(error,
                fmt::format("image_t.stride = {}: must be >= width x bytes per pixel = {}", image.stride, min_stride));
  const int64_t needed = static_cast<int64_t>(image.height) * image.stride;
  if (image.size < needed)
    return fail(error, fmt::format("image_t.size = {}: must be >= height x stride = {}", image.size, needed));
  uint8_t* data = const_cast<uint8_t*>(image.data.data());
  cv::Mat bgr;
  switch (image.pixel_format) {
    case wingman::image_t::GRAY8:
      cv::cvtColor(cv::Mat(image.height, image.width, CV_8UC1, data, image.stride), bgr, cv::COLOR_GRAY2BGR);
      break;
    case wingman::image_t::BGR8:
      bgr = cv::Mat(image.height, image.width, CV_8UC3, data, image.stride).clone();
      break;
    default:  // YUYV
      cv::cvtColor(cv::Mat(image.height, image.width, CV_8UC2, data, image.stride), bgr, cv::COLOR_YUV2BGR_YUYV);
      break;
  }
  return bgr;
}

cv::Rect detection_region(cv::Size image, bool subsquare) {
  if (!subsquare) return {0, 0, image.width, image.height};
  const int side = std::min(image.width, image.height);
  return {(image.width - side) / 2, (image.height - side) / 2, side, side};
}

cv::Rect zoom_crop(cv::Size image, cv::Size net, float cx, float cy) {
  const int w = std::min(net.width, image.width);
  const int h = std::min(net.height, image.height);
  int x = static_cast<int>(std::lround(cx - w / 2.0f));
  int y = static_cast<int>(std::lround(cy - h / 2.0f));
  x = std::clamp(x, 0, image.width - w);
  y = std::clamp(y, 0, image.height - h);
  return {x, y, w, h};
}

Box network_to_image(const Box& box_in_net, const cv::Rect& roi, cv::Size net) {
  const float sx = static_cast<float>(roi.width) / static_cast<float>(net.width);
  const float sy = static_cast<float>(roi.height) / static_cast<float>(net.height);
  Box b = box_in_net;
  b.cx = static_cast<float>(roi.x) + box_in_net.cx * sx;
  b.cy = static_cast<float>(roi.y) + box_in_net.cy * sy;
  b.w = box_in_net.w * sx;
  b.h = box_in_net.h * sy;
  return b;
}

void to_network_input(const cv::Mat& bgr, const cv::Rect& roi, cv::Size net, cv::Mat& resized, float* chw) {
  const cv::Mat region = bgr(roi);
  if (region.size() == net)
    region.copyTo(resized);
  else
    cv::resize(region, resized, net, 0.0, 0.0, cv::INTER_LINEAR);
  const size_t plane = static_cast<size_t>(net.area());
  float* r = chw;
  float* g = chw + plane;
  float* b = chw + 2 * plane;
  constexpr float kScale = 1.0f / 255.0f;
  for (int y = 0; y < net.height; ++y) {
    const uint8_t* p = resized.ptr<uint8_t>(y);
    const size_t row = static_cast<size_t>(y) * net.width;
    for (int x = 0; x < net.width; ++x) {
      b[row + x] = p[3 * x] * kScale;
      g[row + x] = p[3 * x + 1] * kScale;
      r[row + x] = p[3 * x + 2] * kScale;
    }
  }
}

}  // namespace wingman::detector
