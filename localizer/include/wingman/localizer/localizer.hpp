// SPDX-License-Identifier: MIT
// The localizer's logic without LCM: detections and own poses in, targets out.
#pragma once

#include <wingman/geometry/camera_model.hpp>
#include <wingman/geometry/camera_rig.hpp>
#include <wingman/geometry/extrinsics.hpp>
#include "wingman/localizer/box_relation.hpp"
#include "wingman/localizer/camera_to_world.hpp"
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
#include <utility>
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

/// A camera's windows and the channel they go out on (a camera rig: each camera's own).
struct CameraWindows {
  std::string channel;               ///< the rig camera's windows channel
  wingman::track_windows_t windows;  ///< the tracks predicted into that camera's next image
};

/// One camera of the localizer: its model, mount and channels, and what it has sent.
struct LocalizerCamera {
  LocalizerCamera(int32_t id, geometry::CameraModel model, geometry::Extrinsics mount, std::string detections,
                  std::string windows)
      : camera_id(id),
        camera(std::move(model)),
        extrinsics(mount),
        detections_channel(std::move(detections)),
        windows_channel(std::move(windows)) {}

  int32_t camera_id = 0;
  geometry::CameraModel camera;  ///< rescaled to the detections' image size when camera.scale_to_image allows
  geometry::Extrinsics extrinsics;
  std::string detections_channel;  ///< detections_t input
  std::string windows_channel;     ///< track_windows_t output (windows.publish)
  int64_t messages = 0;            ///< detections_t accepted (in order, of the right size)
  int64_t last_utime = -1;         ///< utime of the newest accepted detections_t; -1 before the first
  int64_t processed_utime = -1;    ///< utime of the newest exposure processed with this camera (its frame interval)
};

/// What a camera rig's exposures have been through (cameras.rig).
struct ExposureStats {
  int64_t processed = 0;   ///< exposures given to the tracker (one targets_t each, unless nothing is published)
  int64_t incomplete = 0;  ///< of those, processed without one or more rig cameras (silent, late or overtaken)
  int64_t overflowed = 0;  ///< of those, processed because cameras.max_pending exposures were waiting
  int64_t late = 0;        ///< detections_t dropped: their exposure had been processed without them
};

/// What one detections message gave (one camera), or one exposure (a camera rig).
struct LocalizerOutput {
  /// Targets to publish; nullopt when there is nothing to publish (no confirmed track and output.publish_empty
  /// off, or no fresh own pose and output.publish_camera_frame_only off).
  std::optional<wingman::targets_t> targets;
  /// One line per box that could not be used and per missing own pose, naming the field and why;
  /// the process counts each as a drop.
  std::vector<std::string> rejections;
  /// The detections channel each rejection belongs to (same order): the box's camera's; for a missing own pose the
  /// exposure's first camera's.
  std::vector<std::string> rejection_channels;
  bool camera_frame_only = false;  ///< no own pose fresh enough at the image's exposure time
  /// The message's boxes with class_id != 0, left out before localization (not rejections).
  NonDroneCounts non_drone;
  /// With windows.publish and a fresh own pose: where every track will be in this camera's next image (published
  /// before the targets, so that in lockstep the detector has them before the next frame). Empty windows are
  /// published too (the detector then knows its tracks are gone).
  std::optional<wingman::track_windows_t> windows;
  /// A camera rig with windows.publish and a fresh own pose: every rig camera's windows, in rig order, each for its
  /// own channel (published before the targets, as `windows`). Empty for one camera (that is `windows`).
  std::vector<CameraWindows> camera_windows;
  int64_t utime = 0;  ///< the exposure's utime (every detections_t of it has this utime)
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

  /// Several cameras on one vehicle (cameras.rig): `rig`'s cameras replace options.camera (except scale_to_image,
  /// which applies to each), options.extrinsics, input.detections_channel and windows.channel. The detections_t of
  /// one exposure (all rig cameras' messages with the same utime) are buffered per camera and fused into one tracker
  /// frame, in rig order (Tracker::update_cameras), once every camera that is not silent has sent it: see
  /// add_detections(). Throws std::invalid_argument for invalid options.
  Localizer(const LocalizerOptions& options, const geometry::CameraRig& rig);

  /// The localizer of `options`: the rig of cameras.rig (geometry::load_camera_rig(), which throws
  /// common::ConfigError naming the file's every problem), or with "" the one camera of camera.*.
  static Localizer from_options(const LocalizerOptions& options);

  /// Adds an own pose. Throws std::invalid_argument naming the field when it cannot be used
  /// (out of order, duplicate, dated too far ahead); the caller drops and counts it.
  void on_own_pose(const wingman::own_pose_t& pose);

  /// Localizes and tracks one detections message. A box with class_id != 0 (common::kDroneClassId) is counted in
  /// LocalizerOutput::non_drone and non_drone_boxes(), and with classes.decision "box" left out (only drones are
  /// localized and tracked); with "track" every box is tracked with its drone score as its confidence. Boxes of
  /// SOURCE_CNN go through target.box_relation, ground-truth boxes are the sphere's. Throws std::invalid_argument
  /// naming the field for a message that cannot be used at all (other camera, other image size, out of order, a
  /// model_id the box relation was not measured for); the caller drops and counts it.
  /// One camera only (no cameras.rig): a rig throws std::logic_error (use add_detections()).
  LocalizerOutput on_detections(const wingman::detections_t& detections);

