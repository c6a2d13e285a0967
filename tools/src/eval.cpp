// SPDX-License-Identifier: MIT
// `wingman eval`: matches localized targets to simulator ground truth by utime and measures the errors.
#include "wingman/tools/eval.hpp"

#include "lcm_fingerprint.hpp"
#include "log_progress.hpp"
#include "wingman/tools/report.hpp"

#include <wingman/common/json.hpp>
#include <wingman/common/lcm_log_reader.hpp>
#include <wingman/common/message_validation.hpp>
#include <wingman/detections_t.hpp>
#include <wingman/ground_truth_t.hpp>
#include <wingman/image_t.hpp>
#include <wingman/targets_t.hpp>

#include <fmt/format.h>
#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

namespace wingman::tools {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// Decodes and validates `ev` as Msg; false (counted by the caller) when it is not one or is malformed.
template <class Msg>
bool decode(const common::LcmLogEvent& ev, Msg* m) {
  if (lcm_fingerprint(ev.data, ev.datalen) != static_cast<uint64_t>(Msg::getHash())) return false;
  if (m->decode(ev.data, 0, ev.datalen) < 0) return false;
  return common::validate_message(*m).empty();
}

/// The utime of an image_t event without decoding its pixels (right after the fingerprint, big-endian); nullopt when
/// the event is not an image_t.
std::optional<int64_t> image_utime(const common::LcmLogEvent& ev) {
  if (ev.datalen < 16 || lcm_fingerprint(ev.data, ev.datalen) != static_cast<uint64_t>(wingman::image_t::getHash()))
    return std::nullopt;
  const auto* p = static_cast<const uint8_t*>(ev.data) + 8;
  uint64_t u = 0;
  for (int i = 0; i < 8; ++i) u = (u << 8) | p[i];
  return static_cast<int64_t>(u);
}

/// Index of the range bin of `range` (upper edges `edges`; the last bin is open).
size_t range_bin(const std::vector<double>& edges, double range) {
  return static_cast<size_t>(std::upper_bound(edges.begin(), edges.end(), range) - edges.begin());
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

/// Accumulators per range bin (upper edges `edges`; the last bin is open).
struct BinnedAcc {
  std::vector<double> edges;
  std::vector<Acc> acc;
  explicit BinnedAcc(std::vector<double> e) : edges(std::move(e)), acc(edges.size() + 1) {}
  void add(double range, double e) { acc[range_bin(edges, range)].add(e); }
  std::vector<RangeBin> bins() const {
    std::vector<RangeBin> out;
    for (size_t i = 0; i < acc.size(); ++i) {
      out.push_back({i == 0 ? 0.0 : edges[i - 1], i < edges.size() ? edges[i] : kInf, acc[i].stats()});
    }
    return out;
  }
};

/// Nearest-rank percentiles of `v` (sorted here).
Percentiles percentiles(std::vector<double> v) {
  Percentiles p;
  p.n = static_cast<int64_t>(v.size());
  if (v.empty()) return p;
  std::sort(v.begin(), v.end());
  const auto rank = [&](double q) {
    const auto k = static_cast<size_t>(std::ceil(q * static_cast<double>(v.size())));
    return v[std::clamp<size_t>(k, 1, v.size()) - 1];
  };
  p.p50 = rank(0.50);
  p.p90 = rank(0.90);
  p.p99 = rank(0.99);
  p.max = v.back();
  return p;
}

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

/// True when the centre of `b` lies inside `tb` (edges included); cameras and visibility are the caller's to check.
bool centred_in(const wingman::detection_t& b, const wingman::truth_box_t& tb) {
  return std::abs(b.cx - tb.cx) <= 0.5 * tb.w && std::abs(b.cy - tb.cy) <= 0.5 * tb.h;
}

}  // namespace

bool box_on_leader(const wingman::detection_t& box, int camera_id, const std::vector<wingman::truth_box_t>& truth_boxes,
                   int leader_id) {
  return std::any_of(truth_boxes.begin(), truth_boxes.end(), [&](const wingman::truth_box_t& tb) {
    return tb.vehicle_id == leader_id && tb.camera_id == camera_id && tb.visible && centred_in(box, tb);
  });
}

std::vector<std::string> EvalOptions::validate() const {
  std::vector<std::string> p;
  if (log.empty()) p.push_back("log: an LCM log file is required");
  if (truth_channel.empty()) p.push_back("--truth-channel: must not be empty");
  if (targets_channel.empty()) p.push_back("--targets-channel: must not be empty");
  if (!(settle_s >= 0.0)) p.push_back(fmt::format("--settle: {} must be >= 0 seconds", settle_s));
  if (!(match_radius_m > 0.0)) p.push_back(fmt::format("--match-radius: {} must be > 0 metres", match_radius_m));
  if (follower_id == leader_id) p.push_back(fmt::format("--leader-id: {} must differ from --follower-id", leader_id));
  if (!formation_offset_in_world.allFinite()) p.push_back("--formation-offset: must be three finite numbers");
  for (size_t i = 0; i < range_bins_m.size(); ++i) {
    const double e = range_bins_m[i];
    if (!std::isfinite(e) || e <= 0.0 || (i > 0 && e <= range_bins_m[i - 1])) {
      p.push_back(
          fmt::format("--range-bins: {} (entry {}) must be finite, > 0 and greater than the one before it", e, i + 1));
      break;
    }
  }
  if (report_frames < 0) p.push_back(fmt::format("--frames: {} must be >= 0", report_frames));
  return p;
}

EvalResult evaluate_log(const EvalOptions& o) {
  if (const auto problems = o.validate(); !problems.empty()) {
    std::string all;
    for (const auto& s : problems) all += (all.empty() ? "" : "; ") + s;
    throw std::invalid_argument("wingman eval: " + all);
  }
  if (std::filesystem::is_directory(o.log))
    throw std::runtime_error("wingman eval: the log '" + o.log + "' is a directory");
  std::ifstream probe(o.log, std::ios::binary);
  if (!probe) throw std::runtime_error("wingman eval: cannot read the log '" + o.log + "'");
  probe.close();
  common::LcmLogReader file(o.log);  // a corrupt event throws, naming its byte offset

  struct Estimate {
    int64_t utime;   // predicted_utime
    size_t message;  // index of its targets_t
    wingman::target_t target;
  };
  struct Detections {
    int64_t utime;
    int camera_id;
    int image_width;
    std::vector<wingman::detection_t> boxes;
  };
  std::map<int, Track> truth;                                           // vehicle id -> positions
  std::map<int64_t, std::vector<wingman::truth_box_t>> truth_boxes_at;  // truth utime -> boxes
  std::map<int64_t, int64_t> truth_event_at, image_event_at;            // utime -> first log-event timestamp, us
  std::vector<Estimate> estimates;
  std::vector<std::pair<int64_t, int64_t>> published;  // (targets_t event timestamp, newest source_utime)
  std::vector<Detections> detections;
  std::vector<double> inference_ms;
  std::set<int> sources;
  size_t targets_messages = 0;
  EvalResult r;

  common::Progress progress = log_progress(o.progress, "wingman: reading " + o.log, o.log);
  while (const common::LcmLogEvent* ev = file.read_next()) {
    progress.update(ev->offset);
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
      truth_boxes_at[g.utime] = g.boxes;
      truth_event_at.emplace(g.utime, ev->timestamp);
    } else if (ev->channel == o.targets_channel) {
      wingman::targets_t ts;
      if (!decode(*ev, &ts)) continue;
      const size_t index = targets_messages++;
      int64_t newest = INT64_MIN;
      for (const auto& t : ts.targets) {
        newest = std::max(newest, t.source_utime);
        if (t.world_valid) estimates.push_back({t.predicted_utime, index, t});
      }
      if (!ts.targets.empty()) published.emplace_back(ev->timestamp, newest);
    } else if (ev->channel == o.detections_channel) {
      wingman::detections_t d;
      if (!decode(*ev, &d)) continue;
      sources.insert(d.source);
      inference_ms.push_back(d.inference_latency_us * 1e-3);
      // Drone boxes only, as the localizer tracks them; the other classes are counted apart.
      std::vector<wingman::detection_t> drones;
      for (const auto& b : d.detections) {
        if (b.class_id == 0)
          drones.push_back(b);
        else
          ++r.non_drone_boxes;
      }
      detections.push_back({d.utime, d.camera_id, d.image_width, std::move(drones)});
    } else if (ev->channel == o.image_channel || ev->channel == o.preview_channel) {
      // Only the utime: the pixels are read by the report when needed.
      if (const std::optional<int64_t> u = image_utime(*ev); u && ev->channel == o.image_channel) {
        r.image_utimes.push_back(*u);
        image_event_at.emplace(*u, ev->timestamp);
      } else if (u) {
        r.preview_utimes.push_back(*u);
      }
    }
  }
  progress.update(progress.total());
  progress.finish();
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
  r.first_truth_utime = t0;
  r.duration_s = static_cast<double>(t1 - t0) * 1e-6;
  const auto secs = [t0](int64_t u) { return static_cast<double>(u - t0) * 1e-6; };

