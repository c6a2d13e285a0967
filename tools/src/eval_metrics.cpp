// SPDX-License-Identifier: MIT
// `wingman eval`, metrics: the sections of EvalResult computed from the log's records (eval_log.hpp).
#include "eval_metrics.hpp"

#include <wingman/detections_t.hpp>
#include <wingman/geometry/message_eigen.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

namespace wingman::tools {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// Index of the range bin of `range` (upper edges `edges`; the last bin is open).
size_t range_bin(const std::vector<double>& edges, double range) {
  return static_cast<size_t>(std::upper_bound(edges.begin(), edges.end(), range) - edges.begin());
}

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

/// True when the centre of `b` lies inside `tb` (edges included); cameras and visibility are the caller's to check.
bool centred_in(const wingman::detection_t& b, const wingman::truth_box_t& tb) {
  return std::abs(b.cx - tb.cx) <= 0.5 * tb.w && std::abs(b.cy - tb.cy) <= 0.5 * tb.h;
}

/// Seconds of utime `u` (microseconds) since t0 (microseconds).
double seconds_since(int64_t t0, int64_t u) { return static_cast<double>(u - t0) * 1e-6; }

// --- detection ---

using DetectionsAt = std::map<int64_t, std::vector<const EvalDetections*>>;  ///< utime -> its detections_t

/// Over all detections_t: the boxes not on the leader (false boxes) and the frames (utimes) with one.
void false_box_metrics(const EvalLog& log, const DetectionsAt& detections_at, int leader_id, EvalResult* r) {
  static const std::vector<wingman::truth_box_t> kNoTruth;
  for (const auto& [u, ds] : detections_at) {
    const auto boxes = log.truth_boxes_at.find(u);
    const auto& truth_boxes = boxes == log.truth_boxes_at.end() ? kNoTruth : boxes->second;
    int64_t false_here = 0;
    for (const EvalDetections* d : ds)
      for (const auto& b : d->boxes) false_here += box_on_leader(b, d->camera_id, truth_boxes, leader_id) ? 0 : 1;
    r->false_boxes += false_here;
    if (false_here > 0) ++r->frames_with_false_box;
  }
  r->detection_frames = static_cast<int64_t>(detections_at.size());
}

/// Over the frames where the leader is visible, binned by its truth range: the frames with a box on it, the false
/// boxes and the frames with one (a visible frame with no detections_t counts as missed).
void leader_detection_by_range(const EvalLog& log, const DetectionsAt& detections_at, const EvalOptions& o,
                               EvalResult* r) {
  for (size_t i = 0; i <= o.range_bins_m.size(); ++i) {
    r->detection_by_range.push_back(
        {i == 0 ? 0.0 : o.range_bins_m[i - 1], i < o.range_bins_m.size() ? o.range_bins_m[i] : kInf, 0, 0, 0, 0});
  }
  for (const auto& [u, truth_boxes] : log.truth_boxes_at) {
    const auto leader_box = std::find_if(truth_boxes.begin(), truth_boxes.end(), [&](const wingman::truth_box_t& tb) {
      return tb.vehicle_id == o.leader_id && tb.visible;
    });
    if (leader_box == truth_boxes.end()) continue;
    bool on_leader = false;
    int64_t false_here = 0;
    if (const auto it = detections_at.find(u); it != detections_at.end()) {
      for (const EvalDetections* d : it->second) {
        for (const auto& b : d->boxes) {
          const bool on = box_on_leader(b, d->camera_id, truth_boxes, o.leader_id);
          on_leader = on_leader || on;
          false_here += on ? 0 : 1;
        }
      }
    }
    DetectionBin& bin = r->detection_by_range[range_bin(o.range_bins_m, leader_box->range)];
    ++bin.visible;
    bin.detected += on_leader ? 1 : 0;
    bin.false_boxes += false_here;
    bin.frames_with_false_box += false_here > 0 ? 1 : 0;
  }
  for (const auto& b : r->detection_by_range) {
    r->frames_leader_visible += b.visible;
    r->frames_leader_detected += b.detected;
    r->false_boxes_leader_visible += b.false_boxes;
    r->frames_leader_visible_with_false_box += b.frames_with_false_box;
  }
}

// --- localization ---

/// The truth vehicle a world target is matched to.
struct Match {
  int vehicle_id = -1;      ///< -1: none within the match radius (a false target)
  double distance_m = 0.0;  ///< |p_est - p_truth|, metres
  /// The vehicle's position at the target's time, world frame (ENU), metres.
  Eigen::Vector3d p_truth = Eigen::Vector3d::Zero();
};

/// The matches of every world target (log.estimates' order), one to one in each targets_t (the CLEAR MOT rule): a
/// vehicle gets at most one target of a message and a target at most one vehicle. A track keeps the vehicle it was
/// matched to in the last message it was matched in while it is still within the match radius of it and no other
/// target took it; the rest go by increasing distance. A target within the radius of vehicles that other targets of
/// the message took is a duplicate (`duplicate` true, vehicle_id -1): not a false target, not in the errors.
/// So two tracks near one drone (a coasting neighbour at a crossing, a duplicate before its merge) give it one id,
/// not two, and a neighbour's track that passes nearer to it is not counted as its identity.
struct OneToOne {
  std::vector<Match> match;
  std::vector<bool> duplicate;
};

OneToOne match_one_to_one(const EvalLog& log, const EvalOptions& o) {
  OneToOne out;
  out.match.resize(log.estimates.size());
  out.duplicate.assign(log.estimates.size(), false);
  std::map<int, int> vehicle_of_track;  // the vehicle each track was last matched to
  size_t begin = 0;
  while (begin < log.estimates.size()) {
    size_t end = begin;
    while (end < log.estimates.size() && log.estimates[end].message == log.estimates[begin].message) ++end;
    // Every (target, vehicle) pair within the radius.
    struct Pair {
      size_t target;
      Match m;
    };
    std::vector<Pair> pairs;
    for (size_t i = begin; i < end; ++i) {
      const Eigen::Vector3d p_est = geometry::to_vector3(log.estimates[i].target.p_target_in_world);
      for (const auto& [id, tr] : log.truth) {
        if (id == o.follower_id) continue;
        Eigen::Vector3d p;
        if (!tr.at(log.estimates[i].utime, &p)) continue;
        const double d = (p - p_est).norm();
        if (d <= o.match_radius_m) pairs.push_back({i, Match{id, d, p}});
      }
    }
    std::stable_sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
      return a.m.distance_m < b.m.distance_m || (a.m.distance_m == b.m.distance_m && a.m.vehicle_id > b.m.vehicle_id);
    });
    std::set<size_t> targets_taken;
    std::set<int> vehicles_taken;
    const auto take = [&](const Pair& x) {
      out.match[x.target] = x.m;
      targets_taken.insert(x.target);
      vehicles_taken.insert(x.m.vehicle_id);
      vehicle_of_track[log.estimates[x.target].target.track_id] = x.m.vehicle_id;
    };
    for (const Pair& x : pairs) {  // the correspondences of the previous match first
      const auto it = vehicle_of_track.find(log.estimates[x.target].target.track_id);
      if (it != vehicle_of_track.end() && it->second == x.m.vehicle_id && !targets_taken.count(x.target) &&
          !vehicles_taken.count(x.m.vehicle_id))
        take(x);
    }
    for (const Pair& x : pairs)
      if (!targets_taken.count(x.target) && !vehicles_taken.count(x.m.vehicle_id)) take(x);
    for (const Pair& x : pairs)
      if (!targets_taken.count(x.target)) out.duplicate[x.target] = true;
    begin = end;
  }
  return out;
}

