// SPDX-License-Identifier: MIT
// A video file or a folder of images played back as a camera, in real time or as fast as possible.
#pragma once

#include "wingman/camera_driver/clock.hpp"
#include "wingman/camera_driver/frame_source.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace wingman::camera_driver {

/// How to play a file.
struct FileSourceOptions {
  /// A video file (anything OpenCV's VideoCapture opens, e.g. an MJPG AVI), a folder of images
  /// (png, jpg, jpeg, bmp, pgm, ppm, pnm, tif, tiff; played in name order) or a single image.
  std::string path = "";
  /// realtime: frames paced at fps by the clock, utime = wall-clock schedule of the frame;
  /// fast: no waiting, utime = start_utime + i * 1e6 / fps (deterministic when start_utime is set).
  std::string mode = "realtime";
  /// Playback rate, frames per second; 0 = the video's own rate (30 for images or a video without one).
  double fps = 0.0;
  /// Start again at the end (seq and utime keep increasing); false: the source ends.
  bool loop = false;
  /// fast mode: utime of the first frame, microseconds since the Unix epoch; 0 = wall clock at open.
  int64_t start_utime = 0;
  /// Published layout: BGR8 or GRAY8.
  std::string pixel_format = "BGR8";

  /// One line per problem naming the key ("file.mode = 'slow': must be realtime or fast").
  /// `require_path`: whether an empty path is a problem (only when the file source is selected).
  std::vector<std::string> validate(bool require_path = true) const;
};

/// Plays a video file or an image folder behind the FrameSource interface.
///
/// - Frame::seq is the frame index since open(), counting every frame read (dropped ones too) and
///   continuing across loops, so a dropped frame shows as a seq gap downstream.
/// - A frame that does not decode (unreadable image, empty decoded frame) is a kDropped result,
///   counted in stats().dropped. A file that cannot be opened at all throws from open(), naming it.
/// - With loop, a whole pass without one decodable frame throws (instead of dropping forever).
/// - realtime mode: frame i is due at t0 + i / fps on the monotonic clock and stamped with the wall
///   clock schedule t0_wall + i / fps; read() waits through the Clock at most `timeout_ms`. When
///   decoding falls more than one frame period behind, the schedule restarts at the current time
///   (utime stays close to the wall clock; no frames are skipped).
class FileSource : public FrameSource {
 public:
  /// `clock` must not be null.
  FileSource(FileSourceOptions options, std::shared_ptr<Clock> clock);
  ~FileSource() override;
  FileSource(const FileSource&) = delete;
  FileSource& operator=(const FileSource&) = delete;

  /// Opens the file or lists the folder and decodes the first frame. Throws std::runtime_error naming
  /// the path when it does not exist, is not readable, holds no images or no frame decodes.
  void open() override;
  ReadResult read(Frame& out, int timeout_ms) override;
  std::string describe() const override;
  const SourceStats& stats() const override { return stats_; }

  /// Effective playback rate, frames per second (valid after open()).
  double fps() const { return fps_; }
  /// True when playing images (a folder or one image file) rather than a video.
  bool is_image_list() const;
  /// The images played, in order (empty for a video).
  const std::vector<std::string>& images() const;

 private:
  struct Impl;
  FileSourceOptions options_;
  std::shared_ptr<Clock> clock_;
  std::unique_ptr<Impl> impl_;
  double fps_ = 0.0;
  SourceStats stats_;
};

/// File extensions (lower case, with the dot) FileSource takes as images.
const std::vector<std::string>& image_extensions();

}  // namespace wingman::camera_driver
