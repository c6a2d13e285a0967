// SPDX-License-Identifier: MIT
// Options of wingman-localizer (config/localizer.yaml).
#pragma once

#include <wingman/geometry/camera_model_options.hpp>
#include <wingman/geometry/extrinsics.hpp>
#include "wingman/localizer/pose_buffer.hpp"
#include "wingman/localizer/sphere_localizer.hpp"
#include "wingman/localizer/track_windows.hpp"
#include "wingman/localizer/tracker.hpp"

#include <wingman/common/time_sanity.hpp>

#include <string>
#include <vector>

namespace wingman::localizer {

/// The camera the detections come from: the camera.* keys every camera-building process shares
/// (geometry::CameraModelOptions; camera.camera_id is the one camera this localizer accepts) and the localizer's own.
struct CameraOptions : geometry::CameraModelOptions {
  /// Rescale the calibration to the detections' image size when they differ (intrinsics scaled
  /// by the width and height ratios). Off: a size mismatch drops the message, naming both sizes.
  bool scale_to_image = false;

  template <class V>
  void visit(V& v) {
    geometry::CameraModelOptions::visit(v);
    v("camera.scale_to_image", scale_to_image,
      "rescale intrinsics to the detections' image size (false: a size mismatch is an error)");
  }
  // validate(): the shared keys' (scale_to_image has no rule).
};

/// Several cameras on one vehicle (keys `cameras.*`; docs/localization.md, "Several cameras").
struct CameraRigOptions {
  /// A camera rig file (geometry::load_camera_rig(), geometry/include/wingman/geometry/camera_rig.hpp); "" = the one
  /// camera of camera.*. With a rig its cameras replace camera.* (except camera.scale_to_image, applied to every
  /// camera), extrinsics.*, input.detections_channel and windows.channel: each camera has its own calibration, mount
  /// and channels, and the detections of one exposure (one utime) from all cameras are fused into one tracker frame.
  std::string rig;
  /// A rig camera that has sent no detections_t for this long of message time (behind the newest of any rig camera) is
  /// silent: exposures are not held back waiting for it until it sends again. Seconds, finite, > 0.
  double silent_after_s = 0.2;
  /// Exposures held waiting for cameras at most; beyond it the oldest is processed without the cameras still
  /// missing (counted). >= 1.
  int max_pending = 8;

  template <class V>
  void visit(V& v) {
    v("cameras.rig", rig,
      "camera rig file (several cameras, geometry/include/wingman/geometry/camera_rig.hpp); \"\" = the one camera of "
      "camera.*. A rig replaces camera.* (camera.scale_to_image applies to every rig camera), extrinsics.*, "
      "input.detections_channel and windows.channel with each camera's own");
    v("cameras.silent_after_s", silent_after_s,
      "rig: a camera without detections for this long of message time is not waited for until it sends again, s");
    v("cameras.max_pending", max_pending,
      "rig: exposures held waiting for cameras at most; beyond it the oldest is processed without the missing ones");
  }
  /// One "key = value: rule" line per problem; empty when valid. Reads the rig file: every problem load_camera_rig()
  /// finds, named by cameras.rig.
  std::vector<std::string> validate() const;
};

/// Options of the localizer process.
struct LocalizerOptions {
  std::string detections_channel = "DETECTIONS_CAM0";  ///< detections_t input channel
  std::string own_pose_channel = "OWN_POSE";           ///< own_pose_t input channel
  std::string output_channel = "TARGETS";              ///< targets_t output channel
  /// Publish camera-frame-only targets (world_valid = false) when no own pose is fresh enough.
  bool publish_camera_frame_only = true;
  /// Publish a targets_t with no targets for detections that leave no confirmed track (subscribers see the
  /// pipeline is alive, and lockstep simulation gets one targets_t per image).
  bool publish_empty = true;
  /// Where a multi-class model's class is decided (detection_t.class_id, drone_score):
  /// "box" (default): a box whose class is not drone is left out before tracking (counted, not tracked);
  /// "track": every box is localized and tracked with its drone score (objectness x P(drone)) as its confidence, so
  /// the tracker's confirmation bar (tracker.confirm_min_confidence, on the mean of a track's last N hits) decides
  /// drone or not over the track's frames: a distant drone that one frame calls a bird still gathers its evidence.
  /// For a single-class model (drone_score = confidence) the two are the same.
  std::string class_decision = "box";
  CameraOptions camera;
  SphereLocalizerOptions sphere;
  geometry::ExtrinsicsOptions extrinsics;
  PoseBufferOptions pose;
  TrackerOptions tracker;
  TrackWindowOptions windows;  ///< tracker-driven windows (windows.*)
  CameraRigOptions cameras;    ///< several cameras (cameras.*); "" rig: camera.* and extrinsics.*
  /// Time sanity of the inputs (time.*): how far ahead of the newest accepted time a message may be dated, and when
  /// the clock re-anchors (common/time_sanity.hpp).
  common::TimeSanityOptions time;

  template <class V>
  void visit(V& v) {
    v("input.detections_channel", detections_channel, "detections_t channel from wingman-detector");
    v("input.own_pose_channel", own_pose_channel, "own_pose_t channel with the camera vehicle's pose");
    v("output.channel", output_channel, "targets_t channel to publish tracked targets on");
    v("output.publish_camera_frame_only", publish_camera_frame_only,
      "without a fresh own pose, publish camera-frame targets (world_valid false) instead of nothing");
    v("output.publish_empty", publish_empty,
      "publish an empty targets_t when detections leave no confirmed track (one targets_t per detections_t)");
    v("classes.decision", class_decision,
      "box: boxes of other classes than drone are not tracked; track: every box is tracked with its drone score as "
      "its confidence and the tracker's confirmation bar decides per track");
    cameras.visit(v);
    camera.visit(v);
    sphere.visit(v);
    extrinsics.visit(v);
    pose.visit(v);
    tracker.visit(v);
    windows.visit(v);
    time.visit(v);
  }
  std::vector<std::string> validate() const;
};

}  // namespace wingman::localizer