  /// Either kind: one camera gives one output per message (on_detections()); a rig buffers the message with its
  /// exposure (its utime) and returns the exposures that are now ready, oldest first (none, one, or several; never one
  /// before an older one). An exposure is ready when every rig camera it lacks is not to be waited for:
  /// - it has sent a later exposure (a camera's messages come in order: it will not send this one), or
  /// - it is silent: no message for cameras.silent_after_s of message time behind the newest message of any rig
  ///   camera (a camera that never sent counts from the rig's first message), until it sends again, or
  /// - it is overtaken: every other camera that is not silent has sent a later exposure;
  /// or, whatever it lacks, when more than cameras.max_pending exposures wait. So with every camera sending, an
  /// exposure is processed exactly when its last camera's message comes (lockstep: one targets_t per frame, never
  /// early). Each ready exposure is one tracker frame of its cameras in rig order (Tracker::update_cameras()) and one
  /// LocalizerOutput, whatever order its cameras' messages arrived in. Throws std::invalid_argument naming the field
  /// for a message that cannot be used at all (a camera_id not in the rig, another image size, out of order for its
  /// camera, dated too far ahead, a model_id the box relation was not measured for, or late: its exposure was
  /// processed without it); the caller drops and counts it.
  std::vector<LocalizerOutput> add_detections(const wingman::detections_t& detections);

  /// The cameras (one, or the rig's in rig order), with what each has sent.
  const std::vector<LocalizerCamera>& cameras() const { return cameras_; }
  /// Whether this localizer fuses a camera rig (cameras.rig).
  bool is_rig() const { return rig_; }
  const ExposureStats& exposure_stats() const { return exposure_stats_; }
  /// The rig cameras that are silent now: "camera 2 silent for 3.4 s" each, joined by ", " ("" when none or one
  /// camera); a camera that never sent says "(no message yet)".
  std::string silent_summary() const;
  /// Per rig camera how many detections_t it has sent, and how many exposures went without one or more cameras, e.g.
  /// "detections_t per camera: 0 120, 1 118, 2 60, 3 120 (62 of 120 exposures without every camera)" ("" for one
  /// camera).
  std::string cameras_summary() const;

  /// The non-drone boxes of every message since construction that passed the camera, image size and order checks.
  const NonDroneCounts& non_drone_boxes() const { return non_drone_boxes_; }

  /// The lines worth a log line since the last call (a time resync: which input re-anchored the clock and what was
  /// forgotten), oldest first; the list is emptied.
  std::vector<std::string> take_notes();

  /// What the status says about the tracker, "" when nothing needs saying: the tentative tracks held back now by
  /// tracker.confirm_min_confidence (a model whose scores sit below the bar confirms nothing; this says why).
  std::string tracker_summary() const;

 private:
  /// Camera `c`'s checks of one message (its camera, image size, model_id and time); throws std::invalid_argument.
  /// A detections resync restarts the tracker (and forgets the waiting exposures).
  void admit(LocalizerCamera& c, int clock_input, const wingman::detections_t& d);
  /// One exposure: `per_camera[i]` is camera i's message or null (missing), at least one not null.
  LocalizerOutput process(int64_t utime, const std::vector<const wingman::detections_t*>& per_camera);
  /// Whether rig camera `i` is silent at the newest message time.
  bool silent(size_t i) const;
  /// The newest accepted detections_t utime of any camera (first_utime_ before any camera has one).
  int64_t newest_camera_utime() const;
  /// A new start (time went back): a new tracker, no waiting exposures, every camera but `keep` (may be null) as if
  /// it had sent nothing. For one camera the same (its bookkeeping is unused).
  void restart(const LocalizerCamera* keep);
  /// Per camera of the exposure (null: none), the confirmed tracks occluding each other there
  /// (tracker.occlusion_margin; FrameViews::occluded), their states predicted to `utime`, camera c at
  /// `cam_in_world[c]`.
  std::vector<std::vector<int32_t>> occluded_tracks(int64_t utime,
                                                    const std::vector<const wingman::detections_t*>& per_camera,
                                                    const std::vector<CameraPoseInWorld>& cam_in_world) const;
  /// The windows of the tracks after the exposure at `utime`: camera `c` at `now` then, moving with the body's
  /// velocity of `pose` (the own pose at utime).
  wingman::track_windows_t track_windows(int64_t utime, const LocalizerCamera& c, int8_t source, const PoseSample& pose,
                                         const CameraPoseInWorld& now) const;

  LocalizerOptions options_;
  bool rig_ = false;
  BoxRelation cnn_relation_;              // options_.sphere.box_relation, for SOURCE_CNN detections
  std::vector<LocalizerCamera> cameras_;  ///< one, or the rig's in rig order
  std::vector<int> camera_inputs_;        ///< clock_ input of each camera
  PoseBuffer poses_;
  Tracker tracker_;
  common::StageClock clock_;  ///< admits own poses and detections by message time
  int own_pose_input_;
  /// A rig: the exposures waiting for cameras, by utime: each camera's message or nothing, in rig order.
  std::map<int64_t, std::vector<std::optional<wingman::detections_t>>> pending_;
  int64_t processed_utime_ = -1;  ///< a rig: the newest exposure processed
  int64_t first_utime_ = -1;      ///< a rig: the first accepted detections_t's utime (a silent camera's start)
  ExposureStats exposure_stats_;
  int64_t newest_pose_utime_ = -1;
  NonDroneCounts non_drone_boxes_;
  std::vector<std::string> notes_;  ///< take_notes()
};

}  // namespace wingman::localizer
