// SPDX-License-Identifier: MIT
// Track-level metrics (`wingman val --sequences`): whole clips through the detector and the localizer's tracker.
#pragma once

#include <wingman/detector/box.hpp>
#include <wingman/detector/detection_pipeline.hpp>
#include <wingman/detector/motion_cue.hpp>
#include <wingman/geometry/camera_model.hpp>
#include <wingman/localizer/localizer.hpp>
#include <wingman/localizer/localizer_options.hpp>

#include <opencv2/core.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace wingman::training {

/// How confirmed tracks are judged (the Airborne Object Tracking challenge's spirit: what a flying system would act
/// on).
struct TrackScoringOptions {
  /// A confirmed track is on the drone when more than this share of its hits (frames from its confirmation on in
  /// which the tracker associated a detection with it) has the detection's centre inside a labelled drone box of
  /// that frame; every other confirmed track is false. 0.5: "most of its confirmed life". [0, 1).
  double on_target_fraction = 0.5;
  /// The drone counts as confirmed in time when its first on-target track is confirmed at most this long after the
  /// clip's first labelled frame, seconds of video time. > 0.
  double confirm_within_s = 1.0;

  /// One "field = value: rule" line per invalid field; empty when valid.
  std::vector<std::string> validate() const;
};

/// One confirmed track of one clip.
struct TrackRecord {
  int32_t track_id = 0;     ///< the tracker's id (1, 2, ... in order of confirmation within the clip)
  int confirmed_frame = 0;  ///< video frame index (0-based, read sequentially) at which it was first output
  int last_frame = 0;       ///< last video frame at which it was output
  int hits = 0;             ///< frames from confirmation on with a detection associated with it
  int hits_on_target = 0;   ///< of those, frames whose detection's centre lies in a labelled drone box
  bool on_target = false;   ///< hits_on_target > on_target_fraction x hits (set by score_clip)
};

/// What one clip gave.
struct ClipTrackResult {
  std::string clip;          ///< e.g. V_DRONE_010
  std::string cls;           ///< the clip's class: DRONE, AIRPLANE, BIRD or HELICOPTER
  std::string distance_bin;  ///< CLOSE, MEDIUM or DISTANT (splits.csv)
  /// Non-empty: the clip was not evaluated, and why (a video that cannot be opened, no frame, no frame rate); it is
  /// left out of every sum and counted apart.
  std::string skipped;
  double fps = 0;              ///< the video's frame rate (its header), frames/s
  int frames = 0;              ///< frames read from the video
  int frames_tracked = 0;      ///< of those, frames given to the tracker (every frame_step-th)
  double duration_s = 0;       ///< frames / fps: the video time this clip adds, s
  int first_label_frame = -1;  ///< first frame with a labelled drone box (-1: none, e.g. a distractor clip)
  int64_t drone_boxes = 0;     ///< class-0 detections given to the localizer
  /// Detections of other classes (a multi-class model's distractors): not tracked (LocalizerOutput::non_drone).
  int64_t other_class_boxes = 0;
  int64_t rejected_boxes = 0;       ///< class-0 detections the localizer could not use (e.g. range outside range.*)
  std::vector<TrackRecord> tracks;  ///< every track that was confirmed, by id
  // Set by score_clip:
  int false_tracks = 0;           ///< confirmed tracks not on the drone
  int drone_tracks = 0;           ///< confirmed tracks on the drone (more than one: the drone's track was broken)
  bool drone_confirmed = false;   ///< an on-target track was confirmed (DRONE clips)
  double time_to_confirm_s = -1;  ///< its confirmation - the first labelled frame, s (>= 0; -1: not confirmed)
};

/// Fills the scored fields of `clip` (on_target of each track, false_tracks, drone_tracks, drone_confirmed,
/// time_to_confirm_s) from
/// its tracks, first_label_frame and fps. A track confirmed before the first labelled frame that is on the drone has
/// time_to_confirm_s 0.
void score_clip(ClipTrackResult& clip, const TrackScoringOptions& scoring);

