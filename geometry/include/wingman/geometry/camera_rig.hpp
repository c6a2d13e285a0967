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
  /// forward-looking camera turned left by yaw about body z, then tilted up by pitch), never both; or, for a camera
  /// calibrated by the rig's camchain, R_cam_to_body and p_cam_in_body composed from the chain.
  ExtrinsicsOptions extrinsics;
  std::string image_channel;       ///< channels.image: image_t channel ("" in the file = IMAGE_CAM<camera_id>)
  std::string detections_channel;  ///< channels.detections: detections_t ("" = DETECTIONS_CAM<camera_id>)
  std::string windows_channel;     ///< channels.windows: track_windows_t ("" = WINDOWS_CAM<camera_id>)
};

/// The cameras of a rig file, in file order (the order the localizer fuses one exposure's detections in).
struct CameraRig {
  static constexpr int kMaxCameras = 8;  ///< cameras a rig may have

  std::string source;              ///< the file it was read from
  std::string camchain;            ///< camchain.file, read as absolute ("" = the rig has no camchain)
  std::vector<RigCamera> cameras;  ///< 1..kMaxCameras, camera_ids and channels unique

  /// The camera with `camera_id`, or nullptr.
  const RigCamera* find(int camera_id) const;
};

/// Reads a rig file (docs/camera_rigs.md):
/// @code
///   cameras:
///     - camera: {camera_id: 0, width: 1280, height: 720, focal_px: 640}   # or calibration: FILE
///       mount: {yaw_deg: 0}                                               # or extrinsics: {R_cam_to_body: [...]}
///       extrinsics: {p_cam_in_body: [0.1, 0, 0]}
///       channels: {image: IMAGE_CAM0, detections: DETECTIONS_CAM0, windows: WINDOWS_CAM0}   # optional
///     - ...
/// @endcode
/// or with the mounts from a Kalibr camchain: every camera whose camera.calibration is camchain.file (the same file)
/// takes R_cam_to_body and p_cam_in_body from it (and gives no mount.* or extrinsics.* of its own):
/// @code
///   camchain:
///     file: camchain-imucam.yaml      # relative to the rig file's folder
///     # camchain-imucam (T_cam_imu in every entry): the IMU on the body (defaults: identity, zero)
///     R_imu_to_body: [1, 0, 0, 0, 1, 0, 0, 0, 1]
///     p_imu_in_body: [0, 0, 0]
///     # or a camera-only camchain (T_cn_cnm1): the first entry's (cam0's) mount, as a rig camera's
///     # mount: {yaw_deg: 0, pitch_deg: 0}   extrinsics: {p_cam_in_body: [...]}  (or extrinsics.R_cam_to_body)
///   cameras:
///     - camera: {camera_id: 0, calibration: camchain-imucam.yaml, kalibr_camera: cam0}
///     - ...
/// @endcode
/// Frames: Kalibr's camera frame is the optical frame of extrinsics.hpp (x right, y down, z forward); T_cam_imu maps
/// IMU points into the camera (p_cam = T_cam_imu p_imu), T_cn_cnm1 points of the entry before (in file order; cam0,
/// cam1, ... in Kalibr's files) into entry n's. So R_cam_to_body, p_cam_in_body are those of T_body_imu T_cam_imu^-1
/// or T_body_cam0 T_c1_c0^-1 ... T_cn_cnm1^-1. Each rotation read must be orthonormal within 1e-6 with determinant
/// +1 and is then projected onto the nearest rotation; each last row must be exactly [0, 0, 0, 1].
///
/// Throws common::ConfigError listing every problem of the file at once, each as "<file>:<line>: cameras[i].<key>:
/// ..." (unreadable file, bad YAML, unknown key, a value a camera's validate() rejects, a duplicate camera_id or
/// channel, no cameras or more than kMaxCameras, camera.kalibr_camera without camera.calibration) and, with a
/// camchain, "<chain file>:<line>: <entry>.<key>: ..." for the chain's own (a missing file or entry, a missing
/// T_cam_imu or T_cn_cnm1, a transform that is not 4x4, finite and rigid, a key Kalibr does not write) and
/// "cameras[i].mount.yaw_deg: ..." for a chain camera that also gives its own mount. Calibration files are checked to
/// exist, not read for intrinsics (make_camera() reads them).
CameraRig load_camera_rig(const std::string& path);

}  // namespace wingman::geometry
