// SPDX-License-Identifier: MIT
// `wingman eval`: localization and formation errors of a recorded flight against the simulator's ground truth.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace wingman::tools {

/// What `wingman eval` reads and how it matches.
struct EvalOptions {
  std::string log;  ///< LCM log with ground_truth_t and targets_t (and detections_t, setpoint_t)
  std::string truth_channel = "GROUND_TRUTH";          ///< ground_truth_t channel
  std::string targets_channel = "TARGETS";             ///< targets_t channel
  std::string detections_channel = "DETECTIONS_CAM0";  ///< detections_t channel
  int follower_id = 0;  ///< vehicle_truth_t.vehicle_id of the camera vehicle (the follower)
  int leader_id = 1;    ///< vehicle_truth_t.vehicle_id of the vehicle the formation is kept on
  /// Desired follower position minus leader position, world frame (ENU), metres; the z component is ignored when
  /// formation_height_m is set. Formation metrics are computed only when has_formation is true.
  Eigen::Vector3d formation_offset_in_world = Eigen::Vector3d::Zero();
  bool has_formation = false;
  double formation_height_m = -1.0;  ///< the follower's commanded constant height, metres; < 0: use the offset's z
  double settle_s = 5.0;             ///< formation metrics skip this long after the first ground truth, seconds
  double match_radius_m = 3.0;       ///< a world target farther than this from every truth vehicle is a false target
  std::string json_path;             ///< write the result as JSON here ("" = no)
  std::string report_path;           ///< write a self-contained HTML report here ("" = no)
  std::string title = "Wingman flight";  ///< report title
  /// Checks the options; one line per problem naming the option.
  std::vector<std::string> validate() const;
};

/// RMS, mean of the magnitude and maximum of a set of errors (metres); n = number of samples.
struct ErrorStats {
  int64_t n = 0;
  double rms = 0.0;
  double mean = 0.0;
  double max = 0.0;
};

/// The measured errors of one flight.
struct EvalResult {
  std::string detection_source;                 ///< "cnn", "ground_truth", "mixed" or "none" (from detections_t.source)
  int64_t truth_frames = 0;                     ///< ground_truth_t messages
  int64_t frames_leader_visible = 0;            ///< of those, frames in which the leader's truth box is visible
  int64_t frames_leader_detected = 0;           ///< of those, frames with at least one detection at the same utime
  int64_t target_estimates = 0;                 ///< world-valid targets matched to a truth vehicle
  int64_t false_targets = 0;                    ///< world-valid targets farther than match_radius_m from every vehicle
  int64_t track_ids_on_leader = 0;              ///< distinct track ids matched to the leader
  ErrorStats localization;                      ///< |p_est - p_truth|, 3-D
  std::array<ErrorStats, 3> localization_axis;  ///< per world axis (x, y, z): RMS, mean |e|, max |e|
  ErrorStats along_line_of_sight;               ///< error component along the follower-to-target line
  ErrorStats across_line_of_sight;              ///< error perpendicular to that line
  ErrorStats formation_horizontal;  ///< follower position minus desired position, horizontal, after settle_s
  ErrorStats formation_vertical;    ///< the same, vertical
  double duration_s = 0.0;          ///< ground-truth time span, seconds

  /// Time series for the report (seconds since the first ground truth).
  struct Sample {
    double t_s;
    Eigen::Vector3d p;
  };
  std::vector<Sample> leader_truth, leader_estimate, follower_truth;
  std::vector<std::pair<double, double>> localization_error_over_time;  ///< (t_s, |e| m)
  std::vector<std::pair<double, double>> formation_error_over_time;     ///< (t_s, horizontal |e| m)

  std::string report() const;  ///< lines for people
  std::string json() const;    ///< one JSON object
};

/// Reads the log and computes the errors. Throws std::runtime_error naming the file when it cannot be read or holds
/// no ground truth.
EvalResult evaluate_log(const EvalOptions& options);

/// A self-contained HTML page (inline SVG, no scripts, opens offline): top-down paths of leader truth, leader
/// estimate and follower, and the errors over time.
std::string eval_html_report(const EvalResult& result, const EvalOptions& options);

}  // namespace wingman::tools