  // Leader detection and false boxes, one criterion (box_on_leader) for every count. Over all detections_t: the
  // false boxes and the frames (utimes) with one. Over the frames where the leader is visible, binned by its truth
  // range: the frames with a box on it, the false boxes and the frames with one (a visible frame with no detections_t
  // counts as missed).
  std::map<int64_t, std::vector<const Detections*>> detections_at;  // utime -> its detections_t
  for (const auto& d : detections) detections_at[d.utime].push_back(&d);
  static const std::vector<wingman::truth_box_t> kNoTruth;
  for (const auto& [u, ds] : detections_at) {
    const auto boxes = truth_boxes_at.find(u);
    const auto& truth_boxes = boxes == truth_boxes_at.end() ? kNoTruth : boxes->second;
    int64_t false_here = 0;
    for (const Detections* d : ds)
      for (const auto& b : d->boxes) false_here += box_on_leader(b, d->camera_id, truth_boxes, o.leader_id) ? 0 : 1;
    r.false_boxes += false_here;
    if (false_here > 0) ++r.frames_with_false_box;
  }
  r.detection_frames = static_cast<int64_t>(detections_at.size());
  for (size_t i = 0; i <= o.range_bins_m.size(); ++i) {
    r.detection_by_range.push_back(
        {i == 0 ? 0.0 : o.range_bins_m[i - 1], i < o.range_bins_m.size() ? o.range_bins_m[i] : kInf, 0, 0, 0, 0});
  }
  for (const auto& [u, truth_boxes] : truth_boxes_at) {
    const auto leader_box = std::find_if(truth_boxes.begin(), truth_boxes.end(), [&](const wingman::truth_box_t& tb) {
      return tb.vehicle_id == o.leader_id && tb.visible;
    });
    if (leader_box == truth_boxes.end()) continue;
    bool on_leader = false;
    int64_t false_here = 0;
    if (const auto it = detections_at.find(u); it != detections_at.end()) {
      for (const Detections* d : it->second) {
        for (const auto& b : d->boxes) {
          const bool on = box_on_leader(b, d->camera_id, truth_boxes, o.leader_id);
          on_leader = on_leader || on;
          false_here += on ? 0 : 1;
        }
      }
    }
    DetectionBin& bin = r.detection_by_range[range_bin(o.range_bins_m, leader_box->range)];
    ++bin.visible;
    bin.detected += on_leader ? 1 : 0;
    bin.false_boxes += false_here;
    bin.frames_with_false_box += false_here > 0 ? 1 : 0;
  }
  for (const auto& b : r.detection_by_range) {
    r.frames_leader_visible += b.visible;
    r.frames_leader_detected += b.detected;
    r.false_boxes_leader_visible += b.false_boxes;
    r.frames_leader_visible_with_false_box += b.frames_with_false_box;
  }

