// SPDX-License-Identifier: MIT
// Multi-target tracking in the world frame: gating, association, track birth and death, output modes.
#pragma once

#include "wingman/localizer/kalman_cv3d.hpp"
#include "wingman/localizer/measurement.hpp"
#include "wingman/localizer/size_estimator.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace wingman::localizer {

/// What the tracker publishes for a confirmed track.
enum class TrackerMode {
  kKalman,         ///< the constant-velocity Kalman estimate, predicted to the requested time (default)
  kSlidingWindow,  ///< the thesis's mean of the last n_f associated measurements, not predicted
  kMostConfident,  ///< the thesis's single-target mode: only each frame's most confident detection, one output
};

/// How detections are assigned to tracks.
enum class AssociationMethod {
  kHungarian,  ///< optimal global nearest neighbour (least total Mahalanobis^2), default
  kGreedy,     ///< cheapest pair first
};

/// Options of the tracker (keys `tracker.*` of config/localizer.yaml).
struct TrackerOptions {
  /// Output mode: "kalman", "sliding_window" or "most_confident" (see TrackerMode).
  std::string mode = "kalman";
  /// Assignment method: "hungarian" or "greedy".
  std::string association = "hungarian";
  /// Acceleration noise density of the constant-velocity model, m s^-1.5 (kalman_cv3d.hpp). >= 0.
  double accel_noise = 1.0;
  /// Gate on the squared Mahalanobis distance of a detection to a track's predicted position
  /// (chi-square, 3 dof: 16.27 keeps 99.9 %, 11.34 keeps 99 %). 99.9 %: a manoeuvring target
  /// (2.5 m/s^2) outruns the constant-velocity model and a 99 % gate then splits it in two. > 0.
  double gate_chi2 = 16.27;
  /// M of the M-of-N birth rule: hits a tentative track needs within its first N frames. >= 1.
  /// 10 of 15 with confirm_min_confidence 0.4 (at 30 frames/s: half a second of evidence) was chosen on the
  /// clip-disjoint Halmstad val split (docs/training.md, "Track-level metrics"): against 3 of 5 without a confidence
  /// bar, 28 false tracks instead of 71 on its 22 distractor clips, 17 of 18 drone clips confirmed instead of 18.
  int birth_hits = 10;
  /// N of the M-of-N birth rule, frames (calls of update()); a tentative track that can no longer
  /// reach M hits within N frames is dropped. >= birth_hits.
  int birth_window = 15;
  /// Two-level birth (as ByteTrack): a detection below this confidence updates a track it is associated with but
  /// never starts one. 0 = every detection may start a track. [0, 1].
  double birth_min_confidence = 0.0;
  /// Track-level evidence: a tentative track is confirmed only once the mean detection confidence of its last
  /// birth_window hits also reaches this (and stays tentative, not dropped, while it falls short and keeps being
  /// hit). 0 = the M-of-N rule alone. [0, 1].
  double confirm_min_confidence = 0.4;
  /// A track without a hit for longer than this (image time) is deleted. Seconds, > 0.
  double death_timeout_s = 1.0;
  /// Re-acquisition: a confirmed track deleted (death_timeout_s) less than this long ago is remembered (its id and
  /// where it was at its last hit); a tentative track confirmed within reacquire_gate_m + reacquire_speed_mps x (the
  /// time since that last hit) of a remembered one takes its id instead of a new one (the nearest such), so a drone
  /// that leaves every view, or is missed for a while, and comes back keeps its identity. Seconds, >= 0 (0 = off).
  double reacquire_s = 10.0;
  /// How fast a remembered target may have moved while unseen, m/s (the gate's growth), >= 0.
  double reacquire_speed_mps = 5.0;
  /// The gate's radius at the last hit: the range error of a track, m, > 0.
  double reacquire_gate_m = 2.0;
  /// n_f of the sliding-window mode: measurements averaged (thesis: 5). >= 1.
  int window_size = 5;
  /// Standard deviation of a new track's velocity on each axis, m/s. > 0.
  double initial_velocity_std = 5.0;
  /// Lag compensation horizon: confirmed() predicts at most this far past a track's state time. Seconds, >= 0.
  double max_prediction_s = 1.0;
  /// Tracks (tentative + confirmed) kept at most; detections beyond start no track. >= 1.
  int max_tracks = 64;
  /// Two tracks whose full states (position and velocity) differ by a squared Mahalanobis distance
  /// below this (chi-square, 6 dof: 16.81 = 99 %) are one target followed twice (after a manoeuvre
  /// the gate missed, or duplicate detections): a tentative one is not confirmed, and two confirmed
  /// ones are merged into the older id. 0 disables. Crossing targets differ in velocity and are not
  /// merged. >= 0.
  double merge_chi2 = 16.81;
  /// Two confirmed tracks are merged only once they have agreed (merge_chi2) in every frame for this long: one target
  /// followed twice stays together, two targets crossing agree only while they pass (with 1 m of range noise along
  /// one's path, 2 of 40 seeded 90-degree crossings at 3 m/s merged at once). Seconds, >= 0 (0: at once).
  double merge_after_s = 1.0;
  /// Crossing targets: when giving two confirmed tracks each other's detections costs less than this much more
  /// squared Mahalanobis distance than the optimal assignment, which detection is whose is a coin toss: neither track
  /// takes one; both coast on their constant-velocity prediction (the frame counts as a hit for their life) for at
  /// most max_prediction_s in a row, and the two detections start no track. 0 = always the optimal assignment. >= 0.
  double ambiguity_chi2 = 2.0;
  /// Occlusion: two confirmed tracks whose predicted image boxes in a camera, each grown by this fraction of its size
  /// on every side, touch are occluding each other there (the Localizer decides, FrameViews::occluded): a detector
  /// may then box either drone, or both as one box, so what that camera's association gives them updates neither;
  /// both coast as for ambiguity_chi2 (at most max_prediction_s in a row). Fraction of the box size, >= 0 (0: the
  /// boxes themselves must overlap); occlusion_coast false = off.
  double occlusion_margin = 0.5;
  bool occlusion_coast = true;  ///< the occlusion rule above on (Localizer only: Tracker::update() has no images)
  /// Online size estimation (tracker.size_*): each track's range scale from the camera's motion relative to it.
  SizeEstimatorOptions size;

