// SPDX-License-Identifier: MIT
// Tracker: predict, gate, associate, update, M-of-N birth, timeout death, output modes.
#include "wingman/localizer/tracker.hpp"

#include "wingman/localizer/association.hpp"

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <wingman/common/config.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wingman::localizer {
namespace {

double us_to_s(int64_t us) { return static_cast<double>(us) * 1e-6; }

bool finite(const WorldMeasurement& m) {
  return m.p_target_in_world.allFinite() && m.cov_p_in_world.allFinite() && std::isfinite(m.confidence);
}

}  // namespace

std::vector<std::string> TrackerOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (mode != "kalman" && mode != "sliding_window" && mode != "most_confident")
    p.push_back(problem("tracker.mode", mode, "must be kalman, sliding_window or most_confident"));
  if (association != "hungarian" && association != "greedy")
    p.push_back(problem("tracker.association", association, "must be hungarian or greedy"));
  if (!(accel_noise >= 0) || !std::isfinite(accel_noise))
    p.push_back(problem("tracker.accel_noise", accel_noise, "must be finite and >= 0"));
  if (!(gate_chi2 > 0) || !std::isfinite(gate_chi2))
    p.push_back(problem("tracker.gate_chi2", gate_chi2, "must be finite and > 0"));
  if (!(ambiguity_chi2 >= 0) || !std::isfinite(ambiguity_chi2))
    p.push_back(problem("tracker.ambiguity_chi2", ambiguity_chi2, "must be finite and >= 0"));
  if (!(occlusion_margin >= 0) || !std::isfinite(occlusion_margin))
    p.push_back(problem("tracker.occlusion_margin", occlusion_margin, "must be finite and >= 0"));
  if (!(merge_after_s >= 0) || !std::isfinite(merge_after_s))
    p.push_back(problem("tracker.merge_after_s", merge_after_s, "must be finite and >= 0"));
  if (birth_hits < 1) p.push_back(problem("tracker.birth_hits", birth_hits, "must be >= 1"));
  if (birth_window < birth_hits)
    p.push_back(
        problem("tracker.birth_window", birth_window, fmt::format("must be >= tracker.birth_hits ({})", birth_hits)));
  if (!(birth_min_confidence >= 0 && birth_min_confidence <= 1))
    p.push_back(problem("tracker.birth_min_confidence", birth_min_confidence, "must be in [0, 1]"));
  if (!(confirm_min_confidence >= 0 && confirm_min_confidence <= 1))
    p.push_back(problem("tracker.confirm_min_confidence", confirm_min_confidence, "must be in [0, 1]"));
  if (!(death_timeout_s > 0 && death_timeout_s <= 3600))
    p.push_back(problem("tracker.death_timeout_s", death_timeout_s, "must be in (0, 3600] s"));
  if (!(reacquire_s >= 0 && reacquire_s <= 3600))
    p.push_back(problem("tracker.reacquire_s", reacquire_s, "must be in [0, 3600] s (0 = off)"));
  if (!(reacquire_speed_mps >= 0 && reacquire_speed_mps <= 1000))
    p.push_back(problem("tracker.reacquire_speed_mps", reacquire_speed_mps, "must be in [0, 1000] m/s"));
  if (!(reacquire_gate_m > 0 && reacquire_gate_m <= 1000))
    p.push_back(problem("tracker.reacquire_gate_m", reacquire_gate_m, "must be in (0, 1000] m"));
  if (window_size < 1) p.push_back(problem("tracker.window_size", window_size, "must be >= 1"));
  if (!(initial_velocity_std > 0) || !std::isfinite(initial_velocity_std))
    p.push_back(problem("tracker.initial_velocity_std", initial_velocity_std, "must be finite and > 0"));
  if (!(max_prediction_s >= 0) || !std::isfinite(max_prediction_s))
    p.push_back(problem("tracker.max_prediction_s", max_prediction_s, "must be finite and >= 0"));
  if (max_tracks < 1) p.push_back(problem("tracker.max_tracks", max_tracks, "must be >= 1"));
  if (!(merge_chi2 >= 0) || !std::isfinite(merge_chi2))
    p.push_back(problem("tracker.merge_chi2", merge_chi2, "must be finite and >= 0"));
  for (const std::string& q : size.validate()) p.push_back(q);
  return p;
}