  // Localization: each world target against the nearest truth vehicle (not the follower) at its time.
  Acc all, los_along, los_across;
  std::array<Acc, 3> axis;
  BinnedAcc by_range(o.range_bins_m);
  std::set<int> leader_tracks, false_tracks;
  std::map<size_t, std::pair<double, int>> leader_in_message;  // targets_t index -> (distance, track id)
  // The same for every vehicle: vehicle id -> targets_t index -> (distance, track id); vehicle id -> track ids.
  std::map<int, std::map<size_t, std::pair<double, int>>> vehicle_in_message;
  std::map<int, std::set<int>> vehicle_tracks;
  const Track* follower = truth.count(o.follower_id) ? &truth.at(o.follower_id) : nullptr;
  for (const auto& [u, message, t] : estimates) {
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
    Eigen::Vector3d p_f;
    const bool have_follower = follower && follower->at(u, &p_f);
    if (best_id < 0) {
      ++r.false_targets;
      false_tracks.insert(t.track_id);
      r.targets.push_back({secs(u), t.track_id, -1, t.range, p_est, Eigen::Vector3d::Constant(kNaN), kNaN, t.range,
                           t.radius_m, t.radius_sigma_m});
      continue;
    }
    ++r.target_estimates;
    const Eigen::Vector3d e = p_est - best_p;
    all.add(e.norm());
    for (int k = 0; k < 3; ++k) axis[k].add(e[k]);
    const double range = have_follower ? (best_p - p_f).norm() : t.range;
    by_range.add(range, e.norm());
    r.targets.push_back(
        {secs(u), t.track_id, best_id, range, p_est, best_p, e.norm(), t.range, t.radius_m, t.radius_sigma_m});
    if (have_follower && (best_p - p_f).norm() > 1e-6) {
      const Eigen::Vector3d los = (best_p - p_f).normalized();
      const double along = e.dot(los);
      los_along.add(along);
      los_across.add((e - along * los).norm());
    }
    vehicle_tracks[best_id].insert(t.track_id);
    {
      auto [it, fresh] = vehicle_in_message[best_id].emplace(message, std::make_pair(best, t.track_id));
      if (!fresh && best < it->second.first) it->second = {best, t.track_id};
    }
    if (best_id == o.leader_id) {
      leader_tracks.insert(t.track_id);
      r.leader_estimate.push_back({secs(u), p_est});
      r.localization_error_over_time.emplace_back(secs(u), e.norm());
      auto [it, fresh] = leader_in_message.emplace(message, std::make_pair(best, t.track_id));
      if (!fresh && best < it->second.first) it->second = {best, t.track_id};
      r.frames[t.source_utime].leader_track_id = t.track_id;
    }
  }
  r.localization = all.stats();
  for (int k = 0; k < 3; ++k) r.localization_axis[k] = axis[k].stats();
  r.along_line_of_sight = los_along.stats();
  r.across_line_of_sight = los_across.stats();
  r.localization_by_range = by_range.bins();
  r.track_ids_on_leader = static_cast<int64_t>(leader_tracks.size());
  r.false_track_ids = static_cast<int64_t>(false_tracks.size());
  r.false_targets_per_s = r.duration_s > 0.0 ? static_cast<double>(r.false_targets) / r.duration_s : 0.0;
  int previous_id = -1;
  for (const auto& [message, match] : leader_in_message) {
    if (previous_id >= 0 && match.second != previous_id) ++r.leader_id_switches;
    previous_id = match.second;
  }
  for (const auto& [vehicle, messages] : vehicle_in_message) {
    EvalResult::VehicleIds& v = r.ids_by_vehicle[vehicle];
    v.track_ids = static_cast<int64_t>(vehicle_tracks[vehicle].size());
    int previous = -1;
    for (const auto& [message, match] : messages) {
      if (previous >= 0 && match.second != previous) ++v.id_switches;
      previous = match.second;
    }
  }

