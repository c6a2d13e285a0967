// SPDX-License-Identifier: MIT
// `wingman eval`: matches localized targets to simulator ground truth by utime and measures the errors.
#include "wingman/tools/eval.hpp"

#include "lcm_fingerprint.hpp"

#include <wingman/common/message_validation.hpp>
#include <wingman/detections_t.hpp>
#include <wingman/ground_truth_t.hpp>
#include <wingman/targets_t.hpp>

#include <fmt/format.h>
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace wingman::tools {
namespace {

/// Decodes and validates `ev` as Msg; false (counted by the caller) when it is not one or is malformed.
template <class Msg>
bool decode(const lcm::LogEvent& ev, Msg* m) {
  if (lcm_fingerprint(ev.data, ev.datalen) != static_cast<uint64_t>(Msg::getHash())) return false;
  if (m->decode(ev.data, 0, ev.datalen) < 0) return false;
  return common::validate_message(*m).empty();
}

/// Positions of one vehicle over time, linearly interpolated.
struct Track {
  std::vector<int64_t> utime;
  std::vector<Eigen::Vector3d> p;
  /// Position at `t`; false when t is outside the recorded span.
  bool at(int64_t t, Eigen::Vector3d* out) const {
    if (utime.empty() || t < utime.front() || t > utime.back()) return false;
    const auto it = std::lower_bound(utime.begin(), utime.end(), t);
    const size_t i = static_cast<size_t>(it - utime.begin());
    if (utime[i] == t || i == 0) {
      *out = p[i];
      return true;
    }
    const double a = static_cast<double>(t - utime[i - 1]) / static_cast<double>(utime[i] - utime[i - 1]);
    *out = (1.0 - a) * p[i - 1] + a * p[i];
    return true;
  }
};

/// Accumulates error magnitudes.
struct Acc {
  int64_t n = 0;
  double sum = 0, sum_sq = 0, max = 0;
  void add(double e) {
    e = std::abs(e);
    ++n;
    sum += e;
    sum_sq += e * e;
    max = std::max(max, e);
  }
  ErrorStats stats() const {
    ErrorStats s;
    s.n = n;
    if (n > 0) {
      s.rms = std::sqrt(sum_sq / static_cast<double>(n));
      s.mean = sum / static_cast<double>(n);
      s.max = max;
    }
    return s;
  }
};

std::string stats_line(const char* name, const ErrorStats& s) {
  if (s.n == 0) return fmt::format("  {:<34} no samples\n", name);
  return fmt::format("  {:<34} RMS {:7.3f} m   mean {:7.3f} m   max {:7.3f} m   (n = {})\n", name, s.rms, s.mean, s.max,
                     s.n);
}

std::string stats_json(const ErrorStats& s) {
  return fmt::format("{{\"n\": {}, \"rms_m\": {:.6f}, \"mean_m\": {:.6f}, \"max_m\": {:.6f}}}", s.n, s.rms, s.mean,
                     s.max);
}

std::string escape_html(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '&':
        o += "&amp;";
        break;
      case '"':
        o += "&quot;";
        break;
      default:
        o += c;
    }
  }
  return o;
}

}  // namespace

std::vector<std::string> EvalOptions::validate() const {
  std::vector<std::string> p;
  if (log.empty()) p.push_back("log: an LCM log file is required");
  if (truth_channel.empty()) p.push_back("--truth-channel: must not be empty");
  if (targets_channel.empty()) p.push_back("--targets-channel: must not be empty");
  if (!(settle_s >= 0.0)) p.push_back(fmt::format("--settle: {} must be >= 0 seconds", settle_s));
  if (!(match_radius_m > 0.0)) p.push_back(fmt::format("--match-radius: {} must be > 0 metres", match_radius_m));
  if (follower_id == leader_id) p.push_back(fmt::format("--leader-id: {} must differ from --follower-id", leader_id));
  if (!formation_offset_in_world.allFinite()) p.push_back("--formation-offset: must be three finite numbers");
  return p;
}