TrackerMode TrackerOptions::mode_enum() const {
  if (mode == "sliding_window") return TrackerMode::kSlidingWindow;
  if (mode == "most_confident") return TrackerMode::kMostConfident;
  return TrackerMode::kKalman;
}

AssociationMethod TrackerOptions::association_enum() const {
  return association == "greedy" ? AssociationMethod::kGreedy : AssociationMethod::kHungarian;
}

Tracker::Tracker(TrackerOptions options) : options_(std::move(options)) {
  const auto problems = options_.validate();
  if (!problems.empty()) {
    std::string all = "invalid TrackerOptions:";
    for (const auto& q : problems) all += " " + q + ";";
    throw std::invalid_argument(all);
  }
  mode_ = options_.mode_enum();
  association_ = options_.association_enum();
}

size_t Tracker::num_tentative() const {
  return static_cast<size_t>(std::count_if(tracks_.begin(), tracks_.end(), [](const Track& t) { return t.id == 0; }));
}

size_t Tracker::num_held() const {
  return static_cast<size_t>(std::count_if(tracks_.begin(), tracks_.end(), [&](const Track& t) {
    return t.id == 0 && t.held && t.hits >= options_.birth_hits;
  }));
}

size_t Tracker::num_confirmed() const { return tracks_.size() - num_tentative(); }