  template <class V>
  void visit(V& v) {
    v("tracker.mode", mode, "kalman | sliding_window (thesis, n_f mean) | most_confident (thesis, single target)");
    v("tracker.association", association, "hungarian | greedy");
    v("tracker.accel_noise", accel_noise, "acceleration noise density of the constant-velocity model, m s^-1.5");
    v("tracker.gate_chi2", gate_chi2, "gate on squared Mahalanobis distance (3 dof: 16.27 = 99.9 %, 11.34 = 99 %)");
    v("tracker.birth_hits", birth_hits, "M: hits a tentative track needs within its first N frames");
    v("tracker.birth_window", birth_window, "N: frames a tentative track has to collect M hits");
    v("tracker.birth_min_confidence", birth_min_confidence,
      "a detection below this confidence continues a track but starts none, 0..1 (0 = any)");
    v("tracker.confirm_min_confidence", confirm_min_confidence,
      "a tentative track is confirmed once the mean confidence of its last N hits reaches this, 0..1 (0 = off)");
    v("tracker.death_timeout_s", death_timeout_s, "a track without a hit for this long is deleted, s");
    v("tracker.reacquire_s", reacquire_s,
      "a confirmed track deleted less than this long ago gives its id to a track confirmed near it, s (0 = off)");
    v("tracker.reacquire_speed_mps", reacquire_speed_mps,
      "re-acquisition gate: how fast the unseen target may have moved since its last hit, m/s");
    v("tracker.reacquire_gate_m", reacquire_gate_m, "re-acquisition gate: its radius at the last hit, m");
    v("tracker.window_size", window_size, "n_f: measurements averaged in sliding_window mode");
    v("tracker.initial_velocity_std", initial_velocity_std, "velocity standard deviation of a new track, m/s");
    v("tracker.max_prediction_s", max_prediction_s, "lag compensation: longest prediction past a track's state, s");
    v("tracker.max_tracks", max_tracks, "tracks (tentative + confirmed) kept at most");
    v("tracker.merge_chi2", merge_chi2,
      "merge confirmed tracks closer than this in state (6 dof: 16.81 = 99 %); 0 = off");
    v("tracker.ambiguity_chi2", ambiguity_chi2,
      "two confirmed tracks whose detections could be swapped within this much squared Mahalanobis distance coast "
      "instead (crossing targets); 0 = off");
    v("tracker.occlusion_coast", occlusion_coast,
      "two confirmed tracks whose predicted image boxes touch (a detector may box either, or both as one) are not "
      "updated by that camera's detections: they coast");
    v("tracker.occlusion_margin", occlusion_margin,
      "the predicted boxes are grown by this fraction of their size on every side before the touch test, >= 0");
    v("tracker.merge_after_s", merge_after_s,
      "confirmed tracks are merged once they have agreed in state for this long, s (0 = at once)");
    size.visit(v);
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;

  /// `mode` as an enum. Precondition: validate() is empty.
  TrackerMode mode_enum() const;
  /// `association` as an enum. Precondition: validate() is empty.
  AssociationMethod association_enum() const;
};

/// One confirmed track as published (or, from Tracker::predicted_tracks(), a tentative one too).
struct TrackOutput {
  int32_t track_id = 0;   ///< 1, 2, ... in order of confirmation (a re-acquired target keeps its old one); 0 tentative
  bool confirmed = true;  ///< false: a tentative track (predicted_tracks() only)
  int32_t camera_id = 0;  ///< camera of the last detection used
  Eigen::Vector3d p_target_in_world = Eigen::Vector3d::Zero();  ///< at predicted_utime, m
  Eigen::Vector3d v_target_in_world = Eigen::Vector3d::Zero();  ///< m/s
  Eigen::Matrix3d cov_p = Eigen::Matrix3d::Identity();          ///< covariance of p_target_in_world, m^2
  Eigen::Matrix3d cov_v = Eigen::Matrix3d::Identity();          ///< covariance of v_target_in_world, (m/s)^2
  Eigen::Vector3d p_target_in_cam = Eigen::Vector3d::Zero();    ///< the last detection's x size_scale, camera frame, m
  double range = 0;                                             ///< the last detection's range, m, times size_scale
  /// The track's range scale (true bounding radius / target.radius_m: SizeEstimator; 1 without size estimation) and
  /// its standard deviation (0 without). cov_p includes the scale's share along the line of sight.
  double size_scale = 1.0, size_scale_sigma = 0.0;
  double confidence = 0;        ///< fraction of the last N frames with a hit x last detection confidence, 0..1
  int64_t source_utime = 0;     ///< exposure utime of the newest image that updated the track
  int64_t predicted_utime = 0;  ///< time the state refers to (lag compensation), microseconds
  double age_s = 0;             ///< time since the track's first detection, at the requested time, s
};

/// Counters for the status message and the log.
struct TrackerStats {
  int64_t frames = 0;                 ///< update() calls accepted
  int64_t frames_rejected = 0;        ///< update() calls refused (time not increasing)
  int64_t measurements = 0;           ///< measurements accepted
  int64_t measurements_rejected = 0;  ///< non-finite or ignored (most_confident keeps one per frame)
  int64_t associated = 0;             ///< measurements that updated a track
  int64_t births = 0;                 ///< tentative tracks started
  int64_t confirmations = 0;          ///< tentative tracks confirmed
  /// tentative tracks held back at least once by confirm_min_confidence (M of N reached, the mean confidence not)
  int64_t confirmations_held = 0;
  /// detections that started no track because they were below birth_min_confidence
  int64_t births_refused = 0;
  int64_t tentative_dropped = 0;  ///< tentative tracks that failed the M-of-N rule or timed out
  int64_t deaths = 0;             ///< confirmed tracks deleted after death_timeout_s
  int64_t reacquired = 0;         ///< tracks confirmed with the id of a deleted one (reacquire_s)
  int64_t merges = 0;             ///< duplicates merged into an older confirmed track (or not confirmed)
  int64_t ambiguous = 0;          ///< confirmed-track updates skipped as a coin toss between two tracks (coasted)
  int64_t occluded = 0;           ///< confirmed-track updates skipped: occluding another track there (coasted)
  /// track-frames left out of the hit-and-miss count: the track out of the view of every camera of the frame
  int64_t out_of_view = 0;
};

/// What one frame's cameras tell the tracker beyond their measurements (Tracker::update_cameras; the Localizer knows
/// the cameras, the tracker works in the world frame). Empty: nothing (every track counts every frame, no occlusion).
struct FrameViews {
  /// Whether one of the frame's cameras could see a target at a world position (ENU, m; each track's position
  /// predicted to the frame). A track it says no to, and that no camera hit, is left out of the frame's hit-and-miss
  /// count (the M of N of its birth): the frame of a camera that looks elsewhere is no miss. Its death timeout runs
  /// all the same. Empty: every frame counts for every track.
  std::function<bool(const Eigen::Vector3d&)> could_see;
  /// Per camera (per_camera's order; empty or shorter: none): the ids of the confirmed tracks occluding each other in
  /// that camera (TrackerOptions::occlusion_margin). The detections that camera's association gives them update
  /// neither: they coast, at most max_prediction_s in a row (then the association's choice holds again).
  std::vector<std::vector<int32_t>> occluded;
};

/// Tracks targets from world-frame detections, one frame (image) at a time.
///
/// Per frame: every track is predicted to the frame's exposure time; confirmed tracks take their
/// detections first, then tentative ones take what is left (each by hungarian() or greedy_assign()
/// on the squared Mahalanobis distances, pairs outside tracker.gate_chi2 forbidden); matched tracks
/// are updated, detections left over start tentative tracks. A tentative track is confirmed once it
/// has M hits within its first N frames, so an isolated false positive or a burst of scattered ones
/// never becomes a target. A track is deleted when it has had no hit for death_timeout_s. Two
/// confirmed tracks that agree in position and velocity (merge_chi2) are merged into the older id,
/// with the state of whichever was updated last.
/// Every mode runs this Kalman tracker for association; the mode decides what is published.
class Tracker {
 public:
  /// Throws std::invalid_argument listing options.validate() problems.
  explicit Tracker(TrackerOptions options = {});