/// Runs the localizer (wingman::localizer::Localizer, as wingman-localizer does) over one clip frame by frame and
/// records its confirmed tracks: the seam between the video and detector and the track metrics.
///
/// The camera stands still on the ground: before each frame it gets an own pose at that frame's time with the
/// body at the world origin, unrotated (identity). Frame f is exposed at utime kClipStartUtime + round(f / fps s):
/// video time, never the wall clock. Every box goes to the localizer as wingman-detector publishes it
/// (detector::to_detection); the localizer tracks class 0 (drone) only. A confirmed track's detection
/// in a frame is the box whose localized camera-frame position the track reports (target_t.p_target_in_cam, the
/// tracker's last measurement) when its source_utime is that frame's.
class ClipTracker {
 public:
  /// The first frame's utime, microseconds (any positive constant: the tracker uses differences only).
  static constexpr int64_t kClipStartUtime = 1000000;

  /// @param options  the localizer's options (config/localizer.yaml); its camera.* keys are not used: `camera` is.
  /// @param camera   the camera of the clip's images (its size must be the frames' size).
  /// @param fps      the video's frame rate, frames/s; > 0 (std::invalid_argument otherwise).
  ClipTracker(const localizer::LocalizerOptions& options, geometry::CameraModel camera, double fps);
  ~ClipTracker();

  /// One frame: its video index (strictly increasing; std::invalid_argument otherwise), the detector's boxes of every
  /// class in pixels of the frame ((0, 0) = top-left corner of the top-left pixel), and the labelled drone boxes of
  /// that frame in the same pixels (x, y = top-left corner).
  void add_frame(int frame_index, const std::vector<detector::Box>& boxes, const std::vector<cv::Rect2d>& drone_truths);

  /// The confirmed tracks so far, by id (on_target not yet set: score_clip does).
  std::vector<TrackRecord> tracks() const;
  int64_t drone_boxes() const { return drone_boxes_; }
  int64_t other_class_boxes() const { return other_class_boxes_; }
  int64_t rejected_boxes() const { return rejected_boxes_; }
  /// Frames given to add_frame.
  int frames() const { return frames_; }
  const geometry::CameraModel& camera() const { return camera_; }

 private:
  localizer::LocalizerOptions options_;
  geometry::CameraModel camera_;
  localizer::BoxRelation relation_;  // options_.sphere.box_relation, as the Localizer applies it
  double fps_;
  std::unique_ptr<localizer::Localizer> localizer_;
  std::map<int32_t, TrackRecord> tracks_;
  int last_frame_ = -1;
  int frames_ = 0;
  int64_t drone_boxes_ = 0, other_class_boxes_ = 0, rejected_boxes_ = 0;
};

/// A nominal pinhole camera: `width` x `height` pixels, horizontal field of view `hfov_deg`, square pixels, the
/// principal point at the image centre, no distortion. fx = fy = (width / 2) / tan(hfov / 2).
/// Throws std::invalid_argument for a size <= 0 or hfov_deg outside (0, 180).
geometry::CameraModel nominal_pinhole(int width, int height, double hfov_deg);

