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