  /// Processes one frame's detections (possibly none); `utime` is the image's exposure utime and
  /// must be later than the previous frame's. Returns false (and sets `why` when not null) for a
  /// frame that is not later; such a frame changes nothing. Non-finite measurements are skipped;
  /// each measurement's own utime is ignored (the frame's `utime` is used).
  bool update(int64_t utime, const std::vector<WorldMeasurement>& measurements, std::string* why = nullptr);

  /// One frame of several cameras (one exposure of a camera rig): `per_camera[i]` are camera i's measurements, in
  /// the rig's order. Each camera's measurements are associated in turn against the tracks as the cameras before it
  /// left them (confirmed tracks first, then tentative ones, then the tracks the cameras before it started this
  /// frame), so a target that two overlapping cameras see stays one track; a measurement no camera's association
  /// took starts a track. Hits and misses count once per frame: a frame is a hit for a track when any camera hit it.
  /// most_confident keeps the one most confident measurement of the whole frame. With one camera this is
  /// update(utime, per_camera[0], why). Returns false (and sets `why`) for a frame that is not later.
  /// `views`: what the frame's cameras tell beyond their measurements (FrameViews; the Localizer fills it).
  bool update_cameras(int64_t utime, const std::vector<std::vector<WorldMeasurement>>& per_camera,
                      std::string* why = nullptr, const FrameViews& views = {});