EvalResult evaluate_log(const EvalOptions& o) {
  if (const auto problems = o.validate(); !problems.empty()) {
    std::string all;
    for (const auto& s : problems) all += (all.empty() ? "" : "; ") + s;
    throw std::invalid_argument("wingman eval: " + all);
  }
  std::ifstream probe(o.log, std::ios::binary);
  if (!probe) throw std::runtime_error("wingman eval: cannot read the log '" + o.log + "'");
  probe.close();
  lcm::LogFile file(o.log, "r");
  if (!file.good()) throw std::runtime_error("wingman eval: cannot open the LCM log '" + o.log + "'");

  std::map<int, Track> truth;                                    // vehicle id -> positions
  std::map<int64_t, bool> leader_visible;                        // truth utime -> leader box visible
  std::map<int64_t, int> detections_at;                          // detections utime -> number of boxes
  std::vector<std::pair<int64_t, wingman::target_t>> estimates;  // (predicted utime, target)
  std::set<int> sources;
  EvalResult r;

  while (const lcm::LogEvent* ev = file.readNextEvent()) {
    if (ev->channel == o.truth_channel) {
      wingman::ground_truth_t g;
      if (!decode(*ev, &g)) continue;
      ++r.truth_frames;
      for (const auto& v : g.vehicles) {
        Track& t = truth[v.vehicle_id];
        if (!t.utime.empty() && g.utime <= t.utime.back()) continue;  // keep times strictly increasing
        t.utime.push_back(g.utime);
        t.p.emplace_back(v.p_body_in_world[0], v.p_body_in_world[1], v.p_body_in_world[2]);
      }
      bool visible = false;
      for (const auto& b : g.boxes) visible = visible || (b.vehicle_id == o.leader_id && b.visible);
      leader_visible[g.utime] = visible;
    } else if (ev->channel == o.targets_channel) {
      wingman::targets_t ts;
      if (!decode(*ev, &ts)) continue;
      for (const auto& t : ts.targets) {
        if (t.world_valid) estimates.emplace_back(t.predicted_utime, t);
      }
    } else if (ev->channel == o.detections_channel) {
      wingman::detections_t d;
      if (!decode(*ev, &d)) continue;
      sources.insert(d.source);
      detections_at[d.utime] += d.num_detections;
    }
  }
  if (truth.empty()) {
    throw std::runtime_error("wingman eval: '" + o.log + "' holds no ground_truth_t on channel " + o.truth_channel);
  }
  if (sources.empty()) {
    r.detection_source = "none";
  } else if (sources.size() > 1) {
    r.detection_source = "mixed";
  } else {
    r.detection_source = *sources.begin() == wingman::detections_t::SOURCE_GROUND_TRUTH ? "ground_truth" : "cnn";
  }

  int64_t t0 = INT64_MAX, t1 = INT64_MIN;
  for (const auto& [id, t] : truth) {
    t0 = std::min(t0, t.utime.front());
    t1 = std::max(t1, t.utime.back());
  }
  r.duration_s = static_cast<double>(t1 - t0) * 1e-6;
  const auto secs = [t0](int64_t u) { return static_cast<double>(u - t0) * 1e-6; };

  for (const auto& [u, vis] : leader_visible) {
    if (!vis) continue;
    ++r.frames_leader_visible;
    const auto it = detections_at.find(u);
    if (it != detections_at.end() && it->second > 0) ++r.frames_leader_detected;
  }

  // Localization: each world target against the nearest truth vehicle (not the follower) at its time.
  Acc all, los_along, los_across;
  std::array<Acc, 3> axis;
  std::set<int> leader_tracks;
  const Track* follower = truth.count(o.follower_id) ? &truth.at(o.follower_id) : nullptr;
  for (const auto& [u, t] : estimates) {
    const Eigen::Vector3d p_est(t.p_target_in_world[0], t.p_target_in_world[1], t.p_target_in_world[2]);
    int best_id = -1;
    double best = o.match_radius_m;
    Eigen::Vector3d best_p;
    for (const auto& [id, tr] : truth) {
      if (id == o.follower_id) continue;
      Eigen::Vector3d p;
      if (!tr.at(u, &p)) continue;
      const double d = (p - p_est).norm();
      if (d <= best) {
        best = d;
        best_id = id;
        best_p = p;
      }
    }
    if (best_id < 0) {
      ++r.false_targets;
      continue;
    }
    ++r.target_estimates;
    const Eigen::Vector3d e = p_est - best_p;
    all.add(e.norm());
    for (int k = 0; k < 3; ++k) axis[k].add(e[k]);
    Eigen::Vector3d p_f;
    if (follower && follower->at(u, &p_f) && (best_p - p_f).norm() > 1e-6) {
      const Eigen::Vector3d los = (best_p - p_f).normalized();
      const double along = e.dot(los);
      los_along.add(along);
      los_across.add((e - along * los).norm());
    }
    if (best_id == o.leader_id) {
      leader_tracks.insert(t.track_id);
      r.leader_estimate.push_back({secs(u), p_est});
      r.localization_error_over_time.emplace_back(secs(u), e.norm());
    }
  }
  r.localization = all.stats();
  for (int k = 0; k < 3; ++k) r.localization_axis[k] = axis[k].stats();
  r.along_line_of_sight = los_along.stats();
  r.across_line_of_sight = los_across.stats();
  r.track_ids_on_leader = static_cast<int64_t>(leader_tracks.size());

  // Paths and formation error at every ground-truth time.
  const Track* leader = truth.count(o.leader_id) ? &truth.at(o.leader_id) : nullptr;
  Acc fh, fv;
  if (follower) {
    for (size_t i = 0; i < follower->utime.size(); ++i) {
      const int64_t u = follower->utime[i];
      r.follower_truth.push_back({secs(u), follower->p[i]});
      Eigen::Vector3d p_l;
      if (!leader || !leader->at(u, &p_l)) continue;
      r.leader_truth.push_back({secs(u), p_l});
      if (!o.has_formation || secs(u) < o.settle_s) continue;
      Eigen::Vector3d p_des = p_l + o.formation_offset_in_world;
      if (o.formation_height_m >= 0.0) p_des.z() = o.formation_height_m;
      const Eigen::Vector3d e = follower->p[i] - p_des;
      fh.add(e.head<2>().norm());
      fv.add(e.z());
      r.formation_error_over_time.emplace_back(secs(u), e.head<2>().norm());
    }
  }
  r.formation_horizontal = fh.stats();
  r.formation_vertical = fv.stats();

  if (!o.json_path.empty()) {
    std::ofstream f(o.json_path);
    f << r.json() << "\n";
    if (!f) throw std::runtime_error("wingman eval: cannot write '" + o.json_path + "'");
  }
  if (!o.report_path.empty()) {
    std::ofstream f(o.report_path);
    f << eval_html_report(r, o);
    if (!f) throw std::runtime_error("wingman eval: cannot write '" + o.report_path + "'");
  }
  return r;
}