  // Latency, from the exposure (the earlier of the image and the ground truth of that step, as the logger saw
  // them: a large image can reach the logger after the targets computed from its ground-truth detections) to the
  // published targets.
  for (const auto& [stamp, source_utime] : published) {
    int64_t exposure = INT64_MAX;
    if (const auto it = image_event_at.find(source_utime); it != image_event_at.end()) exposure = it->second;
    if (const auto it = truth_event_at.find(source_utime); it != truth_event_at.end())
      exposure = std::min(exposure, it->second);
    if (exposure == INT64_MAX) continue;
    r.latency_samples_ms.push_back(static_cast<double>(stamp - exposure) * 1e-3);
  }
  r.latency_ms = percentiles(r.latency_samples_ms);
  r.inference_latency_ms = percentiles(inference_ms);

  // Box widths: the detection nearest the leader's truth box centre, among those centred inside it.
  Acc width_single, width_zoom;
  BinnedAcc width_single_bins(o.range_bins_m), width_zoom_bins(o.range_bins_m);
  for (const auto& d : detections) {
    auto& frame = r.frames[d.utime];
    for (const auto& b : d.boxes) frame.detections.push_back({b.cx, b.cy, b.w, b.h, d.camera_id, b.zoom_refined != 0});
    if (d.image_width > 0) frame.image_width = d.image_width;
    r.detections_total += static_cast<int64_t>(d.boxes.size());
    const auto boxes = truth_boxes_at.find(d.utime);
    if (boxes == truth_boxes_at.end()) {
      r.detections_outside_truth += static_cast<int64_t>(d.boxes.size());
      continue;
    }
    for (const auto& b : d.boxes) {
      bool in_any = false;
      for (const auto& tb : boxes->second)
        in_any = in_any || (tb.visible && tb.camera_id == d.camera_id && centred_in(b, tb));
      if (!in_any) ++r.detections_outside_truth;
    }
    if (d.image_width <= 0) continue;
    for (const auto& tb : boxes->second) {
      if (tb.vehicle_id != o.leader_id || tb.camera_id != d.camera_id || !tb.visible) continue;
      for (const bool zoom : {false, true}) {
        const wingman::detection_t* nearest = nullptr;
        double nearest_d = kInf;
        for (const auto& b : d.boxes) {
          if ((b.zoom_refined != 0) != zoom) continue;
          if (!centred_in(b, tb)) continue;
          const double dist = std::hypot(b.cx - tb.cx, b.cy - tb.cy);
          if (dist < nearest_d) nearest_d = dist, nearest = &b;
        }
        if (!nearest) continue;
        const double w = static_cast<double>(d.image_width);
        const double err = std::abs(static_cast<double>(nearest->w) - tb.w) / w;
        (zoom ? width_zoom : width_single).add(err);
        (zoom ? width_zoom_bins : width_single_bins).add(tb.range, err);
        r.box_widths.push_back({tb.range, nearest->w / w, tb.w / w, zoom});
      }
    }
  }
  r.box_width_single = width_single.stats();
  r.box_width_zoom = width_zoom.stats();
  r.box_width_single_by_range = width_single_bins.bins();
  r.box_width_zoom_by_range = width_zoom_bins.bins();
  for (const auto& [u, boxes] : truth_boxes_at) {
    auto& frame = r.frames[u];
    for (const auto& b : boxes)
      frame.truth_boxes.push_back({b.cx, b.cy, b.w, b.h, b.camera_id, b.visible != 0, b.vehicle_id});
  }

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

