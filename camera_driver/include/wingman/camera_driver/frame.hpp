// SPDX-License-Identifier: MIT
// One captured frame as a source hands it over: pixels, size, layout and exposure time.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace wingman::camera_driver {

/// Pixel layout of a Frame. Values equal the wingman::image_t pixel_format constants.
enum class PixelFormat : int8_t {
  kGray8 = 1,  ///< 1 byte per pixel
  kBgr8 = 2,   ///< 3 bytes per pixel: B, G, R
  kYuyv = 3,   ///< 4 bytes per 2 pixels (Y0 U Y1 V); width is even
  kMjpeg = 4,  ///< one undecoded JPEG image; stride is 0
};

/// "GRAY8", "BGR8", "YUYV", "MJPEG" or "unknown(N)".
std::string pixel_format_name(PixelFormat format);

/// Bytes per pixel of a raw format (GRAY8 1, BGR8 3, YUYV 2); 0 for MJPEG.
int bytes_per_pixel(PixelFormat format);

/// One frame.
///
/// Invariants for raw formats (GRAY8, BGR8, YUYV): stride >= width * bytes_per_pixel(format) and
/// data.size() == stride * height; bytes past width * bytes_per_pixel in a row are padding.
/// For MJPEG: stride == 0 and data holds the whole JPEG stream.
struct Frame {
  int64_t utime = 0;  ///< exposure time, microseconds since the Unix epoch (CLOCK_REALTIME domain)
  int64_t seq = 0;    ///< sequence number from the source; a gap means frames were lost
  int width = 0;      ///< pixels
  int height = 0;     ///< pixels
  int stride = 0;     ///< bytes per row including padding; 0 for MJPEG
  PixelFormat format = PixelFormat::kGray8;
  std::vector<uint8_t> data;  ///< rows (height * stride bytes) or the JPEG stream
};

/// "" when `frame` keeps the invariants above, else one line naming the broken one.
std::string check_frame(const Frame& frame);

}  // namespace wingman::camera_driver
