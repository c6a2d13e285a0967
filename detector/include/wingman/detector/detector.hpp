// SPDX-License-Identifier: MIT
// The detector's frame loop without LCM: images and tracker windows in, detections out.
#pragma once

#include "wingman/detector/box.hpp"
#include "wingman/detector/detector_options.hpp"
#include "wingman/detector/motion_cue.hpp"
#include "wingman/detector/sized_detector.hpp"
#include "wingman/detector/track_windows.hpp"

#include <wingman/common/time_sanity.hpp>
#include <wingman/detections_t.hpp>
#include <wingman/image_t.hpp>
#include <wingman/track_windows_t.hpp>

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace wingman::detector {

/// A line for the log that is not a drop, and (with `state`) the heartbeat's new STATE_OK detail: what a network
/// build says (the backend that runs, and why; a network for a new frame size), or a time resync.
struct DetectorNote {
  enum class Level { kInfo, kWarn };
  Level level = Level::kInfo;
  std::string text;
  std::string state;  ///< non-empty: the new STATE_OK detail
};

/// What the detector found in one frame.
struct FrameDetections {
  std::vector<Box> boxes;  ///< every box, drone or not (class_id != 0 with a multi-class model), full-image pixels
  int64_t latency_us = 0;  ///< the time detect() took (the one wall-clock field of detections_t)
};

/// The detector process's per-frame logic (wingman-detector without LCM): the image clock, the single pass (Algorithm
/// 2 through SizedDetector, network sized per frame), the tracker-driven windows (the newest track_windows_t), and
/// the detections_t of each frame. Time is message time only (image_t.utime, track_windows_t.utime_predicted); the
/// same inputs in the same order give the same boxes (the latency excepted).
///
/// Without model.weights ("") images are only checked: admitted by the clock, never detected.
///
/// Threads: admit(), on_windows() and take_notes() are called by one thread (the one reading the bus); detect() may
/// run on another (a real-time worker), one frame at a time. The newest windows and the notes are shared under a lock.
class Detector {
 public:
  /// The STATE_DEGRADED detail without a model.
  static constexpr const char* kNoModelDetail = "no model.weights configured: images are checked and counted only";

  /// Loads the model (model.cfg, model.weights) and builds the single pass's network, then (windows.enabled) the
  /// window network, through model.backend: what the builds say is in take_notes(). Throws std::invalid_argument
  /// listing options.validate() problems, and what load_model() and make_backend() throw (model.backend opencl
  /// without a usable OpenCL device, a kernel that fails to build).
  explicit Detector(const DetectorOptions& options);
  ~Detector();
  Detector(const Detector&) = delete;
  Detector& operator=(const Detector&) = delete;

  /// false without model.weights: images are only checked (degraded(): why).
  bool has_model() const { return pipeline_ != nullptr; }
  /// "" with a model, else kNoModelDetail.
  std::string degraded() const { return has_model() ? "" : kNoModelDetail; }
  /// true with a model and windows.enabled: the caller subscribes to windows.channel.
  bool windows_enabled() const { return options_.windows.enabled && window_detector_ != nullptr; }

  /// Admits a frame by its time (time.*): notes its camera (the camera the windows must be of), then throws
  /// std::invalid_argument naming image_t.utime, its value and the rule for a frame dated more than
  /// time.max_ahead_s ahead or not after the previous one (the caller drops and counts it; it is never detected). A
  /// time resync is a note (take_notes()).
  void admit(const wingman::image_t& image);

  /// The newest windows (the localizer's predictions), kept whole for the frames to come. Throws
  /// std::invalid_argument naming track_windows_t.camera_id for windows of another camera than the frames admitted
  /// (from the first frame on; the caller drops and counts it). Without windows_enabled() they are checked only.
  void on_windows(const wingman::track_windows_t& windows);

  /// Detects in an admitted frame: the single pass, then the newest windows' search (windows_to_search() at the
  /// frame's utime, size and camera; windows older or newer than windows.max_age_s are not searched), merged. Throws
  /// std::invalid_argument for pixels that cannot be read (the caller drops and counts it), std::logic_error without
  /// a model, and what the backend throws. A network built for a new frame size adds a note.
  FrameDetections detect(const wingman::image_t& image);

  /// The detections_t of frame `image` (its header is enough): its utime, seq, camera_id and size, SOURCE_CNN, the
  /// latency, the model's id (weights_model_id()) and every box.
  wingman::detections_t message(const wingman::image_t& image, const FrameDetections& found) const;

  /// One frame in order: admit(), then (with a model) detect() and message(). nullopt without a model. Throws what
  /// admit() and detect() throw.
  std::optional<wingman::detections_t> on_image(const wingman::image_t& image);

  /// The notes since the last call, oldest first; the list is emptied.
  std::vector<DetectorNote> take_notes();

  /// What the windows did since construction (written by detect()).
  const WindowStats& window_stats() const { return window_stats_; }
  /// What the motion cue (motion.enabled) found and what its windows did since construction (written by detect()).
  const MotionStats* motion_stats() const { return motion_ ? &motion_->stats() : nullptr; }
  const WindowStats& motion_window_stats() const { return motion_window_stats_; }

 private:
  std::unique_ptr<InferenceBackend> build_backend(const DarknetModel& sized);
  void note(DetectorNote n);

  DetectorOptions options_;
  common::StageClock clock_;  ///< admits images by image_t.utime
  int image_input_;
  std::string model_id_;  ///< detections_t.model_id
  // What model.backend auto chose at start-up ("opencl" or "cpu"), and why: later networks take the same kind.
  std::string auto_kind_;
  std::string auto_why_;
  bool built_once_ = false;  ///< a fallback warns at start-up only
  std::unique_ptr<SizedDetector> pipeline_;
  std::unique_ptr<WindowDetector> window_detector_;
  int32_t image_camera_id_ = -1;                                    ///< the camera of the frames seen (-1: none yet)
  std::mutex mutex_;                                                ///< guards newest_windows_ and notes_
  std::shared_ptr<const wingman::track_windows_t> newest_windows_;  ///< swapped whole: a frame takes the pointer
  std::vector<DetectorNote> notes_;
  WindowStats window_stats_;
  std::unique_ptr<MotionCue> motion_;    ///< motion.enabled: only detect() touches it (one frame at a time)
  WindowOptions motion_window_options_;  ///< windows.* with motion.max_windows as the crop budget
  WindowStats motion_window_stats_;
};

}  // namespace wingman::detector