  /// The confirmed tracks, ordered by track_id, with their state predicted to `predict_to_utime`
  /// (the publish time; lag compensation). The prediction is limited to [state time, state time +
  /// max_prediction_s]; predicted_utime says where it ended. sliding_window mode does not predict
  /// (predicted_utime = source_utime); most_confident mode returns at most the one track with the
  /// newest hit.
  std::vector<TrackOutput> confirmed(int64_t predict_to_utime) const;

  /// Every track held, confirmed (by track_id) then tentative (track_id 0, confirmed false; most confident first),
  /// with its constant-velocity Kalman state predicted to `predict_to_utime` whatever the mode (at most
  /// max_prediction_s past the state): where each will be at the next exposure (tracker-driven windows).
  std::vector<TrackOutput> predicted_tracks(int64_t predict_to_utime) const;

  /// Whether confirmed tracks `id_a` and `id_b` agree in state (merge_chi2, their last frame's states): one target
  /// followed twice, which the merge rule will join. False for an unknown id or with merge_chi2 0.
  bool agree(int32_t id_a, int32_t id_b) const;
  /// Tentative tracks that have their M hits but are held back by confirm_min_confidence right now.
  size_t num_held() const;
  /// Tentative (not yet confirmed) tracks held.
  size_t num_tentative() const;
  /// Confirmed tracks held.
  size_t num_confirmed() const;
  const TrackerStats& stats() const { return stats_; }
  const TrackerOptions& options() const { return options_; }