/// What `wingman val --sequences` evaluates and how.
struct SequenceEvalOptions {
  /// The imported Halmstad dataset (`wingman import-halmstad`): its folder or its data.yaml; its splits.csv names
  /// each clip's split (required).
  std::string data;
  /// The Halmstad dataset (videos/<clip>.mp4, labels/<clip>.csv). Relative paths are the caller's working directory's.
  std::string halmstad_root = "../shared/datasets/halmstad";
  std::string split = "val";                      ///< the clips of this split in splits.csv
  std::vector<std::string> clips;                 ///< only these clips of the split (empty = all of them)
  std::string cfg = "builtin:wingman-small";      ///< Darknet .cfg path or builtin:<name> (detector::load_model)
  std::string weights = "builtin:wingman-small";  ///< Darknet .weights path or builtin:wingman-small
  std::string backend = "cpu";      ///< detector backend: auto (opencl whenever usable, not timed), opencl or cpu
  std::string input_size = "auto";  ///< network input, as ValOptions::input_size
  /// Algorithm 2's settings: the detector's defaults (p_thresh 0.2, what wingman-detector publishes).
  detector::DetectorPipelineOptions detection;
  /// The detector's motion cue (motion.enabled): each clip's frames (every frame_step-th, at their video times) through
  /// detector::MotionCue, its windows searched by the window network (windows.crop_px, p_thresh, gate_sigma; budget
  /// motion.max_windows), as wingman-detector does. Off by default.
  detector::MotionOptions motion;
  detector::WindowOptions windows;  ///< the window network's settings for the motion cue's windows
  /// wingman-localizer's YAML (config/localizer.yaml's keys) read by the common loader; "" = its built-in defaults.
  /// Its camera.* keys are not used: the camera is nominal_pinhole(frame size, hfov_deg).
  std::string localizer_config;
  /// Horizontal field of view of the nominal pinhole, degrees. The dataset gives no intrinsics; its authors set the
  /// visible camera's zoom to about the thermal camera's field of view, 24 x 19 degrees (Svanstrom 2020 thesis).
  /// (0, 180).
  double hfov_deg = 24.0;
  int frame_step = 1;  ///< track every frame_step-th frame (0, step, 2 step, ...); time stays frame / fps. >= 1
  /// Track only each clip's frames before this video time, s (0: whole clips; >= 0). A clip's duration, its false
  /// tracks per hour and its drone's time to confirm are then those of that part. A run with a limit writes no
  /// boxes_cache files (they hold whole clips); it reads them, using the frames before the limit.
  double max_seconds = 0;
  TrackScoringOptions scoring;
  /// A folder for the detector's boxes of every tracked frame, one `<clip>.boxes` file per clip ("" = none). A clip
  /// whose file is there is tracked from it instead of running the detector (the video is not read), so the tracker's
  /// settings can be compared on the same boxes in seconds; a clip whose file is missing is detected and its file
  /// written. A file made with other detection settings (model, weights' SHA-256, backend, input size, Algorithm 2's
  /// options, frame_step) is an error naming the file and both settings, never silently reused.
  std::string boxes_cache;

  /// One "field = value: rule" line per invalid field; empty when valid.
  std::vector<std::string> validate() const;
};

/// One row of the summary: the clips of one class (DRONE also by distance bin).
struct TrackGroupSummary {
  std::string name;           ///< "DRONE CLOSE", ..., "DRONE", "AIRPLANE", "BIRD", "HELICOPTER", "distractors"
  bool drone = false;         ///< a group of DRONE clips
  int clips = 0;              ///< clips evaluated (skipped ones left out)
  double hours = 0;           ///< video time, hours
  int false_tracks = 0;       ///< confirmed tracks not on a drone
  int drone_tracks = 0;       ///< confirmed tracks on a drone (drone groups; more than `confirmed`: broken tracks)
  double false_per_hour = 0;  ///< false_tracks / hours (0 when hours is 0)
  /// One-sided 95 % upper bound of the false-track rate (Poisson, exact), per hour: with few hours of video 0 false
  /// tracks still allows a high rate.
  double false_per_hour_upper95 = 0;
  int confirmed = 0;                     ///< drone groups: clips whose drone was confirmed as a track
  int confirmed_within = 0;              ///< of those, within TrackScoringOptions::confirm_within_s of the first label
  double median_time_to_confirm_s = -1;  ///< over the confirmed clips; -1 when none
};

/// The result of run_sequence_eval.
struct SequenceEvalResult {
  std::string split;
  double hfov_deg = 0, focal_px = 0;  ///< the nominal pinhole used (focal_px of the first clip's frame size)
  int frame_step = 1;
  double max_seconds = 0;                ///< SequenceEvalOptions::max_seconds (0: whole clips)
  detector::MotionStats motion;          ///< the motion cue's work over every clip detected (motion.enabled)
  detector::WindowStats motion_windows;  ///< and its windows' (searched, crops, found a drone)
  TrackScoringOptions scoring;
  std::vector<ClipTrackResult> clips;  ///< by clip name; skipped ones included (ClipTrackResult::skipped)

