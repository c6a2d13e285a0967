// SPDX-License-Identifier: MIT
// `wingman model box-relation`: measures how a detector model's boxes relate to the target's bounding sphere on
// rendered images with known geometry, and writes the relation file the localizer reads (target.box_relation).
#pragma once

#include <wingman/localizer/box_relation.hpp>

#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace wingman::tools {

/// What to measure on, and with which detector.
struct BoxRelationRequest {
  /// A folder written by `wingman dataset synth` (images/<split>/*, meta/<split>/*.json with sphere_box).
  std::string data;
  std::string split = "val";
  /// The detector's process configuration (config/detector.yaml keys); "" = its built-in defaults, which are
  /// what `cmake --install` installs. Its model.* and detection.* keys decide the boxes measured.
  std::string detector_config;
  /// Which boxes: "single" (the single pass, with zoom-in as the detector configuration says: the relation's main
  /// grid) or "window" (each target searched as the tracker-driven windows search a tracked drone, a window on its
  /// outline box with 2 px of doubt, when the single pass would see it under windows.max_net_px network pixels; the
  /// window's boxes: the relation's window grid). Windows are searched whether or not the configuration enables them.
  std::string pass = "single";
  /// Fitting the window grid: the relation whose main grid, model and edge noise are kept (its window grid is
  /// replaced); it must have been measured for the same weights.
  std::string base = "builtin:wingman-small";
  /// Evaluate this relation ("sphere", "builtin:wingman-small" or a file) instead of fitting one.
  std::string check;
  /// Fitting: the relation file to write (required unless check is given).
  std::string out;
  /// The model's name written into the file (informative).
  std::string model_name = "wingman-small";
  /// Box-width bin edges (fraction of the image width) and aspect (h / w) bin edges of the fitted table.
  std::vector<double> size_edges = {0.004, 0.008, 0.016, 0.032, 0.064, 0.128, 0.256, 0.8};
  std::vector<double> aspect_edges = {0.05, 0.5, 0.75, 1.0, 1.5, 20.0};
  /// The window grid's box-width bin edges, image pixels (its aspect bins: aspect_edges).
  std::vector<double> window_size_edges = {4, 8, 11, 16, 22, 32, 45, 64, 128};
  /// Bins with fewer measured boxes are filled from their neighbours.
  int min_bin_count = 8;
  /// The frame-to-frame edge wander written into the file (BoxScale::edge_noise_rel; not measurable on single
  /// images).
  double edge_noise_rel = 0.1;
  /// A detection belongs to the target when its IoU with the target's outline box reaches this.
  double min_iou = 0.3;
  int max_images = 0;  ///< 0: all
  /// Also write every matched target as one CSV row here (airframe, true range, bounding and frame radius, the
  /// line of sight's elevation, the detected and sphere boxes, the ratios, the range error under the relation, the
  /// image and both boxes' centres); "" = none.
  std::string samples_csv;
  std::string command_line;  ///< written into the file as measured_with
};

/// The range error of the measured boxes under a relation, as range / true range - 1 (the localizer's exact method
/// with the true camera and the airframe's true bounding radius).
struct RangeErrorStats {
  int64_t n = 0;
  double median = 0;   ///< median relative error
  double mad = 0;      ///< 1.4826 x median absolute deviation
  double p90_abs = 0;  ///< 90th percentile of |error|
};

/// What a run measured.
struct BoxRelationSummary {
  int64_t images = 0, matched = 0, unmatched = 0, skipped_truncated = 0;
  /// pass "window": targets the windows would not search (the single pass sees them over windows.max_net_px)
  int64_t not_searched = 0;
  /// images without a drone (`wingman dataset synth`'s synth.negative_fraction): nothing to measure
  int64_t no_target = 0;
  /// Relative range error with the sphere relation (ratio 1: the radius taken as is) and with the relation
  /// fitted or checked, overall, per airframe and per true-range bin ("2-5 m", ..., "40+ m").
  RangeErrorStats sphere_all, relation_all;
  std::map<std::string, RangeErrorStats> sphere_by_airframe, relation_by_airframe, relation_by_range;
  std::string relation_name;
  /// The report as a Markdown table (what the verb prints).
  std::string markdown() const;
};

/// Runs the measurement (and with request.out set and no check, writes the fitted relation there).
/// Throws std::invalid_argument for bad options, std::runtime_error naming the file for unreadable data.
BoxRelationSummary run_box_relation(const BoxRelationRequest& request, std::ostream& progress);

}  // namespace wingman::tools