void Tracker::associate(std::vector<Track*>& tracks, const std::vector<WorldMeasurement>& z, std::vector<bool>& z_used,
                        std::vector<int>& track_to_z, Eigen::MatrixXd* cost_out) const {
  track_to_z.assign(tracks.size(), -1);
  if (tracks.empty() || z.empty()) return;
  Eigen::MatrixXd cost = Eigen::MatrixXd::Constant(static_cast<Eigen::Index>(tracks.size()),
                                                   static_cast<Eigen::Index>(z.size()), kForbiddenCost);
  for (size_t i = 0; i < tracks.size(); ++i)
    for (size_t j = 0; j < z.size(); ++j) {
      if (z_used[j]) continue;
      // Against the detection the track predicts at its size: c + (p - c) / s (s = 1 without size estimation).
      const double s = tracks[i]->scale.scale;
      const Eigen::Vector3d c = z[j].p_cam_in_world;
      const Eigen::Vector3d y =
          z[j].p_target_in_world - (s == 1.0 ? tracks[i]->sc.p() : c + (tracks[i]->sc.p() - c) / s);
      const Eigen::Matrix3d S = tracks[i]->sc.P.topLeftCorner<3, 3>() / (s * s) + z[j].cov_p_in_world;
      const double d2 = y.dot(S.ldlt().solve(y));
      if (d2 <= options_.gate_chi2) cost(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = d2;
    }
  track_to_z = association_ == AssociationMethod::kGreedy ? greedy_assign(cost) : hungarian(cost);
  for (int j : track_to_z)
    if (j >= 0) z_used[static_cast<size_t>(j)] = true;
  if (cost_out) *cost_out = std::move(cost);
}

void Tracker::hit(Track& t, const WorldMeasurement& z) {
  t.recent_confidence.push_back(z.confidence);
  while (static_cast<int>(t.recent_confidence.size()) > options_.birth_window) t.recent_confidence.pop_front();
  const Eigen::Vector3d c = z.p_cam_in_world;
  t.size.add(z.utime, z.p_target_in_world, z.cov_p_in_world, c);
  const SizeEstimate e = t.size.estimate();
  // An acceptable fit is adopted when it agrees (within twice the larger sigma) with the scale adopted before, or with
  // another acceptable fit half a window or more earlier: a manoeuvre that camera and target share (a follower
  // starting after its leader) can make one window's fit confidently wrong (63 % off, sigma 2.5 %, in the formation
  // flight's first window).
  const auto agree = [](const SizeEstimate& a, const SizeEstimate& b) {
    return std::abs(a.scale - b.scale) <= 2.0 * std::max(a.sigma, b.sigma);
  };
  bool adopt = false;
  if (e.acceptable(options_.size.accept_rel) && t.scale.from_data && agree(e, t.scale)) {
    adopt = true;
  } else if (e.acceptable(options_.size.accept_rel)) {
    const int64_t half_window_us = static_cast<int64_t>(std::llround(0.5 * options_.size.window_s * 1e6));
    if (t.candidate_utime >= 0 && z.utime - t.candidate_utime >= half_window_us) {
      adopt = agree(e, t.candidate);
      t.candidate_utime = -1;  // judged: the next acceptable fit starts a new pair
    }
    if (!adopt && t.candidate_utime < 0) {
      t.candidate = e;
      t.candidate_utime = z.utime;
    }
  }
  if (adopt) {
    // Adopt it, and move the state along the ray from the camera to match (the track's past detections were taken
    // at the old scale): p' = c + k (p - c), its covariance by k^2.
    const double k = e.scale / t.scale.scale;
    t.sc.x.head<3>() = c + k * (t.sc.p() - c);
    t.sc.P.topLeftCorner<3, 3>() *= k * k;
    t.sc.P.topRightCorner<3, 3>() *= k;
    t.sc.P.bottomLeftCorner<3, 3>() *= k;
    t.scale = e;
  }
  const double s = t.scale.scale;
  // The filter, not Tracker::update: the detection at the track's size.
  // (s = 1 exactly: the detection as it is, so that the numbers without size estimation are bit for bit the same.)
  t.sc = s == 1.0 ? localizer::update(t.sc, z.p_target_in_world, z.cov_p_in_world)
                  : localizer::update(t.sc, c + s * (z.p_target_in_world - c), s * s * z.cov_p_in_world);
  t.last_hit_utime = z.utime;
  t.last = z;
  t.p_at_last_hit = t.sc.p();
  t.window.push_back({z.utime, z.p_target_in_world, z.cov_p_in_world});
  while (static_cast<int>(t.window.size()) > options_.window_size) t.window.pop_front();
}

bool Tracker::update(int64_t utime, const std::vector<WorldMeasurement>& measurements, std::string* why) {
  return update_cameras(utime, std::vector<std::vector<WorldMeasurement>>(1, measurements), why);
}

bool Tracker::update_cameras(int64_t utime, const std::vector<std::vector<WorldMeasurement>>& per_camera,
                             std::string* why, const FrameViews& views) {
  if (have_frame_ && utime <= last_frame_utime_) {
    ++stats_.frames_rejected;
    if (why)
      *why =
          fmt::format("frame utime {} is not after the previous frame's ({}, {} s {})", utime, last_frame_utime_,
                      us_to_s(std::abs(last_frame_utime_ - utime)), utime == last_frame_utime_ ? "apart" : "earlier");
    return false;
  }
  ++stats_.frames;

  // The detections this frame uses, per camera; each carries the frame's utime.
  std::vector<std::vector<WorldMeasurement>> zs(per_camera.size());
  for (size_t c = 0; c < per_camera.size(); ++c) {
    zs[c].reserve(per_camera[c].size());
    for (const WorldMeasurement& m : per_camera[c]) {
      if (!finite(m)) {
        ++stats_.measurements_rejected;
        continue;
      }
      zs[c].push_back(m);
      zs[c].back().utime = utime;
    }
  }
  size_t total = 0;
  for (const auto& z : zs) total += z.size();
  if (mode_ == TrackerMode::kMostConfident && total > 1) {  // the frame's most confident detection, the first of ties
    size_t best_c = 0, best_j = 0;
    bool found = false;
    for (size_t c = 0; c < zs.size(); ++c)
      for (size_t j = 0; j < zs[c].size(); ++j)
        if (!found || zs[c][j].confidence > zs[best_c][best_j].confidence) best_c = c, best_j = j, found = true;
    const WorldMeasurement keep = zs[best_c][best_j];
    for (auto& z : zs) z.clear();
    zs[best_c].assign(1, keep);
    stats_.measurements_rejected += static_cast<int64_t>(total - 1);
    total = 1;
  }
  stats_.measurements += static_cast<int64_t>(total);

  // Predict every track to the exposure time.
  for (Track& t : tracks_) {
    t.sc = predict(t.sc, options_.accel_noise, us_to_s(utime - t.state_utime));
    t.state_utime = utime;
  }

  // Per camera in order: confirmed tracks choose first, tentative ones take the rest, then the tracks the cameras
  // before started this frame; the detections left start tracks (kept in `born` until the book-keeping is done).
  const int64_t max_coast_us = static_cast<int64_t>(std::llround(options_.max_prediction_s * 1e6));
  std::vector<bool> track_hit(tracks_.size(), false);
  std::vector<bool> ambiguous(tracks_.size(), false);  // a coin toss with another confirmed track this frame
  struct Birth {
    Track track;
    bool refused = false;  // below birth_min_confidence: starts nothing, takes nothing
  };
  std::vector<Birth> born;
  for (size_t cam = 0; cam < zs.size(); ++cam) {
    const std::vector<WorldMeasurement>& z = zs[cam];
    std::vector<bool> z_used(z.size(), false);
    for (const bool confirmed_pass : {true, false}) {
      std::vector<Track*> group;
      std::vector<size_t> index;  // into tracks_, or tracks_.size() + i for born[i]
      for (size_t i = 0; i < tracks_.size(); ++i)
        if ((tracks_[i].id != 0) == confirmed_pass) {
          group.push_back(&tracks_[i]);
          index.push_back(i);
        }
      if (!confirmed_pass)
        for (size_t i = 0; i < born.size(); ++i)
          if (!born[i].refused) {
            group.push_back(&born[i].track);
            index.push_back(tracks_.size() + i);
          }
      std::vector<int> track_to_z;
      Eigen::MatrixXd cost;
      associate(group, z, z_used, track_to_z, &cost);
      // Two confirmed tracks that could as well have each other's detections (targets crossing): a coin toss, which
      // would swap their identities half the time; both coast instead (the frame counts for their life), at most
      // max_prediction_s in a row (two targets flying together: the optimal assignment again).
      std::vector<bool> coast(group.size(), false), occluded(group.size(), false);
      // Occluding each other in this camera (FrameViews::occluded): what it gives them may be either, or both as one.
      if (confirmed_pass && cam < views.occluded.size() && !views.occluded[cam].empty()) {
        const std::vector<int32_t>& ids = views.occluded[cam];
        for (size_t k = 0; k < group.size(); ++k)
          if (track_to_z[k] >= 0 && std::find(ids.begin(), ids.end(), group[k]->id) != ids.end())
            coast[k] = occluded[k] = true;
      }
      if (confirmed_pass && options_.ambiguity_chi2 > 0) {
        const auto c = [&](size_t track, int det) { return cost(static_cast<Eigen::Index>(track), det); };
        for (size_t a = 0; a < group.size(); ++a)
          for (size_t b = a + 1; b < group.size(); ++b) {
            const int i = track_to_z[a], j = track_to_z[b];
            if (i < 0 || j < 0 || is_forbidden(c(a, j)) || is_forbidden(c(b, i))) continue;
            if ((c(a, j) + c(b, i)) - (c(a, i) + c(b, j)) < options_.ambiguity_chi2) coast[a] = coast[b] = true;
          }
      }
      for (size_t k = 0; k < group.size(); ++k) {
        if (!coast[k]) continue;
        ambiguous[index[k]] = true;
        const Track& t = *group[k];
        if (t.coasting_since_utime >= 0 && utime - t.coasting_since_utime > max_coast_us) coast[k] = false;
      }
      for (size_t k = 0; k < group.size(); ++k) {
        if (track_to_z[k] < 0) continue;
        if (index[k] < tracks_.size()) track_hit[index[k]] = true;
        if (coast[k]) {
          group[k]->last_hit_utime = utime;
          ++(occluded[k] ? stats_.occluded : stats_.ambiguous);
          continue;
        }
        hit(*group[k], z[static_cast<size_t>(track_to_z[k])]);
        ++stats_.associated;
      }
    }
    for (size_t j = 0; j < z.size(); ++j) {
      if (z_used[j]) continue;
      Birth b;
      b.refused = z[j].confidence < options_.birth_min_confidence;
      Track& t = b.track;
      t.sc = cv_initialize(z[j].p_target_in_world, z[j].cov_p_in_world, options_.initial_velocity_std);
      t.state_utime = utime;
      t.birth_utime = utime;
      t.last_hit_utime = utime;
      t.frames = 1;
      t.hits = 1;
      t.recent.push_back(true);
      t.recent_confidence.push_back(z[j].confidence);
      t.last = z[j];
      t.window.push_back({utime, z[j].p_target_in_world, z[j].cov_p_in_world});
      t.size = SizeEstimator(options_.size);
      t.size.add(utime, z[j].p_target_in_world, z[j].cov_p_in_world, z[j].p_cam_in_world);
      t.scale = t.size.estimate();  // the prior: 1 +- prior_rel (1 +- 0 when off)
      born.push_back(std::move(b));
    }
  }
  // A coasting run starts with its first ambiguous frame and ends with the first frame that is not.
  for (size_t i = 0; i < tracks_.size(); ++i) {
    if (tracks_[i].id == 0) continue;
    if (!ambiguous[i]) {
      tracks_[i].coasting_since_utime = -1;
    } else if (tracks_[i].coasting_since_utime < 0) {
      tracks_[i].coasting_since_utime = utime;
    }
  }

  // Book-keeping and deletion of the existing tracks.
  const int64_t death_timeout_us = static_cast<int64_t>(std::llround(options_.death_timeout_s * 1e6));
  std::vector<Track> kept;
  kept.reserve(tracks_.size() + born.size());
  for (size_t i = 0; i < tracks_.size(); ++i) {
    Track& t = tracks_[i];
    if (track_hit[i] || !views.could_see || views.could_see(t.sc.x.head<3>())) {  // else: out of every view
      ++t.frames;
      if (track_hit[i]) ++t.hits;
      t.recent.push_back(track_hit[i]);
      while (static_cast<int>(t.recent.size()) > options_.birth_window) t.recent.pop_front();
    } else {
      ++stats_.out_of_view;
    }
    const bool timed_out = utime - t.last_hit_utime > death_timeout_us;
    if (t.id == 0 && (timed_out || t.hits + (options_.birth_window - t.frames) < options_.birth_hits)) {
      ++stats_.tentative_dropped;
      continue;
    }
    if (t.id != 0 && timed_out) {
      ++stats_.deaths;
      if (options_.reacquire_s > 0) lost_.push_back({t.id, t.p_at_last_hit, t.last_hit_utime});
      continue;
    }
    kept.push_back(std::move(t));
  }
  tracks_ = std::move(kept);

  // Confirmation (M of N and the track-level confidence), unless the track only duplicates a confirmed one; then
  // merges.
  for (Track& t : tracks_) {
    if (t.id != 0 || t.hits < options_.birth_hits) continue;
    if (!confident_enough(t)) {
      if (!t.held) ++stats_.confirmations_held;
      t.held = true;
      continue;
    }
    if (duplicates_a_confirmed_track(t)) {
      t.id = -1;  // removed by merge_duplicates()
      ++stats_.merges;
      continue;
    }
    t.id = id_for_confirmed(t, utime);
    ++stats_.confirmations;
  }
  merge_duplicates(utime);

  // Detections no camera's association took start tentative tracks.
  for (Birth& b : born) {
    if (static_cast<int>(tracks_.size()) >= options_.max_tracks) continue;
    if (b.refused) {
      ++stats_.births_refused;
      continue;
    }
    Track& t = b.track;
    ++stats_.births;
    if (t.hits >= options_.birth_hits && confident_enough(t)) {
      t.id = id_for_confirmed(t, utime);
      ++stats_.confirmations;
    }
    tracks_.push_back(std::move(t));
  }

  have_frame_ = true;
  last_frame_utime_ = utime;
  return true;
}

int32_t Tracker::id_for_confirmed(const Track& t, int64_t utime) {
  const int64_t keep_us = static_cast<int64_t>(std::llround(options_.reacquire_s * 1e6));
  // Forget what is too old (or from the future: time went back), then take the nearest remembered track whose gate,
  // grown by how far it may have flown since its last hit, holds t's position now.
  lost_.erase(
      std::remove_if(lost_.begin(), lost_.end(),
                     [&](const Lost& l) { return utime - l.last_hit_utime > keep_us || l.last_hit_utime > utime; }),
      lost_.end());
  const Eigen::Vector3d p = t.sc.p();
  auto best = lost_.end();
  double best_d = 0.0;
  for (auto it = lost_.begin(); it != lost_.end(); ++it) {
    const double dt_s = static_cast<double>(utime - it->last_hit_utime) * 1e-6;
    const double d = (p - it->p_at_last_hit).norm();
    if (d <= options_.reacquire_gate_m + options_.reacquire_speed_mps * dt_s && (best == lost_.end() || d < best_d))
      best = it, best_d = d;
  }
  if (best == lost_.end()) return next_id_++;
  const int32_t id = best->id;
  lost_.erase(best);
  ++stats_.reacquired;
  return id;
}

bool Tracker::confident_enough(const Track& t) const {
  if (options_.confirm_min_confidence <= 0.0) return true;
  if (t.recent_confidence.empty()) return false;
  double sum = 0.0;
  for (const double c : t.recent_confidence) sum += c;
  return sum / static_cast<double>(t.recent_confidence.size()) >= options_.confirm_min_confidence;
}

bool Tracker::same_target(const Track& a, const Track& b) const {
  if (options_.merge_chi2 <= 0) return false;
  const Vector6d d = a.sc.x - b.sc.x;
  return d.dot((a.sc.P + b.sc.P).ldlt().solve(d)) < options_.merge_chi2;
}

bool Tracker::agree(int32_t id_a, int32_t id_b) const {
  const auto find = [this](int32_t id) -> const Track* {
    for (const Track& t : tracks_)
      if (t.id == id && id > 0) return &t;
    return nullptr;
  };
  const Track* a = find(id_a);
  const Track* b = find(id_b);
  return a != nullptr && b != nullptr && a != b && same_target(*a, *b);
}

bool Tracker::duplicates_a_confirmed_track(const Track& t) const {
  for (const Track& c : tracks_)
    if (c.id > 0 && &c != &t && same_target(c, t)) return true;
  return false;
}

void Tracker::merge_duplicates(int64_t utime) {
  const int64_t after_us = static_cast<int64_t>(std::llround(options_.merge_after_s * 1e6));
  std::map<std::pair<int32_t, int32_t>, int64_t> agreeing;  // the pairs that agree now (the others start again)
  for (size_t i = 0; i < tracks_.size(); ++i) {
    for (size_t j = i + 1; j < tracks_.size(); ++j) {
      Track& a = tracks_[i];
      Track& b = tracks_[j];
      if (a.id <= 0 || b.id <= 0 || !same_target(a, b)) continue;  // tentative, already merged, or distinct
      const std::pair<int32_t, int32_t> key{std::min(a.id, b.id), std::max(a.id, b.id)};
      const auto it = agreeing_since_.find(key);
      const int64_t since = it == agreeing_since_.end() ? utime : it->second;
      if (utime - since < after_us) {  // not yet: two targets crossing agree only while they pass
        agreeing[key] = since;
        continue;
      }
      Track& older = a.id < b.id ? a : b;
      Track& younger = a.id < b.id ? b : a;
      const int32_t id = older.id;
      const int64_t birth = older.birth_utime;
      if (younger.last_hit_utime > older.last_hit_utime) older = younger;  // the fresher estimate
      older.id = id;
      older.birth_utime = birth;
      younger.id = -1;  // marked for removal
      ++stats_.merges;
    }
  }
  agreeing_since_ = std::move(agreeing);
  tracks_.erase(std::remove_if(tracks_.begin(), tracks_.end(), [](const Track& t) { return t.id < 0; }), tracks_.end());
}

TrackOutput Tracker::output(const Track& t, int64_t predict_to_utime, bool kalman) const {
  TrackOutput o;
  o.track_id = t.id;
  o.confirmed = t.id > 0;
  o.camera_id = t.last.camera_id;
  o.size_scale = t.scale.scale;
  o.size_scale_sigma = t.scale.sigma;
  o.p_target_in_cam = o.size_scale * t.last.p_target_in_cam;
  o.range = o.size_scale * t.last.range;
  const double hit_fraction =
      static_cast<double>(std::count(t.recent.begin(), t.recent.end(), true)) / options_.birth_window;
  o.confidence = std::clamp(hit_fraction * t.last.confidence, 0.0, 1.0);
  o.source_utime = t.last_hit_utime;
  o.age_s = std::max(0.0, us_to_s(predict_to_utime - t.birth_utime));

  if (mode_ == TrackerMode::kSlidingWindow && !kalman) {
    // Thesis: the mean of the last n_f measurements, published as current (it lags by about
    // (n_f - 1) / 2 frames times the speed). Velocity by finite difference across the window.
    const double n = static_cast<double>(t.window.size());
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    Eigen::Matrix3d sum_R = Eigen::Matrix3d::Zero();
    for (const WindowEntry& e : t.window) {
      mean += e.p;
      sum_R += e.R;
    }
    o.p_target_in_world = mean / n;
    o.cov_p = sum_R / (n * n);
    const WindowEntry& first = t.window.front();
    const WindowEntry& last = t.window.back();
    if (t.window.size() >= 2 && last.utime > first.utime) {
      const double dt = us_to_s(last.utime - first.utime);
      o.v_target_in_world = (last.p - first.p) / dt;
      o.cov_v = (first.R + last.R) / (dt * dt);
    } else {
      o.v_target_in_world.setZero();
      o.cov_v = options_.initial_velocity_std * options_.initial_velocity_std * Eigen::Matrix3d::Identity();
    }
    o.predicted_utime = t.last_hit_utime;
    return o;
  }

  const int64_t max_us = static_cast<int64_t>(std::llround(options_.max_prediction_s * 1e6));
  const int64_t dt_us = std::clamp<int64_t>(predict_to_utime - t.state_utime, 0, max_us);
  const StateCov p = predict(t.sc, options_.accel_noise, us_to_s(dt_us));
  o.p_target_in_world = p.x.head<3>();
  o.v_target_in_world = p.x.tail<3>();
  o.cov_p = p.P.topLeftCorner<3, 3>();
  // The size's share: the whole relative position scales with it.
  const Eigen::Vector3d rel = o.p_target_in_world - t.last.p_cam_in_world;
  o.cov_p += o.size_scale_sigma * o.size_scale_sigma / (o.size_scale * o.size_scale) * rel * rel.transpose();
  o.cov_v = p.P.bottomRightCorner<3, 3>();
  o.predicted_utime = t.state_utime + dt_us;
  return o;
}

std::vector<TrackOutput> Tracker::confirmed(int64_t predict_to_utime) const {
  std::vector<TrackOutput> out;
  const Track* newest = nullptr;
  for (const Track& t : tracks_) {
    if (t.id == 0) continue;
    if (mode_ == TrackerMode::kMostConfident) {
      if (!newest || t.last_hit_utime > newest->last_hit_utime ||
          (t.last_hit_utime == newest->last_hit_utime && t.last.confidence > newest->last.confidence))
        newest = &t;
      continue;
    }
    out.push_back(output(t, predict_to_utime));
  }
  if (newest) out.push_back(output(*newest, predict_to_utime));
  std::sort(out.begin(), out.end(), [](const TrackOutput& a, const TrackOutput& b) { return a.track_id < b.track_id; });
  return out;
}

std::vector<TrackOutput> Tracker::predicted_tracks(int64_t predict_to_utime) const {
  std::vector<TrackOutput> out;
  for (const Track& t : tracks_) {
    if (t.id < 0) continue;  // merged away
    out.push_back(output(t, predict_to_utime, true));
  }
  std::stable_sort(out.begin(), out.end(), [](const TrackOutput& a, const TrackOutput& b) {
    if (a.confirmed != b.confirmed) return a.confirmed;
    if (a.confirmed) return a.track_id < b.track_id;
    return a.confidence > b.confidence;
  });
  return out;
}

}  // namespace wingman::localizer
