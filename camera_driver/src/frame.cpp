// SPDX-License-Identifier: MIT
// Frame helpers: format names, bytes per pixel, invariant checks.
#include "wingman/camera_driver/frame.hpp"

namespace wingman::camera_driver {

std::string pixel_format_name(PixelFormat format) {
  switch (format) {
    case PixelFormat::kGray8:
      return "GRAY8";
    case PixelFormat::kBgr8:
      return "BGR8";
    case PixelFormat::kYuyv:
      return "YUYV";
    case PixelFormat::kMjpeg:
      return "MJPEG";
  }
  return "unknown(" + std::to_string(static_cast<int>(format)) + ")";
}

int bytes_per_pixel(PixelFormat format) {
  switch (format) {
    case PixelFormat::kGray8:
      return 1;
    case PixelFormat::kBgr8:
      return 3;
    case PixelFormat::kYuyv:
      return 2;
    case PixelFormat::kMjpeg:
      return 0;
  }
  return 0;
}

std::string check_frame(const Frame& frame) {
  if (frame.width <= 0 || frame.height <= 0) {
    return "frame " + std::to_string(frame.seq) + ": zero size " + std::to_string(frame.width) + "x" +
           std::to_string(frame.height);
  }
  if (frame.format == PixelFormat::kMjpeg) {
    if (frame.stride != 0) return "frame " + std::to_string(frame.seq) + ": MJPEG stride must be 0";
    if (frame.data.empty()) return "frame " + std::to_string(frame.seq) + ": empty JPEG stream";
    return "";
  }
  const int bpp = bytes_per_pixel(frame.format);
  if (bpp == 0) return "frame " + std::to_string(frame.seq) + ": unknown pixel format";
  if (frame.format == PixelFormat::kYuyv && frame.width % 2 != 0) {
    return "frame " + std::to_string(frame.seq) + ": YUYV width " + std::to_string(frame.width) + " is odd";
  }
  if (frame.stride < frame.width * bpp) {
    return "frame " + std::to_string(frame.seq) + ": stride " + std::to_string(frame.stride) + " < width * " +
           std::to_string(bpp);
  }
  const size_t expected = static_cast<size_t>(frame.stride) * static_cast<size_t>(frame.height);
  if (frame.data.size() != expected) {
    return "frame " + std::to_string(frame.seq) + ": " + std::to_string(frame.data.size()) +
           " bytes, expected stride * height = " + std::to_string(expected);
  }
  return "";
}

}  // namespace wingman::camera_driver
