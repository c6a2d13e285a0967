// SPDX-License-Identifier: MIT
// `wingman eval`, reporting: EvalResult as lines for people, one JSON object and the per-target CSV.
#include "wingman/tools/eval.hpp"

#include <wingman/common/json.hpp>

#include <fmt/format.h>

#include <cmath>
#include <map>
#include <string>

namespace wingman::tools {
namespace {

/// One line of error statistics; values times `scale`, in `unit`.
std::string stats_line(const std::string& name, const ErrorStats& s, const char* unit = "m", double scale = 1.0) {
  if (s.n == 0) return fmt::format("  {:<34} no samples\n", name);
  return fmt::format("  {:<34} RMS {:7.3f} {u}   mean {:7.3f} {u}   max {:7.3f} {u}   (n = {})\n", name, s.rms * scale,
                     s.mean * scale, s.max * scale, s.n, fmt::arg("u", unit));
}

common::Json stats_json(const ErrorStats& s) {
  return {{"n", s.n}, {"rms_m", s.rms}, {"mean_m", s.mean}, {"max_m", s.max}};
}

common::Json fraction_json(const ErrorStats& s) {
  return {{"n", s.n}, {"rms", s.rms}, {"mean", s.mean}, {"max", s.max}};
}

common::Json percentiles_json(const Percentiles& p) {
  return {{"n", p.n}, {"p50_ms", p.p50}, {"p90_ms", p.p90}, {"p99_ms", p.p99}, {"max_ms", p.max}};
}

/// A bin's upper edge; null for the last, open bin.
common::Json hi_json(double hi_m) { return std::isinf(hi_m) ? common::Json(nullptr) : common::Json(hi_m); }

std::string bin_name(const RangeBin& b) {
  return std::isinf(b.hi_m) ? fmt::format("{:g}+ m", b.lo_m) : fmt::format("{:g}-{:g} m", b.lo_m, b.hi_m);
}

common::Json bins_json(const std::vector<RangeBin>& bins, bool fraction) {
  common::Json j = common::Json::array();
  for (const auto& b : bins)
    j.push_back({{"lo_m", b.lo_m},
                 {"hi_m", hi_json(b.hi_m)},
                 {"error", fraction ? fraction_json(b.error) : stats_json(b.error)}});
  return j;
}

common::Json detection_bins_json(const std::vector<DetectionBin>& bins) {
  common::Json j = common::Json::array();
  for (const auto& b : bins)
    j.push_back({{"lo_m", b.lo_m},
                 {"hi_m", hi_json(b.hi_m)},
                 {"visible", b.visible},
                 {"detected", b.detected},
                 {"false_boxes", b.false_boxes},
                 {"frames_with_false_box", b.frames_with_false_box}});
  return j;
}

}  // namespace

std::string EvalResult::report() const {
  std::string s;
  s += fmt::format(
      "flight: {:.1f} s of ground truth ({} frames); detections from {}\n", duration_s, truth_frames,
      detection_source == "ground_truth" ? "GROUND TRUTH (simulated boxes, no detector model)" : detection_source);
  for (const auto& [channel, line] : detector_backends) s += fmt::format("detector ({}): {}\n", channel, line);
  const auto percent = [](int64_t part, int64_t whole) {
    return whole > 0 ? 100.0 * static_cast<double>(part) / static_cast<double>(whole) : 0.0;
  };
  s += fmt::format(
      "leader detected in {} of {} frames where it is visible ({:.1f} %; a box centred in its truth box), "
      "{} false box(es) in {} of those frames\n",
      frames_leader_detected, frames_leader_visible, percent(frames_leader_detected, frames_leader_visible),
      false_boxes_leader_visible, frames_leader_visible_with_false_box);
  s += fmt::format(
      "detected boxes: {} in {} frames with a detections_t; {} not on the leader (false boxes) in {} frames, "
      "{} of them centred in no visible truth box; {} box(es) of other classes (not drones: not counted)\n",
      detections_total, detection_frames, false_boxes, frames_with_false_box, detections_outside_truth,
      non_drone_boxes);
  for (const auto& b : detection_by_range) {
    if (b.visible == 0) continue;
    s += fmt::format("  leader detected at range {:<12} {:6.1f} % of {} frames ({}), {} false box(es) in {} frames\n",
                     bin_name(RangeBin{b.lo_m, b.hi_m, {}}), percent(b.detected, b.visible), b.visible, b.detected,
                     b.false_boxes, b.frames_with_false_box);
  }
  s += fmt::format("world targets: {} matched, {} false{}; {} track id(s) on the leader, {} id switch(es)\n",
                   target_estimates, false_targets,
                   duplicate_targets > 0
                       ? fmt::format(", {} duplicate (near a vehicle another target took)", duplicate_targets)
                       : "",
                   track_ids_on_leader, leader_id_switches);
  s += fmt::format("false tracks: {:.3f} false targets per second, {} distinct false track id(s)\n",
                   false_targets_per_s, false_track_ids);
  if (ids_by_vehicle.size() > 1) {  // several targets: each one's identities
    std::string line;
    for (const auto& [vehicle, v] : ids_by_vehicle)
      line += fmt::format("{}vehicle {}: {} id(s), {} switch(es)", line.empty() ? "" : "; ", vehicle, v.track_ids,
                          v.id_switches);
    s += "track ids per vehicle: " + line + "\n";
  }
  s += "localization error (estimate - truth):\n";
  s += stats_line("3-D", localization);
  s += stats_line("x (east)", localization_axis[0]);
  s += stats_line("y (north)", localization_axis[1]);
  s += stats_line("z (up)", localization_axis[2]);
  s += stats_line("along the line of sight", along_line_of_sight);
  s += stats_line("across the line of sight", across_line_of_sight);
  s += "localization error by true range:\n";
  for (const auto& b : localization_by_range) s += stats_line("range " + bin_name(b), b.error);
  if (formation_horizontal.n > 0) {
    s += "formation error (follower - desired position):\n";
    s += stats_line("horizontal", formation_horizontal);
    s += stats_line("vertical", formation_vertical);
  }
  const auto pct = [](const char* name, const Percentiles& p) {
    if (p.n == 0) return fmt::format("  {:<34} no samples\n", name);
    return fmt::format("  {:<34} p50 {:7.2f} ms   p90 {:7.2f} ms   p99 {:7.2f} ms   max {:7.2f} ms   (n = {})\n", name,
                       p.p50, p.p90, p.p99, p.max, p.n);
  };
  s += "latency (log-event timestamps, wall clock):\n";
  s += pct("exposure to published target", latency_ms);
  s += pct("detector inference", inference_latency_ms);
  s += "box-width error |w_det - w_truth| / image width, in % of the width:\n";
  s += stats_line("single pass", box_width_single, "%", 100.0);
  for (const auto& b : box_width_single_by_range)
    if (b.error.n > 0) s += stats_line("  range " + bin_name(b), b.error, "%", 100.0);
  s += stats_line("zoom-in or window", box_width_zoom, "%", 100.0);
  for (const auto& b : box_width_zoom_by_range)
    if (b.error.n > 0) s += stats_line("  range " + bin_name(b), b.error, "%", 100.0);
  return s;
}

namespace {
/// {"<vehicle id>": {"track_ids": n, "id_switches": n}, ...}
common::Json ids_json(const std::map<int, EvalResult::VehicleIds>& ids) {
  common::Json j = common::Json::object();
  for (const auto& [vehicle, v] : ids)
    j[std::to_string(vehicle)] = {{"track_ids", v.track_ids}, {"id_switches", v.id_switches}};
  return j;
}
}  // namespace

std::string EvalResult::json() const {
  common::Json j;
  j["detection_source"] = detection_source;
  j["detector_backends"] = common::Json::object();
  for (const auto& [channel, line] : detector_backends) j["detector_backends"][channel] = line;
  j["duration_s"] = duration_s;
  j["truth_frames"] = truth_frames;
  j["frames_leader_visible"] = frames_leader_visible;
  j["frames_leader_detected"] = frames_leader_detected;
  j["false_boxes_leader_visible"] = false_boxes_leader_visible;
  j["frames_leader_visible_with_false_box"] = frames_leader_visible_with_false_box;
  j["target_estimates"] = target_estimates;
  j["false_targets"] = false_targets;
  j["duplicate_targets"] = duplicate_targets;
  j["false_targets_per_s"] = false_targets_per_s;
  j["false_track_ids"] = false_track_ids;
  j["track_ids_on_leader"] = track_ids_on_leader;
  j["leader_id_switches"] = leader_id_switches;
  j["ids_by_vehicle"] = ids_json(ids_by_vehicle);
  j["localization"] = stats_json(localization);
  j["localization_x"] = stats_json(localization_axis[0]);
  j["localization_y"] = stats_json(localization_axis[1]);
  j["localization_z"] = stats_json(localization_axis[2]);
  j["along_line_of_sight"] = stats_json(along_line_of_sight);
  j["across_line_of_sight"] = stats_json(across_line_of_sight);
  j["localization_by_range"] = bins_json(localization_by_range, false);
  j["formation_horizontal"] = stats_json(formation_horizontal);
  j["formation_vertical"] = stats_json(formation_vertical);
  j["latency"] = percentiles_json(latency_ms);
  j["inference_latency"] = percentiles_json(inference_latency_ms);
  j["box_width_single"] = fraction_json(box_width_single);
  j["box_width_zoom"] = fraction_json(box_width_zoom);
  j["box_width_single_by_range"] = bins_json(box_width_single_by_range, true);
  j["box_width_zoom_by_range"] = bins_json(box_width_zoom_by_range, true);
  j["detection_by_range"] = detection_bins_json(detection_by_range);
  j["detections_total"] = detections_total;
  j["detections_outside_truth"] = detections_outside_truth;
  j["detection_frames"] = detection_frames;
  j["false_boxes"] = false_boxes;
  j["frames_with_false_box"] = frames_with_false_box;
  j["non_drone_boxes"] = non_drone_boxes;
  return common::json_text(j);
}

std::string EvalResult::csv() const {
  std::string s =
      "t_s,track_id,vehicle_id,range_m,est_x,est_y,est_z,truth_x,truth_y,truth_z,error_m,range_est_m,radius_m,"
      "radius_sigma_m,camera_id\n";
  const auto num = [](double v) { return std::isnan(v) ? std::string() : fmt::format("{:.4f}", v); };
  for (const auto& t : targets) {
    s += fmt::format("{:.6f},{},{},{:.4f},{:.4f},{:.4f},{:.4f},{},{},{},{},{:.4f},{:.4f},{:.4f},{}\n", t.t_s,
                     t.track_id, t.vehicle_id, t.range_m, t.p_est.x(), t.p_est.y(), t.p_est.z(), num(t.p_truth.x()),
                     num(t.p_truth.y()), num(t.p_truth.z()), num(t.error_m), t.range_est_m, t.radius_m,
                     t.radius_sigma_m, t.camera_id);
  }
  return s;
}

}  // namespace wingman::tools
