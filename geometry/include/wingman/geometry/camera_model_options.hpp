// SPDX-License-Identifier: MIT
// The camera.* keys from which a process builds its camera (make_camera()): wingman-localizer's and wingman-sim's.
#pragma once

#include <string>
#include <vector>

namespace wingman::geometry {

/// One camera as a process's config names it: a calibration file or an ideal pinhole, and the camera's id on the bus.
/// wingman-localizer and wingman-sim read the same keys into it with the same defaults, so the pipeline works on
/// embedded defaults; each adds its own keys (the localizer camera.scale_to_image, the simulator camera.rate_hz).
/// make_camera() (calibration.hpp) turns it into a CameraModel.
struct CameraModelOptions {
  /// The largest image side validate() accepts by default, pixels.
  static constexpr int kMaxSidePx = 16384;

  /// Calibration file (ROS camera_info, OpenCV FileStorage or Kalibr camchain YAML); "" = an ideal pinhole camera
  /// from width, height and focal_px below (principal point at the image centre).
  std::string calibration;
  std::string kalibr_camera = "cam0";  ///< camera of a Kalibr camchain file; not empty
  /// The camera's id on the bus (image_t, detections_t and truth_box_t camera_id), >= 0. A process that takes
  /// detections (the localizer) accepts only this camera's and drops and counts the others; one that produces images
  /// (the simulator) publishes its images, detections and truth boxes with it.
  int camera_id = 0;
  int width = 1280;         ///< ideal pinhole: image width, pixels, 1..kMaxSidePx
  int height = 720;         ///< ideal pinhole: image height, pixels, 1..kMaxSidePx
  double focal_px = 640.0;  ///< ideal pinhole: fx = fy, pixels, finite and > 0

  template <class V>
  void visit(V& v) {
    v("camera.calibration", calibration,
      "calibration YAML (ROS camera_info, OpenCV, Kalibr); \"\" = ideal pinhole below");
    v("camera.kalibr_camera", kalibr_camera, "which camera of a Kalibr camchain file");
    v("camera.camera_id", camera_id,
      "which camera this is: camera_id of its images, detections and truth boxes (a reader drops and counts other "
      "cameras' messages)");
    v("camera.width", width, "ideal pinhole only: image width, pixels");
    v("camera.height", height, "ideal pinhole only: image height, pixels");
    v("camera.focal_px", focal_px, "ideal pinhole only: focal length fx = fy, pixels");
  }
  /// One "camera.<key> = value: rule" line per problem; empty when valid. `max_width_px` and `max_height_px` bound
  /// camera.width and camera.height (a process whose images must fit a smaller limit passes it).
  std::vector<std::string> validate(int max_width_px = kMaxSidePx, int max_height_px = kMaxSidePx) const;
};

}  // namespace wingman::geometry