/// Track ids of the matched and false targets, and per targets_t the match nearest each vehicle.
struct TrackIds {
  using NearestInMessage = std::map<size_t, std::pair<double, int>>;  ///< targets_t index -> (distance, track id)
  std::set<int> leader_tracks, false_tracks;
  NearestInMessage leader_in_message;
  std::map<int, NearestInMessage> vehicle_in_message;  ///< vehicle id -> its nearest match per targets_t
  std::map<int, std::set<int>> vehicle_tracks;         ///< vehicle id -> track ids matched to it

  static void keep_nearest(NearestInMessage* in, size_t message, double distance, int track_id) {
    auto [it, fresh] = in->emplace(message, std::make_pair(distance, track_id));
    if (!fresh && distance < it->second.first) it->second = {distance, track_id};
  }
  /// Changes of track id from one targets_t to the next (log order).
  static int64_t switches(const NearestInMessage& in) {
    int64_t n = 0;
    int previous = -1;
    for (const auto& [message, match] : in) {
      if (previous >= 0 && match.second != previous) ++n;
      previous = match.second;
    }
    return n;
  }
  void add(size_t message, const Match& m, int track_id, bool leader) {
    vehicle_tracks[m.vehicle_id].insert(track_id);
    keep_nearest(&vehicle_in_message[m.vehicle_id], message, m.distance_m, track_id);
    if (!leader) return;
    leader_tracks.insert(track_id);
    keep_nearest(&leader_in_message, message, m.distance_m, track_id);
  }
  void fill(EvalResult* r) const {
    r->track_ids_on_leader = static_cast<int64_t>(leader_tracks.size());
    r->false_track_ids = static_cast<int64_t>(false_tracks.size());
    r->leader_id_switches = switches(leader_in_message);
    for (const auto& [vehicle, messages] : vehicle_in_message) {
      EvalResult::VehicleIds& v = r->ids_by_vehicle[vehicle];
      v.track_ids = static_cast<int64_t>(vehicle_tracks.at(vehicle).size());
      v.id_switches = switches(messages);
    }
  }
};

}  // namespace