  const auto write = [](const std::string& path, const std::string& text) {
    std::ofstream f(path);
    f << text;
    if (!f) throw std::runtime_error("wingman eval: cannot write '" + path + "'");
  };
  if (!o.json_path.empty()) write(o.json_path, r.json() + "\n");
  if (!o.csv_path.empty()) write(o.csv_path, r.csv());
  if (!o.report_path.empty()) write_html_report(r, o, o.report_path);
  return r;
}

std::string EvalResult::report() const {
  std::string s;
  s += fmt::format(
      "flight: {:.1f} s of ground truth ({} frames); detections from {}\n", duration_s, truth_frames,
      detection_source == "ground_truth" ? "GROUND TRUTH (simulated boxes, no detector model)" : detection_source);
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
  s += fmt::format("world targets: {} matched, {} false; {} track id(s) on the leader, {} id switch(es)\n",
                   target_estimates, false_targets, track_ids_on_leader, leader_id_switches);
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
  s += stats_line("zoom-in", box_width_zoom, "%", 100.0);
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
  j["duration_s"] = duration_s;
  j["truth_frames"] = truth_frames;
  j["frames_leader_visible"] = frames_leader_visible;
  j["frames_leader_detected"] = frames_leader_detected;
  j["false_boxes_leader_visible"] = false_boxes_leader_visible;
  j["frames_leader_visible_with_false_box"] = frames_leader_visible_with_false_box;
  j["target_estimates"] = target_estimates;
  j["false_targets"] = false_targets;
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
      "radius_sigma_m\n";
  const auto num = [](double v) { return std::isnan(v) ? std::string() : fmt::format("{:.4f}", v); };
  for (const auto& t : targets) {
    s += fmt::format("{:.6f},{},{},{:.4f},{:.4f},{:.4f},{:.4f},{},{},{},{},{:.4f},{:.4f},{:.4f}\n", t.t_s, t.track_id,
                     t.vehicle_id, t.range_m, t.p_est.x(), t.p_est.y(), t.p_est.z(), num(t.p_truth.x()),
                     num(t.p_truth.y()), num(t.p_truth.z()), num(t.error_m), t.range_est_m, t.radius_m,
                     t.radius_sigma_m);
  }
  return s;
}

}  // namespace wingman::tools
