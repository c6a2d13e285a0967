// SPDX-License-Identifier: MIT
// A monitoring preview of a camera: small JPEG frames at a low rate on a channel of their own, which lcm-spy shows
// (Java LCM drops full 1280x720 frames) and flight logs keep (recorders leave IMAGE_* out).
#pragma once

#include <wingman/image_t.hpp>

#include <opencv2/core/mat.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace wingman::camera_driver {

/// Keys `preview.*` of the camera driver's and the simulator's configuration.
struct PreviewOptions {
  /// Publish previews (default true): off the detector's path (the full frame is published first).
  bool enabled = true;
  /// LCM channel; "" = the image channel's name with its leading IMAGE replaced by PREVIEW (IMAGE_CAM0 ->
  /// PREVIEW_CAM0), or PREVIEW_ + the image channel when it does not start with IMAGE.
  std::string channel;
  /// At most this many previews per second of message time (image_t.utime, never the wall clock: a replay gives the
  /// same previews), > 0.
  double rate_hz = 1.0;
  /// Width of a preview, pixels (a frame narrower than this keeps its size; the aspect is kept), 16..4096.
  int max_width = 320;
  /// JPEG quality, 1..100.
  int jpeg_quality = 75;

  template <class V>
  void visit(V& v) {
    v("preview.enabled", enabled, "publish small JPEG previews for monitoring (lcm-spy, flight logs)");
    v("preview.channel", channel, "preview channel; \"\" = the image channel with IMAGE replaced by PREVIEW");
    v("preview.rate_hz", rate_hz, "previews per second of message time, at most");
    v("preview.max_width", max_width, "preview width, pixels (aspect kept; narrower frames keep their size)");
    v("preview.jpeg_quality", jpeg_quality, "JPEG quality of the previews, 1..100");
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
  /// The channel previews of `image_channel` go to (see `channel`).
  std::string channel_for(const std::string& image_channel) const;
};

/// Makes the previews of one camera's frames. Not thread-safe; one per camera.
class PreviewMaker {
 public:
  /// Precondition: options.validate() is empty.
  explicit PreviewMaker(PreviewOptions options);

  /// The preview of `frame` when one is due: the first frame, then the first frame at least 1 / rate_hz after the
  /// previous preview (message time; a frame dated earlier than the previous preview restarts the clock). An MJPEG,
  /// GRAY8, BGR8 or YUYV image_t, downscaled to max_width and JPEG-encoded (pixel_format MJPEG, stride 0),
  /// with the frame's utime, seq and camera_id. nullopt when none is due, when disabled, or when the frame's pixels
  /// cannot be read (counted in failures()).
  std::optional<wingman::image_t> offer(const wingman::image_t& frame);
  /// The same for a BGR frame already in memory (the simulator's render).
  std::optional<wingman::image_t> offer_bgr(const cv::Mat& bgr, int64_t utime, int64_t seq, int32_t camera_id);

  int64_t made() const { return made_; }
  int64_t failures() const { return failures_; }

 private:
  bool due(int64_t utime);
  std::optional<wingman::image_t> encode(const cv::Mat& bgr, int64_t utime, int64_t seq, int32_t camera_id);

  PreviewOptions o_;
  int64_t period_us_;
  std::optional<int64_t> last_utime_;
  int64_t made_ = 0;
  int64_t failures_ = 0;
};

}  // namespace wingman::camera_driver