std::string EvalResult::report() const {
  std::string s;
  s += fmt::format(
      "flight: {:.1f} s of ground truth ({} frames); detections from {}\n", duration_s, truth_frames,
      detection_source == "ground_truth" ? "GROUND TRUTH (simulated boxes, no detector model)" : detection_source);
  s += fmt::format("leader detected in {} of {} frames where it is visible ({:.1f} %)\n", frames_leader_detected,
                   frames_leader_visible,
                   frames_leader_visible ? 100.0 * static_cast<double>(frames_leader_detected) /
                                               static_cast<double>(frames_leader_visible)
                                         : 0.0);
  s += fmt::format("world targets: {} matched, {} false; {} track id(s) on the leader\n", target_estimates,
                   false_targets, track_ids_on_leader);
  s += "localization error (estimate - truth):\n";
  s += stats_line("3-D", localization);
  s += stats_line("x (east)", localization_axis[0]);
  s += stats_line("y (north)", localization_axis[1]);
  s += stats_line("z (up)", localization_axis[2]);
  s += stats_line("along the line of sight", along_line_of_sight);
  s += stats_line("across the line of sight", across_line_of_sight);
  if (formation_horizontal.n > 0) {
    s += "formation error (follower - desired position):\n";
    s += stats_line("horizontal", formation_horizontal);
    s += stats_line("vertical", formation_vertical);
  }
  return s;
}

