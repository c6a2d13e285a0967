// SPDX-License-Identifier: MIT
// `wingman eval`, reading (internal to the tools): the flight log as plain per-message records, nothing computed.
#pragma once

#include "wingman/tools/eval.hpp"

#include <wingman/detection_t.hpp>
#include <wingman/target_t.hpp>
#include <wingman/truth_box_t.hpp>

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace wingman::tools {

/// World positions of one vehicle over time (ground_truth_t), linearly interpolated.
struct TruthTrack {
  std::vector<int64_t> utime;      ///< simulated time, microseconds, strictly increasing
  std::vector<Eigen::Vector3d> p;  ///< vehicle_truth_t.p_body_in_world at each utime: world frame (ENU), metres
  /// Position at `t` (utime, microseconds); false when t is outside the recorded span.
  bool at(int64_t t, Eigen::Vector3d* out) const;
};

/// One world-valid target_t of one targets_t.
struct EvalEstimate {
  int64_t utime;   ///< target_t.predicted_utime, microseconds
  size_t message;  ///< index of its targets_t among the decoded ones, log order
  wingman::target_t target;
};

/// One detections_t, its drone boxes only (class_id 0, as the localizer tracks them).
struct EvalDetections {
  int64_t utime;  ///< detections_t.utime, microseconds
  int camera_id;
  int image_width;  ///< pixels of the source image; <= 0 unknown
  std::vector<wingman::detection_t> boxes;
};

/// Everything `wingman eval` uses from a log, per message and undigested. Messages that are not of their channel's
/// type or fail validation are left out. utimes are simulated time, timestamps the log events' (the logger's
/// receive time, wall clock); both microseconds.
struct EvalLog {
  int64_t truth_frames = 0;                                             ///< decoded ground_truth_t messages
  std::map<int, TruthTrack> truth;                                      ///< vehicle id -> positions
  std::map<int64_t, std::vector<wingman::truth_box_t>> truth_boxes_at;  ///< truth utime -> its boxes (last message)
  std::map<int64_t, int64_t> truth_event_at;  ///< truth utime -> timestamp of its first ground_truth_t event
  std::map<int64_t, int64_t> image_event_at;  ///< image utime -> timestamp of its first image_t event (image channel)
  std::vector<EvalEstimate> estimates;        ///< world-valid targets, log order
  /// For each targets_t with targets, log order: (its event timestamp, the newest source_utime among its targets).
  std::vector<std::pair<int64_t, int64_t>> published;
  std::vector<EvalDetections> detections;  ///< every detections_t, log order
  std::vector<double> inference_ms;        ///< detections_t.inference_latency_us of each, milliseconds
  std::set<int> sources;                   ///< distinct detections_t.source values
  int64_t non_drone_boxes = 0;             ///< detected boxes with class_id != 0 (not in `detections`)
  std::vector<int64_t> image_utimes;       ///< utimes of the image_t events on the image channel, log order
  std::vector<int64_t> preview_utimes;     ///< utimes of the image_t events on the preview channel, log order
  /// Each detector's status channel (STATUS_DETECTOR...) -> the first heartbeat detail that says which backend runs
  /// and why ("backend opencl: ... (auto, not timed: ...)"); empty when the log holds no such heartbeat.
  std::map<std::string, std::string> detector_backends;
};

/// Reads options.log (channels and progress from `options`, which must be valid) into records. Throws
/// std::runtime_error naming the file when it is a directory, cannot be read, is corrupt (with the byte offset) or
/// holds no ground_truth_t on options.truth_channel.
EvalLog read_eval_log(const EvalOptions& options);

}  // namespace wingman::tools