 private:
  struct WindowEntry {
    int64_t utime;
    Eigen::Vector3d p;
    Eigen::Matrix3d R;
  };
  struct Track {
    int32_t id = 0;  // 0 while tentative, -1 once merged away
    StateCov sc;
    int64_t state_utime = 0;                                  // time sc refers to
    int64_t birth_utime = 0;                                  // first detection
    int64_t last_hit_utime = 0;                               // newest detection
    int frames = 0;                                           // frames since birth, the birth frame included
    int hits = 0;                                             // hits since birth
    std::deque<bool> recent;                                  // hit or miss of the last birth_window frames
    std::deque<double> recent_confidence;                     // detection confidence of the last birth_window hits
    bool held = false;                                        // once held back by confirm_min_confidence (counted once)
    std::deque<WindowEntry> window;                           // last window_size detections
    WorldMeasurement last;                                    // newest detection (as detected: the configured size)
    Eigen::Vector3d p_at_last_hit = Eigen::Vector3d::Zero();  // the filter's position after the newest detection
    SizeEstimator size;                                       // the track's detections for its range scale
    SizeEstimate scale;                 // the adopted range scale: detections enter the filter at c + s (z - c)
    SizeEstimate candidate;             // an acceptable fit waiting for a second, later one that agrees with it
    int64_t candidate_utime = -1;       // its time; -1: none
    int64_t coasting_since_utime = -1;  // first frame of the current run of ambiguous frames; -1: none
  };

  /// `cost` (optional): the tracks x detections squared Mahalanobis distances (kForbiddenCost outside the gates).
  void associate(std::vector<Track*>& tracks, const std::vector<WorldMeasurement>& z, std::vector<bool>& z_used,
                 std::vector<int>& track_to_z, Eigen::MatrixXd* cost = nullptr) const;
  void hit(Track& t, const WorldMeasurement& z);
  /// `kalman`: the Kalman state whatever the mode (predicted_tracks()).
  TrackOutput output(const Track& t, int64_t predict_to_utime, bool kalman = false) const;
  bool same_target(const Track& a, const Track& b) const;
  /// The mean confidence of t's last birth_window hits reaches confirm_min_confidence (always true when it is 0).
  bool confident_enough(const Track& t) const;
  bool duplicates_a_confirmed_track(const Track& t) const;
  void merge_duplicates(int64_t utime);  // also removes tracks marked id = -1
  /// The id for `t`, confirmed at `utime`: a remembered (deleted) track's whose gate holds it (reacquire_s), the
  /// nearest, else a new one.
  int32_t id_for_confirmed(const Track& t, int64_t utime);

  /// A deleted confirmed track, remembered for re-acquisition.
  struct Lost {
    int32_t id;
    Eigen::Vector3d p_at_last_hit;
    int64_t last_hit_utime;
  };
  std::vector<Lost> lost_;

  TrackerOptions options_;
  TrackerMode mode_;
  /// Pairs of confirmed track ids (smaller first) that agree in state, and the first frame of their agreement.
  std::map<std::pair<int32_t, int32_t>, int64_t> agreeing_since_;
  AssociationMethod association_;
  std::vector<Track> tracks_;
  int32_t next_id_ = 1;
  bool have_frame_ = false;
  int64_t last_frame_utime_ = 0;
  TrackerStats stats_;
};

}  // namespace wingman::localizer
