// SPDX-License-Identifier: MIT
// The localizer's logic without LCM: detections and own poses in, targets out.
#pragma once

#include <wingman/geometry/camera_model.hpp>
#include <wingman/geometry/extrinsics.hpp>
#include "wingman/localizer/box_relation.hpp"
#include "wingman/localizer/localizer_options.hpp"
#include "wingman/localizer/pose_buffer.hpp"
#include "wingman/localizer/tracker.hpp"

#include <wingman/common/time_sanity.hpp>
#include <wingman/detections_t.hpp>
#include <wingman/own_pose_t.hpp>
#include <wingman/targets_t.hpp>
#include <wingman/track_windows_t.hpp>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace wingman::localizer {

/// Boxes the localizer does not track because they are not drones (detection_t.class_id != 0: the airplanes, birds
/// and helicopters of a multi-class model). They are expected input, not errors: not drops.
struct NonDroneCounts {
  int64_t total = 0;                ///< boxes with class_id != 0
  std::map<int, int64_t> by_class;  ///< class_id -> boxes, for the classes seen
  bool tracked = false;             ///< classes.decision: track (they were tracked by their drone score)

  /// "" when total is 0, else one line for the status detail, e.g.
  /// "non-drone boxes not tracked: 12 (airplane 3, bird 9)" (names: common::detection_class_name()), or with
  /// `tracked` "non-drone boxes tracked by their drone score: 12 (...)".
  std::string summary() const;
};

/// What one detections message gave.
struct LocalizerOutput {
  /// Targets to publish; nullopt when there is nothing to publish (no confirmed track and output.publish_empty
  /// off, or no fresh own pose and output.publish_camera_frame_only off).
  std::optional<wingman::targets_t> targets;
  /// One line per box that could not be used and per missing own pose, naming the field and why;
  /// the process counts each as a drop.
  std::vector<std::string> rejections;
  bool camera_frame_only = false;  ///< no own pose fresh enough at the image's exposure time
  /// The message's boxes with class_id != 0, left out before localization (not rejections).
  NonDroneCounts non_drone;
  /// With windows.publish and a fresh own pose: where every track will be in this camera's next image (published
  /// before the targets, so that in lockstep the detector has them before the next frame). Empty windows are
  /// published too (the detector then knows its tracks are gone).
  std::optional<wingman::track_windows_t> windows;
};

/// Turns detections into tracked targets (Algorithm: eq. 24 / tangent planes per box, then the
/// frames, then the tracker). Uses message utimes only: the same inputs give the same outputs.
class Localizer {
 public:
  /// `camera` must match the detections' image size (checked per message). options.time: the time sanity of the two
  /// inputs (common::StageClock): an own pose or detections_t dated more than time.max_ahead_s after the newest
  /// message time accepted is dropped; when one input's messages have all been refused for time.resync_after_s of
  /// their own time (a bad first message latched the order), the clock re-anchors on them: an own-pose resync
  /// empties the pose buffer, a detections resync restarts the tracker (new tracks, as after a restart).
  /// Throws std::invalid_argument for invalid options.
  Localizer(const LocalizerOptions& options, geometry::CameraModel camera);

  /// Adds an own pose. Throws std::invalid_argument naming the field when it cannot be used
  /// (out of order, duplicate, dated too far ahead); the caller drops and counts it.
  void on_own_pose(const wingman::own_pose_t& pose);

  /// Localizes and tracks one detections message. A box with class_id != 0 (common::kDroneClassId) is counted in
  /// LocalizerOutput::non_drone and non_drone_boxes(), and with classes.decision "box" left out (only drones are
  /// localized and tracked); with "track" every box is tracked with its drone score as its confidence. Boxes of
  /// SOURCE_CNN go through target.box_relation, ground-truth boxes are the sphere's. Throws std::invalid_argument
  /// naming the field for a message that cannot be used at all (other camera, other image size, out of order, a
  /// model_id the box relation was not measured for); the caller drops and counts it.
  LocalizerOutput on_detections(const wingman::detections_t& detections);

  /// The non-drone boxes of every message since construction that passed the camera, image size and order checks.
  const NonDroneCounts& non_drone_boxes() const { return non_drone_boxes_; }

  /// The lines worth a log line since the last call (a time resync: which input re-anchored the clock and what was
  /// forgotten), oldest first; the list is emptied.
  std::vector<std::string> take_notes();

  /// What the status says about the tracker, "" when nothing needs saying: the tentative tracks held back now by
  /// tracker.confirm_min_confidence (a model whose scores sit below the bar confirms nothing; this says why).
  std::string tracker_summary() const;

 private:
  /// The windows of the tracks after detections `d`, the camera at `pose` (the own pose at d.utime).
  wingman::track_windows_t track_windows(const wingman::detections_t& d, const PoseSample& pose) const;
  wingman::targets_t camera_frame_targets(const wingman::detections_t& d,
                                          const std::vector<CameraMeasurement>& measurements) const;

  LocalizerOptions options_;
  BoxRelation cnn_relation_;  // options_.sphere.box_relation, for SOURCE_CNN detections
  geometry::CameraModel camera_;
  geometry::Extrinsics extrinsics_;
  PoseBuffer poses_;
  Tracker tracker_;
  common::StageClock clock_;  ///< admits own poses and detections by message time
  int own_pose_input_;
  int detections_input_;
  int64_t newest_pose_utime_ = -1;
  int64_t previous_detections_utime_ = -1;  ///< the last accepted detections_t's utime (frame interval for windows)
  NonDroneCounts non_drone_boxes_;
  std::vector<std::string> notes_;  ///< take_notes()
};

}  // namespace wingman::localizer