std::string EvalResult::json() const {
  return fmt::format(
      "{{\"detection_source\": \"{}\", \"duration_s\": {:.3f}, \"truth_frames\": {}, \"frames_leader_visible\": {}, "
      "\"frames_leader_detected\": {}, \"target_estimates\": {}, \"false_targets\": {}, \"track_ids_on_leader\": {}, "
      "\"localization\": {}, \"localization_x\": {}, \"localization_y\": {}, \"localization_z\": {}, "
      "\"along_line_of_sight\": {}, \"across_line_of_sight\": {}, \"formation_horizontal\": {}, "
      "\"formation_vertical\": {}}}",
      detection_source, duration_s, truth_frames, frames_leader_visible, frames_leader_detected, target_estimates,
      false_targets, track_ids_on_leader, stats_json(localization), stats_json(localization_axis[0]),
      stats_json(localization_axis[1]), stats_json(localization_axis[2]), stats_json(along_line_of_sight),
      stats_json(across_line_of_sight), stats_json(formation_horizontal), stats_json(formation_vertical));
}

namespace {

/// A chart area mapping data coordinates to SVG pixels.
struct Frame {
  double x0, x1, y0, y1;  // data range
  double w, h, pad;       // pixels
  double sx(double x) const { return pad + (x - x0) / (x1 - x0) * (w - 2 * pad); }
  double sy(double y) const { return h - pad - (y - y0) / (y1 - y0) * (h - 2 * pad); }
};

std::string polyline(const Frame& f, const std::vector<std::pair<double, double>>& pts, const char* colour,
                     double width, const char* dash = "") {
  if (pts.empty()) return "";
  std::string s = fmt::format(R"(<polyline fill="none" stroke="{}" stroke-width="{}" stroke-dasharray="{}" points=")",
                              colour, width, dash);
  for (const auto& [x, y] : pts) s += fmt::format("{:.1f},{:.1f} ", f.sx(x), f.sy(y));
  return s + "\"/>\n";
}

std::string axes(const Frame& f, const std::string& xlabel, const std::string& ylabel) {
  std::string s = fmt::format(R"(<rect x="{}" y="{}" width="{}" height="{}" fill="#fbfbfb" stroke="#999"/>)", f.pad,
                              f.pad, f.w - 2 * f.pad, f.h - 2 * f.pad);
  for (int i = 0; i <= 4; ++i) {
    const double x = f.x0 + (f.x1 - f.x0) * i / 4.0, y = f.y0 + (f.y1 - f.y0) * i / 4.0;
    s += fmt::format(R"(<text x="{:.1f}" y="{:.1f}" font-size="11" text-anchor="middle">{:.1f}</text>)", f.sx(x),
                     f.h - f.pad + 14, x);
    s += fmt::format(R"(<text x="{:.1f}" y="{:.1f}" font-size="11" text-anchor="end">{:.1f}</text>)", f.pad - 4,
                     f.sy(y) + 4, y);
  }
  s += fmt::format(R"(<text x="{:.1f}" y="{:.1f}" font-size="12" text-anchor="middle">{}</text>)", f.w / 2, f.h - 4,
                   xlabel);
  s += fmt::format(R"svg(<text x="12" y="{:.1f}" font-size="12" transform="rotate(-90 12 {:.1f})" )svg"
                   R"(text-anchor="middle">{}</text>)",
                   f.h / 2, f.h / 2, ylabel);
  return s + "\n";
}

}  // namespace

