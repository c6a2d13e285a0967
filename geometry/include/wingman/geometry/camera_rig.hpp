// SPDX-License-Identifier: MIT
// A camera rig: several cameras on one vehicle, each with its calibration, mount and bus channels, in one file that
// the simulator (which renders them), the localizer (which fuses them) and `wingman fly` (which starts a detector
// for each) read alike.
#pragma once

#include <wingman/geometry/camera_model_options.hpp>
#include <wingman/geometry/extrinsics.hpp>

#include <string>
#include <vector>

namespace wingman::geometry {

/// One camera of a rig file: the keys of a process's single camera (camera.*, extrinsics.*) and its channels.
struct RigCamera {
  /// camera.*: the calibration (a relative camera.calibration path is taken from the rig file's folder; read here
  /// as absolute) or the ideal pinhole, and camera.camera_id (unique in the rig).
  CameraModelOptions camera;
  /// extrinsics.*: the mount. Either extrinsics.R_cam_to_body, or mount.yaw_deg / mount.pitch_deg (the default
  /// forward-looking camera turned left by yaw about body z, then tilted up by pitch), never both.
  ExtrinsicsOptions extrinsics;
  std::string image_channel;       ///< channels.image: image_t channel ("" in the file = IMAGE_CAM<camera_id>)
  std::string detections_channel;  ///< channels.detections: detections_t ("" = DETECTIONS_CAM<camera_id>)
  std::string windows_channel;     ///< channels.windows: track_windows_t ("" = WINDOWS_CAM<camera_id>)
};

/// The cameras of a rig file, in file order (the order the localizer fuses one exposure's detections in).
struct CameraRig {
  static constexpr int kMaxCameras = 8;  ///< cameras a rig may have

  std::string source;              ///< the file it was read from
  std::vector<RigCamera> cameras;  ///< 1..kMaxCameras, camera_ids and channels unique

  /// The camera with `camera_id`, or nullptr.
  const RigCamera* find(int camera_id) const;
};

/// Reads a rig file:
/// @code
///   cameras:
///     - camera: {camera_id: 0, width: 1280, height: 720, focal_px: 640}   # or calibration: FILE
///       mount: {yaw_deg: 0}                                               # or extrinsics: {R_cam_to_body: [...]}
///       extrinsics: {p_cam_in_body: [0.1, 0, 0]}
///       channels: {image: IMAGE_CAM0, detections: DETECTIONS_CAM0, windows: WINDOWS_CAM0}   # optional
///     - ...
/// @endcode
/// Throws common::ConfigError listing every problem of the file at once, each as "<file>:<line>: cameras[i].<key>:
/// ..." (unreadable file, bad YAML, unknown key, a value a camera's validate() rejects, a duplicate camera_id or
/// channel, no cameras or more than kMaxCameras). Calibration files are checked to exist, not read.
CameraRig load_camera_rig(const std::string& path);

}  // namespace wingman::geometry