bool box_on_leader(const wingman::detection_t& box, int camera_id, const std::vector<wingman::truth_box_t>& truth_boxes,
                   int leader_id) {
  return std::any_of(truth_boxes.begin(), truth_boxes.end(), [&](const wingman::truth_box_t& tb) {
    return tb.vehicle_id == leader_id && tb.camera_id == camera_id && tb.visible && centred_in(box, tb);
  });
}

std::string detection_source_name(const std::set<int>& sources) {
  if (sources.empty()) return "none";
  if (sources.size() > 1) return "mixed";
  return *sources.begin() == wingman::detections_t::SOURCE_GROUND_TRUTH ? "ground_truth" : "cnn";
}

void log_metrics(const EvalLog& log, EvalResult* r) {
  r->truth_frames = log.truth_frames;
  r->non_drone_boxes = log.non_drone_boxes;
  r->image_utimes = log.image_utimes;
  r->preview_utimes = log.preview_utimes;
  r->detection_source = detection_source_name(log.sources);
  r->detector_backends = log.detector_backends;
  int64_t t0 = INT64_MAX, t1 = INT64_MIN;
  for (const auto& [id, t] : log.truth) {
    t0 = std::min(t0, t.utime.front());
    t1 = std::max(t1, t.utime.back());
  }
  r->first_truth_utime = t0;
  r->duration_s = static_cast<double>(t1 - t0) * 1e-6;
}

void detection_metrics(const EvalLog& log, const EvalOptions& o, EvalResult* r) {
  DetectionsAt detections_at;
  for (const auto& d : log.detections) detections_at[d.utime].push_back(&d);
  false_box_metrics(log, detections_at, o.leader_id, r);
  leader_detection_by_range(log, detections_at, o, r);
}

