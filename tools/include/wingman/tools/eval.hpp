// SPDX-License-Identifier: MIT
// `wingman eval`: localization, tracking, latency and box errors of a recorded flight against the simulator's truth.
#pragma once

#include <wingman/detection_t.hpp>
#include <wingman/truth_box_t.hpp>

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace wingman::tools {

/// What `wingman eval` reads and how it matches.
///
/// Every metric is computed from message utimes (simulated time), so it is the same on every run of the same log;
/// the only exception is latency, which is by nature wall-clock: it uses the log events' timestamps (the logger's
/// receive time).
struct EvalOptions {
  std::string log;  ///< LCM log with ground_truth_t and targets_t (and detections_t, image_t)
  std::string truth_channel = "GROUND_TRUTH";  ///< ground_truth_t channel
  std::string targets_channel = "TARGETS";     ///< targets_t channel
  /// detections_t channels: a POSIX extended regular expression a whole channel name must match
  /// (recorder::ChannelPattern, as lcm subscribes); the default takes every camera's (a rig's several cameras: each box
  /// is judged against its own camera's truth boxes).
  std::string detections_channel = "DETECTIONS_CAM[0-9]+";
  std::string image_channel = "IMAGE_CAM0";  ///< image_t channel (latency reference, report frames)
  /// The camera's monitoring preview (small JPEG image_t, 1 Hz: camera_driver/preview.hpp): the report's frames when
  /// the log has no full images (flight logs leave IMAGE_* out).
  std::string preview_channel = "PREVIEW_CAM0";
  int follower_id = 0;  ///< vehicle_truth_t.vehicle_id of the camera vehicle (the follower)
  int leader_id = 1;    ///< vehicle_truth_t.vehicle_id of the vehicle the formation is kept on
  /// Desired follower position minus leader position, world frame (ENU), metres; the z component is ignored when
  /// formation_height_m is set. Formation metrics are computed only when has_formation is true.
  Eigen::Vector3d formation_offset_in_world = Eigen::Vector3d::Zero();
  bool has_formation = false;
  double formation_height_m = -1.0;  ///< the follower's commanded constant height, metres; < 0: use the offset's z
  double settle_s = 5.0;             ///< formation metrics skip this long after the first ground truth, seconds
  double match_radius_m = 3.0;       ///< a world target farther than this from every truth vehicle is a false target
  /// Upper edges of the range bins, metres, strictly increasing and > 0: {5, 10} gives [0, 5), [5, 10), [10, inf).
  std::vector<double> range_bins_m = {5, 10, 15, 20, 30};
  std::string json_path;                 ///< write the result as JSON here ("" = no)
  std::string csv_path;                  ///< write the per-target time series as CSV here ("" = no)
  std::string report_path;               ///< the HTML report's file ("" = no): write_html_report (report.hpp)
  std::string title = "Wingman flight";  ///< report title
  int report_frames = 6;                 ///< the report shows up to this many camera frames (0 = none)
  /// Progress (percent of the log read, every few seconds) goes here; nullptr = quiet.
  std::ostream* progress = nullptr;
  /// Checks the options; one line per problem naming the option.
  std::vector<std::string> validate() const;
};

/// RMS, mean of the magnitude and maximum of a set of errors (metres, or the unit stated where used);
/// n = number of samples.
struct ErrorStats {
  int64_t n = 0;
  double rms = 0.0;
  double mean = 0.0;
  double max = 0.0;
};

/// Nearest-rank percentiles of a set of durations, milliseconds: pXX is the ceil(XX/100 * n)-th smallest value.
struct Percentiles {
  int64_t n = 0;
  double p50 = 0.0, p90 = 0.0, p99 = 0.0, max = 0.0;
};

/// Errors of the samples whose truth range lies in [lo_m, hi_m) (hi_m is infinity for the last bin).
struct RangeBin {
  double lo_m = 0.0;
  double hi_m = 0.0;
  ErrorStats error;
};

/// Detection of the leader in the ground-truth frames where its truth box is visible and its range lies in
/// [lo_m, hi_m) (hi_m is infinity for the last bin). A box is on the leader when box_on_leader() says so; every other
/// box of those frames is a false box.
struct DetectionBin {
  double lo_m = 0.0;
  double hi_m = 0.0;
  int64_t visible = 0;                ///< frames in which the leader's truth box is visible
  int64_t detected = 0;               ///< of those, frames with at least one box on the leader
  int64_t false_boxes = 0;            ///< boxes of those frames not on the leader
  int64_t frames_with_false_box = 0;  ///< of the visible frames, those with at least one false box
};

/// The measured errors of one flight.
struct EvalResult {
  std::string detection_source;  ///< "cnn", "ground_truth", "mixed" or "none" (from detections_t.source)
  /// Each detector's status channel -> its heartbeat's line on the backend that ran and why (the two backends' boxes
  /// differ in the 4th decimal, so a flight's figures are those of its backend); empty when none was logged.
  std::map<std::string, std::string> detector_backends;
  int64_t truth_frames = 0;           ///< ground_truth_t messages
  int64_t frames_leader_visible = 0;  ///< of those, frames in which the leader's truth box is visible
  /// Of those, frames with at least one box on the leader (box_on_leader()); a box elsewhere does not count.
  int64_t frames_leader_detected = 0;
  /// Boxes not on the leader (false boxes) in the frames where the leader is visible, and how many of those frames
  /// have at least one. The sums of detection_by_range's false_boxes and frames_with_false_box.
  int64_t false_boxes_leader_visible = 0;
  int64_t frames_leader_visible_with_false_box = 0;
  /// World-valid targets matched to a truth vehicle: one to one in each targets_t (a vehicle at most one target; a
  /// track keeps its vehicle while it stays within match_radius_m of it, the rest by increasing distance).
  int64_t target_estimates = 0;
  /// World-valid targets farther than match_radius_m from every truth vehicle but the follower (target samples).
  int64_t false_targets = 0;
  /// World-valid targets within match_radius_m of vehicles only that other targets of the same targets_t took (a
  /// second track on one drone, a neighbour's track passing near it): neither matched nor false.
  int64_t duplicate_targets = 0;
  double false_targets_per_s = 0.0;  ///< false_targets / duration_s
  int64_t false_track_ids = 0;       ///< distinct track ids among the false targets
  int64_t track_ids_on_leader = 0;   ///< distinct track ids matched to the leader
  /// Changes of the leader's track id: in each targets_t (log order) the target matched to the leader gives the id;
  /// every change from one message with a leader target to the next one with one counts.
  int64_t leader_id_switches = 0;
  /// Every truth vehicle but the follower that a world target was matched to, the leader included: distinct track
  /// ids and id switches, counted as for the leader (several targets: crossings keep or swap identities).
  struct VehicleIds {
    int64_t track_ids = 0;
    int64_t id_switches = 0;
  };
  std::map<int, VehicleIds> ids_by_vehicle;
  ErrorStats localization;                      ///< |p_est - p_truth|, 3-D, metres
  std::array<ErrorStats, 3> localization_axis;  ///< per world axis (x, y, z): RMS, mean |e|, max |e|
  ErrorStats along_line_of_sight;               ///< error component along the follower-to-target line
  ErrorStats across_line_of_sight;              ///< error perpendicular to that line
  /// |p_est - p_truth| binned by the true distance from the follower's centre to the matched vehicle's centre at the
  /// target's predicted_utime (EvalOptions::range_bins_m).
  std::vector<RangeBin> localization_by_range;
  ErrorStats formation_horizontal;  ///< follower position minus desired position, horizontal, after settle_s
  ErrorStats formation_vertical;    ///< the same, vertical
  double duration_s = 0.0;          ///< ground-truth time span, seconds
  /// Exposure to published target, ms: for each targets_t with targets, its log-event timestamp minus the earlier
  /// log-event timestamp of the image_t and the ground_truth_t whose utime is the newest source_utime among its
  /// targets (either one alone when the other is not in the log; no sample when neither is).
  Percentiles latency_ms;
  Percentiles inference_latency_ms;  ///< detections_t.inference_latency_us, ms
  /// Box-width error |w_det - w_truth| / image_width (a fraction of the image width): each detection matched to the
  /// leader's visible truth box at the same utime and camera (of the detections whose centre lies inside the truth
  /// box, the one with the nearest centre). Single-pass boxes (detection_t.pass_kind PASS_SINGLE) and re-detected ones
  /// (zoom-in or window) apart.
  ErrorStats box_width_single, box_width_zoom;
  /// Leader detection and false boxes by the leader's truth range (range_bins_m edges); the bins' visible and
  /// detected add up to frames_leader_visible and frames_leader_detected.
  std::vector<DetectionBin> detection_by_range;
  int64_t detections_outside_truth = 0;  ///< detected boxes whose centre lies in no visible truth box
  /// boxes of a class other than drone (class_id != 0: a multi-class model's airplane, bird, helicopter), which the
  /// localizer does not track: left out of every other count here (none of them is a detection or a false box)
  int64_t non_drone_boxes = 0;
  int64_t detections_total = 0;  ///< detected boxes in all detections_t
  int64_t detection_frames = 0;  ///< distinct utimes with a detections_t
  /// Boxes in all detections_t not on the leader (box_on_leader(); a box at a utime without ground truth is not on
  /// it), whether or not the leader is visible; includes detections_outside_truth.
  int64_t false_boxes = 0;
  int64_t frames_with_false_box = 0;  ///< of the detection_frames, those with at least one false box
  std::vector<RangeBin> box_width_single_by_range, box_width_zoom_by_range;  ///< the same, binned by truth box range

  /// Time series (seconds since the first ground truth).
  struct Sample {
    double t_s;
    Eigen::Vector3d p;
  };
  std::vector<Sample> leader_truth, leader_estimate, follower_truth;
  std::vector<std::pair<double, double>> localization_error_over_time;  ///< (t_s, |e| m), leader only
  std::vector<std::pair<double, double>> formation_error_over_time;     ///< (t_s, horizontal |e| m)
  /// One world-valid target of one targets_t (the CSV rows).
  struct TargetSample {
    double t_s;  ///< predicted_utime, seconds since the first ground truth
    int track_id;
    int vehicle_id;                  ///< matched truth vehicle, -1 = false target
    double range_m;                  ///< true follower-to-vehicle distance (matched), else target_t.range
    Eigen::Vector3d p_est, p_truth;  ///< world frame, metres; p_truth is NaN for a false target
    double error_m;                  ///< |p_est - p_truth|, NaN for a false target
    double range_est_m;              ///< target_t.range: the localizer's camera-to-target distance, metres
    double radius_m;                 ///< target_t.radius_m: the track's size estimate (bounding radius), metres
    double radius_sigma_m;           ///< target_t.radius_sigma_m: its standard deviation, metres (0: not estimated)
    int camera_id;                   ///< target_t.camera_id: the camera of the track's last detection
  };
  std::vector<TargetSample> targets;
  /// One matched detection's box width (the report's scatter).
  struct BoxWidthSample {
    double range_m;       ///< truth box range, metres
    double w_det_frac;    ///< detected width / image width
    double w_truth_frac;  ///< truth width / image width
    bool redetected;      ///< detection_t.pass_kind is not PASS_SINGLE (zoom-in or window)
  };
  std::vector<BoxWidthSample> box_widths;
  std::vector<double> latency_samples_ms;  ///< every latency sample (the report's histogram)
  /// What one camera frame (by utime) showed, for drawing the report's frames.
  struct FrameInfo {
    struct Box {
      float cx, cy, w, h;  ///< pixels of the source image
      int camera_id;
      bool flag;            ///< truth: visible; detection: re-detected (pass_kind not PASS_SINGLE)
      int vehicle_id = -1;  ///< truth: vehicle id; detection: -1
    };
    std::vector<Box> truth_boxes, detections;
    int image_width = 0;       ///< width of the source image the boxes are in (detections_t.image_width), 0 unknown
    int leader_track_id = -1;  ///< track id of the leader's matched target with this source_utime, -1 none
  };
  std::map<int64_t, FrameInfo> frames;  ///< by utime (ground truth and detections of camera 0)
  std::vector<int64_t> image_utimes;    ///< utimes of the image_t events on image_channel, log order
  std::vector<int64_t> preview_utimes;  ///< utimes of the image_t events on preview_channel, log order
  int64_t first_truth_utime = 0;        ///< t = 0 of the time series

  std::string report() const;  ///< lines for people
  std::string json() const;    ///< one JSON object
  std::string csv() const;     ///< per-target time series with a header line
};

/// True when the detection `box` of camera `camera_id` is on the leader: its centre lies inside (edges included) the
/// visible truth box of vehicle `leader_id` for that camera among `truth_boxes` (the ground truth of the box's utime).
/// The one criterion behind every leader-detection and false-box count of EvalResult.
bool box_on_leader(const wingman::detection_t& box, int camera_id, const std::vector<wingman::truth_box_t>& truth_boxes,
                   int leader_id);

/// Reads the log and computes the errors; writes json_path and csv_path when set. Throws std::invalid_argument
/// naming the option for bad options, std::runtime_error naming the file when it cannot be read or written or holds
/// no ground truth. report_path is the caller's to write, after this: write_html_report (report.hpp, which builds on
/// this header; nothing here depends on it).
EvalResult evaluate_log(const EvalOptions& options);

}  // namespace wingman::tools