  /// The rows: DRONE CLOSE, DRONE MEDIUM, DRONE DISTANT (the bins present), DRONE, AIRPLANE, BIRD, HELICOPTER (the
  /// classes present), distractors (the three together).
  std::vector<TrackGroupSummary> groups() const;
  int skipped() const;  ///< clips skipped
  /// The table, the two targets (<= 1 false track per hour of distractor video; >= 95 % of drone clips confirmed
  /// within confirm_within_s), every false track, every drone clip not confirmed in time, every skipped clip.
  std::string report() const;
  /// One JSON object: the settings, the groups and every clip with its tracks.
  std::string json() const;
};

/// Detects in one video frame (BGR): the boxes of every class in pixels of the frame.
using FrameDetector = std::function<std::vector<detector::Box>(const cv::Mat& bgr)>;

/// One clip's detector output as SequenceEvalOptions::boxes_cache stores it.
struct ClipBoxes {
  std::string settings;                             ///< what made them (detection_settings()); compared before reuse
  double fps = 0;                                   ///< the video's frame rate, frames/s (> 0)
  int frames = 0;                                   ///< frames the video gave (>= 0)
  int width = 0, height = 0;                        ///< frame size, pixels (> 0 when frames > 0)
  int frame_step = 1;                               ///< every frame_step-th frame was detected (>= 1)
  std::map<int, std::vector<detector::Box>> boxes;  ///< tracked frame index -> its boxes (frames without boxes absent)
};

/// Writes `b` to `path` (a text file: a header, then one line per box with every float in round-trip precision),
/// through a temporary file renamed into place. Throws std::runtime_error naming the path when it cannot be written.
void write_clip_boxes(const std::string& path, const ClipBoxes& b);

/// Reads a file write_clip_boxes wrote. Throws DatasetError naming the file and line for anything else (a missing or
/// unknown header, a bad number, a frame outside the clip or not a multiple of frame_step, a negative size, more than
/// 10^7 frames).
ClipBoxes read_clip_boxes(const std::string& path);

/// The settings string a boxes cache is keyed by: cfg (and a cfg file's SHA-256), the weights' SHA-256
/// (detector::weights_model_id), backend, input size and every DetectorPipelineOptions field. "custom detector" when
/// run_sequence_eval is given one. The detector's code is not in it: after a change to the detector, start a new cache.
std::string detection_settings(const SequenceEvalOptions& o);

/// Reads the labelled boxes of one Halmstad label CSV (`frame,class,x,y,w,h`; MATLAB pixels, so 0.5 px is
/// subtracted from x and y): frame -> boxes of class DRONE. Boxes of the other known classes (AIRPLANE, BIRD,
/// HELICOPTER) are read and left out. Throws DatasetError naming the file and line for a missing file, a bad header, a
/// bad field or an unknown class.
std::map<int, std::vector<cv::Rect2d>> read_halmstad_drone_boxes(const std::string& path);

/// Runs every clip of the split through `detect` (empty: the detector built from the options, as `wingman val`
/// builds it) and ClipTracker, and scores them. Clips in name order; one line per clip to `log` (may be empty) and
/// `progress(clips done, clips in all)` (may be empty) after each clip.
/// Deterministic for a deterministic detector. Throws std::invalid_argument listing invalid options; DatasetError
/// naming the file for a missing or malformed splits.csv, a split without clips, a clip named in `clips` that is
/// not in the split, a missing Halmstad folder, or a missing or malformed label file; std::runtime_error from loading
/// the model or the localizer config (common::ConfigError). A video that cannot be opened or gives no frame is
/// skipped and reported (ClipTrackResult::skipped).
SequenceEvalResult run_sequence_eval(const SequenceEvalOptions& options, const FrameDetector& detect = {},
                                     const std::function<void(const std::string&)>& log = {},
                                     const std::function<void(size_t, size_t)>& progress = {});

}  // namespace wingman::training
