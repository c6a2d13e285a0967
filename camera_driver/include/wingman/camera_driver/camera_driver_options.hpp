// SPDX-License-Identifier: MIT
// Configuration of wingman-camera-driver: which source, how to capture or play it, where to publish.
#pragma once

#include "wingman/camera_driver/file_source.hpp"
#include "wingman/camera_driver/preview.hpp"
#include "wingman/camera_driver/v4l2_source.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace wingman::camera_driver {

/// What CameraDriver publishes.
struct OutputOptions {
  /// LCM channel of the image_t messages.
  std::string channel = "IMAGE_CAM0";
  /// image_t.camera_id: which camera on the vehicle (0..n-1).
  int camera_id = 0;
  /// true: decode MJPEG frames and publish BGR8; false: publish the JPEG stream undecoded (MJPEG).
  bool decode_mjpeg = false;
  /// Pixels on the bus: "raw" publishes frames as the source gives them (GRAY8, BGR8 or YUYV uncompressed; a V4L2
  /// MJPEG camera's stream undecoded unless decode_mjpeg); "mjpeg" JPEG-encodes raw frames with OpenCV at
  /// jpeg_quality (image_t pixel_format MJPEG, stride 0; the detector decodes it), while a V4L2 MJPEG camera's
  /// stream passes through as captured, never decoded and re-encoded. Four 1280x720 cameras on one bus need mjpeg
  /// (docs/reliability.md, "Load and soak").
  std::string encoding = "raw";
  /// JPEG quality of output.encoding mjpeg, 1..100 (OpenCV's IMWRITE_JPEG_QUALITY).
  int jpeg_quality = 90;
  /// Raw frames wider than this are downscaled to it before publishing (cv::INTER_AREA, aspect kept; YUYV becomes
  /// BGR8), pixels; 0 = as captured. A V4L2 MJPEG camera's stream is not downscaled unless decode_mjpeg. Consumers
  /// with a calibration of the full size need it scaled (the localizer's camera.scale_to_image).
  int max_width = 0;
  /// Stop after publishing this many frames (exit 0); 0 = no limit.
  int64_t max_frames = 0;
  /// Added to every frame's timestamp before it is published, seconds: from the source's stamp to the exposure the
  /// localizer should pair with the own pose (the middle of the exposure, in the own pose's clock). Negative when the
  /// source stamps late: a V4L2 driver stamping the end of the frame or its arrival (USB transfer, readout), a
  /// camera with a measured lag (the thesis's: 0.13 s). A Kalibr camera-IMU calibration's timeshift_cam_imu
  /// (t_imu = t_cam + shift) where the own pose runs on that IMU's clock. 0 = stamps as the source gives them.
  /// Finite, |offset| <= 1 s.
  double time_offset_s = 0.0;

  /// One line per problem naming the key; empty when valid.
  std::vector<std::string> validate() const;
};

/// Everything config/camera_driver.yaml holds (one key per field; see visit()).
struct CameraDriverOptions {
  /// Frame source: v4l2 (a camera) or file (a video file or an image folder).
  std::string source_kind = "v4l2";
  /// V4L2 capture settings (section v4l2), used when source_kind is v4l2.
  V4l2SourceOptions v4l2;
  /// File playback settings (section file), used when source_kind is file.
  FileSourceOptions file;
  /// Publishing settings (section output).
  OutputOptions output;
  /// The monitoring preview (section preview): small JPEG frames at 1 Hz on PREVIEW_CAM0 by default.
  PreviewOptions preview;

  template <class V>
  void visit(V& v) {
    v("source.kind", source_kind, "frame source: v4l2 (a camera) or file (a video file or an image folder)");
    v("v4l2.device", v4l2.device, "device node, e.g. /dev/video0 or a stable /dev/v4l/by-id/... link");
    v("v4l2.pixel_format", v4l2.pixel_format, "pixel format to request: YUYV or MJPEG");
    v("v4l2.width", v4l2.width, "requested width, pixels (the driver may round it; the rounded size is used)");
    v("v4l2.height", v4l2.height, "requested height, pixels (the driver may round it; the rounded size is used)");
    v("v4l2.fps", v4l2.fps, "requested frame rate, frames per second; 0 = keep the driver's rate");
    v("v4l2.buffers", v4l2.buffers, "number of mmap capture buffers to request, 2..32");
    v("v4l2.reconnect_initial_s", v4l2.reconnect_initial_s,
      "first wait before reopening an unplugged camera, seconds; doubles after each failed attempt");
    v("v4l2.reconnect_max_s", v4l2.reconnect_max_s, "longest wait between reopening attempts, seconds");
    v("v4l2.stall_timeout_s", v4l2.stall_timeout_s,
      "no frame for this long while streaming counts as an unplug (reopen), seconds; 0 = never");
    v("v4l2.wait_for_device", v4l2.wait_for_device,
      "a device missing or failing at start is retried like an unplug (heartbeat ERROR says why); false: exit 1");
    v("file.path", file.path, "video file, image folder (played in name order) or single image; required for file");
    v("file.mode", file.mode,
      "realtime (paced at fps, utime = wall clock) or fast (no waiting, utime = start_utime + i / fps)");
    v("file.fps", file.fps, "playback rate, frames per second; 0 = the video's own rate (30 for images)");
    v("file.loop", file.loop, "start again at the end (seq and utime keep increasing); false = exit at the end");
    v("file.start_utime", file.start_utime,
      "fast mode: utime of the first frame, microseconds since the epoch; 0 = wall clock at start");
    v("file.pixel_format", file.pixel_format, "published layout for files: BGR8 or GRAY8");
    v("output.channel", output.channel, "LCM channel of the image_t messages");
    v("output.camera_id", output.camera_id, "image_t.camera_id: which camera on the vehicle (0..n-1)");
    v("output.decode_mjpeg", output.decode_mjpeg,
      "decode MJPEG frames and publish BGR8 (true) or publish them undecoded (false)");
    v("output.encoding", output.encoding,
      "pixels on the bus: raw (as the source gives them) or mjpeg (raw frames JPEG-encoded; MJPEG cameras pass "
      "through)");
    v("output.jpeg_quality", output.jpeg_quality, "JPEG quality of output.encoding mjpeg, 1..100");
    v("output.max_width", output.max_width,
      "raw frames wider than this are downscaled to it (aspect kept; YUYV becomes BGR8), pixels; 0 = as captured");
    v("output.max_frames", output.max_frames, "exit 0 after publishing this many frames; 0 = no limit");
    v("output.time_offset_s", output.time_offset_s,
      "added to every frame's timestamp: source stamp -> middle of the exposure in the own pose's clock, s "
      "(negative for late stamps; Kalibr's timeshift_cam_imu); 0 = as stamped");
    preview.visit(v);
  }

  /// Every problem, each naming its key; empty when valid. Both source sections are checked (so a
  /// typo shows before the source is switched), but file.path is required only for source.kind file.
  std::vector<std::string> validate() const;
};

}  // namespace wingman::camera_driver