void localization_metrics(const EvalLog& log, const EvalOptions& o, EvalResult* r) {
  const int64_t t0 = r->first_truth_utime;
  Acc all, los_along, los_across;
  std::array<Acc, 3> axis;
  BinnedAcc by_range(o.range_bins_m);
  TrackIds ids;
  const TruthTrack* follower = log.truth.count(o.follower_id) ? &log.truth.at(o.follower_id) : nullptr;
  const OneToOne matches = match_one_to_one(log, o);
  for (size_t i = 0; i < log.estimates.size(); ++i) {
    const auto& [u, message, t] = log.estimates[i];
    const Eigen::Vector3d p_est = geometry::to_vector3(t.p_target_in_world);
    if (matches.duplicate[i]) {
      ++r->duplicate_targets;
      continue;
    }
    const Match& m = matches.match[i];
    const double t_s = seconds_since(t0, u);
    Eigen::Vector3d p_f;
    const bool have_follower = follower && follower->at(u, &p_f);
    if (m.vehicle_id < 0) {
      ++r->false_targets;
      ids.false_tracks.insert(t.track_id);
      r->targets.push_back({t_s, t.track_id, -1, t.range, p_est, Eigen::Vector3d::Constant(kNaN), kNaN, t.range,
                            t.radius_m, t.radius_sigma_m, t.camera_id});
      continue;
    }
    ++r->target_estimates;
    const Eigen::Vector3d e = p_est - m.p_truth;
    all.add(e.norm());
    for (int k = 0; k < 3; ++k) axis[k].add(e[k]);
    const double range = have_follower ? (m.p_truth - p_f).norm() : t.range;
    by_range.add(range, e.norm());
    r->targets.push_back({t_s, t.track_id, m.vehicle_id, range, p_est, m.p_truth, e.norm(), t.range, t.radius_m,
                          t.radius_sigma_m, t.camera_id});
    if (have_follower && (m.p_truth - p_f).norm() > 1e-6) {
      const Eigen::Vector3d los = (m.p_truth - p_f).normalized();
      const double along = e.dot(los);
      los_along.add(along);
      los_across.add((e - along * los).norm());
    }
    ids.add(message, m, t.track_id, m.vehicle_id == o.leader_id);
    if (m.vehicle_id == o.leader_id) {
      r->leader_estimate.push_back({t_s, p_est});
      r->localization_error_over_time.emplace_back(t_s, e.norm());
      r->frames[t.source_utime].leader_track_id = t.track_id;
    }
  }
  r->localization = all.stats();
  for (int k = 0; k < 3; ++k) r->localization_axis[k] = axis[k].stats();
  r->along_line_of_sight = los_along.stats();
  r->across_line_of_sight = los_across.stats();
  r->localization_by_range = by_range.bins();
  r->false_targets_per_s = r->duration_s > 0.0 ? static_cast<double>(r->false_targets) / r->duration_s : 0.0;
  ids.fill(r);
}

void latency_metrics(const EvalLog& log, EvalResult* r) {
  // From the exposure (the earlier of the image and the ground truth of that step, as the logger saw them: a large
  // image can reach the logger after the targets computed from its ground-truth detections) to the published targets.
  for (const auto& [stamp, source_utime] : log.published) {
    int64_t exposure = INT64_MAX;
    if (const auto it = log.image_event_at.find(source_utime); it != log.image_event_at.end()) exposure = it->second;
    if (const auto it = log.truth_event_at.find(source_utime); it != log.truth_event_at.end())
      exposure = std::min(exposure, it->second);
    if (exposure == INT64_MAX) continue;
    r->latency_samples_ms.push_back(static_cast<double>(stamp - exposure) * 1e-3);
  }
  r->latency_ms = percentiles(r->latency_samples_ms);
  r->inference_latency_ms = percentiles(log.inference_ms);
}