std::string eval_html_report(const EvalResult& r, const EvalOptions& o) {
  // Top-down view with equal axis scales.
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (const auto* v : {&r.leader_truth, &r.leader_estimate, &r.follower_truth}) {
    for (const auto& s : *v) {
      x0 = std::min(x0, s.p.x());
      x1 = std::max(x1, s.p.x());
      y0 = std::min(y0, s.p.y());
      y1 = std::max(y1, s.p.y());
    }
  }
  if (x0 > x1) x0 = -1, x1 = 1, y0 = -1, y1 = 1;
  const double span = std::max({x1 - x0, y1 - y0, 2.0}) * 1.1;
  const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
  const Frame top{cx - span / 2, cx + span / 2, cy - span / 2, cy + span / 2, 560, 560, 48};
  const auto xy = [](const std::vector<EvalResult::Sample>& v) {
    std::vector<std::pair<double, double>> o;
    for (const auto& s : v) o.emplace_back(s.p.x(), s.p.y());
    return o;
  };
  std::string svg_top =
      fmt::format(R"(<svg id="topdown" xmlns="http://www.w3.org/2000/svg" width="{}" height="{}">)", top.w, top.h);
  svg_top += axes(top, "x (east), m", "y (north), m");
  svg_top += polyline(top, xy(r.leader_truth), "#1f77b4", 2.0);
  svg_top += polyline(top, xy(r.follower_truth), "#2ca02c", 2.0);
  for (const auto& s : r.leader_estimate) {
    svg_top += fmt::format(R"(<circle cx="{:.1f}" cy="{:.1f}" r="1.6" fill="#d62728" fill-opacity="0.5"/>)",
                           top.sx(s.p.x()), top.sy(s.p.y()));
  }
  svg_top += "</svg>";

  double tmax = std::max(r.duration_s, 1.0), emax = 0.5;
  for (const auto& [t, e] : r.localization_error_over_time) emax = std::max(emax, e);
  for (const auto& [t, e] : r.formation_error_over_time) emax = std::max(emax, e);
  const Frame ef{0.0, tmax, 0.0, emax * 1.1, 720, 300, 48};
  std::string svg_err =
      fmt::format(R"(<svg id="errors" xmlns="http://www.w3.org/2000/svg" width="{}" height="{}">)", ef.w, ef.h);
  svg_err += axes(ef, "time, s", "error, m");
  svg_err += polyline(ef, r.localization_error_over_time, "#d62728", 1.2);
  svg_err += polyline(ef, r.formation_error_over_time, "#2ca02c", 1.5);
  svg_err += "</svg>";

  std::string html = "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>" + escape_html(o.title) +
                     "</title>\n<style>body{font-family:sans-serif;margin:24px;color:#222} pre{background:#f4f4f4;"
                     "padding:12px} .k{display:inline-block;width:14px;height:4px;margin:0 6px 3px 12px}</style>"
                     "</head><body>\n";
  html += "<h1>" + escape_html(o.title) + "</h1>\n";
  if (r.detection_source == "ground_truth") {
    html +=
        "<p><b>Detections came from simulator ground truth</b> (no trained detector model was used): these "
        "numbers measure localization, tracking and control, not detection.</p>\n";
  }
  html += "<p>Log: <code>" + escape_html(o.log) + "</code></p>\n<pre>" + escape_html(r.report()) + "</pre>\n";
  html +=
      "<h2>Top-down view</h2><p><span class=\"k\" style=\"background:#1f77b4\"></span>leader truth"
      "<span class=\"k\" style=\"background:#d62728\"></span>leader estimate"
      "<span class=\"k\" style=\"background:#2ca02c\"></span>follower</p>\n" +
      svg_top + "\n";
  html +=
      "<h2>Errors over time</h2><p><span class=\"k\" style=\"background:#d62728\"></span>localization |e|"
      "<span class=\"k\" style=\"background:#2ca02c\"></span>formation, horizontal</p>\n" +
      svg_err + "\n</body></html>\n";
  return html;
}

}  // namespace wingman::tools
