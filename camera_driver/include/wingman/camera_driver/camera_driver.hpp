// SPDX-License-Identifier: MIT
// CameraDriver: reads a FrameSource and turns its frames into wingman::image_t messages (no LCM I/O).
#pragma once

#include "wingman/camera_driver/camera_driver_options.hpp"
#include "wingman/camera_driver/clock.hpp"
#include "wingman/camera_driver/frame_source.hpp"
#include "wingman/camera_driver/v4l2_io.hpp"

#include <wingman/image_t.hpp>

#include <cstdint>
#include <memory>
#include <string>

namespace wingman::camera_driver {

/// What one CameraDriver::step() produced.
struct DriverStep {
  /// kFrame: `image` is ready to publish. kDropped also covers frames the driver could not convert.
  ReadStatus status = ReadStatus::kTimeout;
  /// The message to publish (status kFrame only).
  wingman::image_t image;
  /// Frames lost before or at this step (sequence gap, drop); report them as source drops.
  int64_t lost = 0;
  /// One line on a loss, drop or disconnection; "" otherwise.
  std::string reason;
  /// True on the first step after the camera came back.
  bool reconnected = false;
  /// Time spent converting the frame (MJPEG decode or encode, copy into the message), milliseconds.
  double convert_ms = 0.0;
};

/// Frame -> image_t. Raw frames keep their stride (padding included); MJPEG gets stride 0.
/// Precondition: check_frame(frame) is "".
wingman::image_t to_image_message(const Frame& frame, int32_t camera_id);
/// Same, moving the pixel data out of `frame` instead of copying it.
wingman::image_t to_image_message(Frame&& frame, int32_t camera_id);

/// Decodes an MJPEG frame into a BGR8 frame with the same utime and seq. Returns "" or one line on
/// why it does not decode (corrupt stream, or a size other than the frame says).
std::string decode_mjpeg(const Frame& jpeg, Frame& bgr);

/// JPEG-encodes a raw frame (GRAY8, BGR8, or YUYV converted to BGR first) with OpenCV at `quality` (1..100) into an
/// MJPEG frame (stride 0) with the same utime, seq and size: output.encoding mjpeg. Returns "" or one line on why it
/// could not. Precondition: check_frame(raw) is "" and raw.format is not MJPEG.
std::string encode_mjpeg(const Frame& raw, int quality, Frame& jpeg);

/// Downscales a raw frame to `max_width` pixels wide (cv::INTER_AREA, aspect kept, height at least 1): GRAY8 stays
/// GRAY8, BGR8 and YUYV become BGR8, rows unpadded; same utime and seq: output.max_width. Precondition:
/// check_frame(raw) is "", raw.format is not MJPEG and raw.width > max_width > 0.
void downscale_frame(const Frame& raw, int max_width, Frame& small);

/// Builds the source options.source_kind selects (not opened). `io` is used for v4l2 only.
/// Throws std::invalid_argument naming the key when the options are invalid.
std::unique_ptr<FrameSource> make_source(const CameraDriverOptions& options, std::shared_ptr<V4l2Io> io,
                                         std::shared_ptr<Clock> clock);

/// The logic of wingman-camera-driver without LCM: read a frame, check it, convert it, count it.
class CameraDriver {
 public:
  /// `source` must not be null; it is opened by open(). Throws std::invalid_argument with the first of
  /// options.validate()'s problems.
  CameraDriver(OutputOptions options, std::unique_ptr<FrameSource> source);

  /// Opens the source. Throws std::runtime_error naming the device or file.
  void open();
  /// Reads once, waiting at most about `timeout_ms` milliseconds. Never throws for a single bad frame
  /// (that is a kDropped step); throws std::runtime_error when the source cannot go on.
  DriverStep step(int timeout_ms);
  /// True when the source ended or output.max_frames frames were produced.
  bool done() const;

  const FrameSource& source() const { return *source_; }
  /// The source's line, and the stamps' shift when output.time_offset_s is not 0 ("..., stamps moved by -0.13 s
  /// (output.time_offset_s)").
  std::string describe() const;
  /// Frames converted for publishing.
  int64_t frames_out() const { return frames_out_; }
  /// Frames dropped by the driver itself (failed checks, MJPEG decode or encode), on top of the source's.
  int64_t driver_drops() const { return driver_drops_; }

 private:
  OutputOptions options_;
  std::unique_ptr<FrameSource> source_;
  Frame frame_;    // the source fills it; its data moves into the published message
  Frame decoded_;  // MJPEG decoded to BGR8 (output.decode_mjpeg)
  Frame scaled_;   // a raw frame downscaled (output.max_width)
  Frame encoded_;  // a raw frame JPEG-encoded (output.encoding mjpeg)
  int64_t frames_out_ = 0;
  int64_t driver_drops_ = 0;
  bool ended_ = false;
  int64_t time_offset_us_ = 0;  // output.time_offset_s, microseconds
};

}  // namespace wingman::camera_driver
