// SPDX-License-Identifier: MIT
// `wingman eval`, metrics (internal to the tools): each function fills one section of EvalResult from the log's
// records. Times in the result are seconds since the first ground truth (EvalResult::first_truth_utime); positions
// are world frame (ENU), metres.
#pragma once

#include "eval_log.hpp"
#include "wingman/tools/eval.hpp"

#include <set>
#include <string>

namespace wingman::tools {

/// "none" (no detections_t), "ground_truth" or "cnn" (one detections_t.source), "mixed" (several).
std::string detection_source_name(const std::set<int>& sources);

/// Sets truth_frames, first_truth_utime and duration_s (ground-truth time span, seconds) and copies the counts the
/// reading took (non_drone_boxes, image_utimes, preview_utimes) and detection_source.
void log_metrics(const EvalLog& log, EvalResult* r);

/// Leader detection and false boxes (box_on_leader()): false_boxes, frames_with_false_box, detection_frames,
/// detection_by_range (by the leader's truth range, options.range_bins_m) and their sums frames_leader_visible,
/// frames_leader_detected, false_boxes_leader_visible, frames_leader_visible_with_false_box.
void detection_metrics(const EvalLog& log, const EvalOptions& options, EvalResult* r);

/// Localization and identities: each world target matched to the nearest truth vehicle (not the follower) within
/// options.match_radius_m at its predicted_utime. Sets localization (3-D, per axis, along/across the follower's line
/// of sight, by true range), the false targets, the track ids and id switches (leader and per vehicle), and the time
/// series targets, leader_estimate, localization_error_over_time and frames[].leader_track_id. Needs
/// first_truth_utime and duration_s (log_metrics).
void localization_metrics(const EvalLog& log, const EvalOptions& options, EvalResult* r);

/// Latency, ms (wall clock, log-event timestamps): latency_ms and latency_samples_ms from the exposure (the earlier
/// event of the image_t and the ground_truth_t of the newest source_utime) to each published targets_t;
/// inference_latency_ms from detections_t.inference_latency_us.
void latency_metrics(const EvalLog& log, EvalResult* r);

/// Boxes: detections_total, detections_outside_truth, the box-width errors (fractions of the image width; single
/// pass and zoom-in, overall and by truth range) with their samples box_widths, and frames[]' detections,
/// image_width and truth boxes (pixels of the source image).
void box_metrics(const EvalLog& log, const EvalOptions& options, EvalResult* r);

/// Paths and formation: follower_truth, leader_truth (at the follower's ground-truth times), and when
/// options.has_formation, formation_horizontal / formation_vertical (follower minus desired position, metres, after
/// options.settle_s seconds) and formation_error_over_time. Needs first_truth_utime (log_metrics).
void formation_metrics(const EvalLog& log, const EvalOptions& options, EvalResult* r);

}  // namespace wingman::tools