namespace {

/// frames[]: each detections_t's boxes and image width, each ground truth's boxes; detections_total and
/// detections_outside_truth.
void frame_boxes(const EvalLog& log, EvalResult* r) {
  for (const auto& d : log.detections) {
    auto& frame = r->frames[d.utime];
    for (const auto& b : d.boxes)
      frame.detections.push_back({b.cx, b.cy, b.w, b.h, d.camera_id, b.pass_kind != wingman::detection_t::PASS_SINGLE});
    if (d.image_width > 0) frame.image_width = d.image_width;
    r->detections_total += static_cast<int64_t>(d.boxes.size());
    const auto boxes = log.truth_boxes_at.find(d.utime);
    if (boxes == log.truth_boxes_at.end()) {
      r->detections_outside_truth += static_cast<int64_t>(d.boxes.size());
      continue;
    }
    for (const auto& b : d.boxes) {
      bool in_any = false;
      for (const auto& tb : boxes->second)
        in_any = in_any || (tb.visible && tb.camera_id == d.camera_id && centred_in(b, tb));
      if (!in_any) ++r->detections_outside_truth;
    }
  }
  for (const auto& [u, boxes] : log.truth_boxes_at) {
    auto& frame = r->frames[u];
    for (const auto& b : boxes)
      frame.truth_boxes.push_back({b.cx, b.cy, b.w, b.h, b.camera_id, b.visible != 0, b.vehicle_id});
  }
}

/// Among `d`'s boxes of one kind (re-detected at a finer scale: zoom-in or window; or single pass) centred inside `tb`,
/// the one with the nearest centre; nullptr when none.
const wingman::detection_t* nearest_box(const EvalDetections& d, const wingman::truth_box_t& tb, bool zoom) {
  const wingman::detection_t* nearest = nullptr;
  double nearest_d = kInf;
  for (const auto& b : d.boxes) {
    if ((b.pass_kind != wingman::detection_t::PASS_SINGLE) != zoom) continue;
    if (!centred_in(b, tb)) continue;
    const double dist = std::hypot(b.cx - tb.cx, b.cy - tb.cy);
    if (dist < nearest_d) nearest_d = dist, nearest = &b;
  }
  return nearest;
}

}  // namespace

void box_metrics(const EvalLog& log, const EvalOptions& o, EvalResult* r) {
  frame_boxes(log, r);
  // Box widths: the detection nearest the leader's truth box centre, among those centred inside it.
  Acc width_single, width_zoom;
  BinnedAcc width_single_bins(o.range_bins_m), width_zoom_bins(o.range_bins_m);
  for (const auto& d : log.detections) {
    const auto boxes = log.truth_boxes_at.find(d.utime);
    if (boxes == log.truth_boxes_at.end() || d.image_width <= 0) continue;
    for (const auto& tb : boxes->second) {
      if (tb.vehicle_id != o.leader_id || tb.camera_id != d.camera_id || !tb.visible) continue;
      for (const bool zoom : {false, true}) {
        const wingman::detection_t* nearest = nearest_box(d, tb, zoom);
        if (!nearest) continue;
        const double w = static_cast<double>(d.image_width);
        const double err = std::abs(static_cast<double>(nearest->w) - tb.w) / w;
        (zoom ? width_zoom : width_single).add(err);
        (zoom ? width_zoom_bins : width_single_bins).add(tb.range, err);
        r->box_widths.push_back({tb.range, nearest->w / w, tb.w / w, zoom});
      }
    }
  }
  r->box_width_single = width_single.stats();
  r->box_width_zoom = width_zoom.stats();
  r->box_width_single_by_range = width_single_bins.bins();
  r->box_width_zoom_by_range = width_zoom_bins.bins();
}

void formation_metrics(const EvalLog& log, const EvalOptions& o, EvalResult* r) {
  const auto follower = log.truth.find(o.follower_id);
  const auto leader = log.truth.find(o.leader_id);
  Acc fh, fv;
  if (follower != log.truth.end()) {
    const TruthTrack& f = follower->second;
    for (size_t i = 0; i < f.utime.size(); ++i) {
      const int64_t u = f.utime[i];
      const double t_s = seconds_since(r->first_truth_utime, u);
      r->follower_truth.push_back({t_s, f.p[i]});
      Eigen::Vector3d p_l;
      if (leader == log.truth.end() || !leader->second.at(u, &p_l)) continue;
      r->leader_truth.push_back({t_s, p_l});
      if (!o.has_formation || t_s < o.settle_s) continue;
      Eigen::Vector3d p_des = p_l + o.formation_offset_in_world;
      if (o.formation_height_m >= 0.0) p_des.z() = o.formation_height_m;
      const Eigen::Vector3d e = f.p[i] - p_des;
      fh.add(e.head<2>().norm());
      fv.add(e.z());
      r->formation_error_over_time.emplace_back(t_s, e.head<2>().norm());
    }
  }
  r->formation_horizontal = fh.stats();
  r->formation_vertical = fv.stats();
}

}  // namespace wingman::tools
