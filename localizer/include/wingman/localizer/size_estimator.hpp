// SPDX-License-Identifier: MIT
// Online size estimation: a track's range scale from the camera's motion relative to the target.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace wingman::localizer {

/// Options of the size estimator (keys `tracker.size_*` of config/localizer.yaml).
struct SizeEstimatorOptions {
  /// Estimate each target's size online; false (default): the configured size is used as it is. Off by default: in
  /// the formation flight with ground-truth boxes, from a radius 30 % too small, it first adopted a size 20 % too
  /// large as the leader turned and the follower lagged (a manoeuvre both share, both fits of the pair agreeing);
  /// 30 % too large, it adopted nothing in 40 s (docs/localization.md, "Online size").
  bool enabled = false;
  /// Standard deviation of the range scale before any evidence: how far target.radius_m (with the box relation) may
  /// be off, relative. The prior is 1 +- this. (0, 1].
  double prior_rel = 0.3;
  /// Detections of the last window_s seconds are fitted (the target is taken to fly at constant acceleration over
  /// it). > 0.
  double window_s = 4.0;
  /// A scale is reported only from at least this many detections spanning 90 % of the window at least (a fit on the
  /// first seconds of a track, through the follower's start, was adopted 21 % off in a flight). >= 3.
  int min_detections = 10;
  /// The tracker adopts a fit only when its sigma is at most this fraction of the scale and the straight-path model
  /// fits (chi-square per degree of freedom <= kMaxFitChi2Dof); until then the track keeps the scale it has (1 at
  /// birth). (0, 1].
  double accept_rel = 0.05;

  template <class V>
  void visit(V& v) {
    v("tracker.size_estimation", enabled,
      "estimate each target's size (range scale) online from the camera's motion across the line of sight");
    v("tracker.size_prior_rel", prior_rel,
      "standard deviation of the range scale before evidence (target.radius_m's doubt)");
    v("tracker.size_window_s", window_s, "detections of this many seconds are fitted (constant acceleration), s");
    v("tracker.size_min_detections", min_detections, "detections a scale needs (spanning 90 % of the window at least)");
    v("tracker.size_accept_rel", accept_rel,
      "a track adopts a fitted scale only when its sigma is at most this fraction of it (and the fit holds)");
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
};

/// The range scale of one track and its standard deviation.
struct SizeEstimate {
  double scale = 1.0;      ///< true bounding radius / configured one (1: the configuration is right)
  double sigma = 0.0;      ///< standard deviation of scale; the prior's while there is no evidence
  bool from_data = false;  ///< false: the prior (too few detections, or a camera that did not move relative to it)
  double chi2_dof = 0.0;   ///< the straight-path fit's chi-square per degree of freedom (from_data only)

  /// Whether a tracker should adopt this estimate (see SizeEstimatorOptions::accept_rel).
  bool acceptable(double accept_rel) const;
};

/// The largest chi-square per degree of freedom of a fit a tracker adopts: above it the target did not fly straight
/// over the window (a turn), which biases the fit.
inline constexpr double kMaxFitChi2Dof = 3.0;

/// Estimates a target's range scale s from its detections and the camera's positions.
///
/// The localizer turns each box into a position z with the configured radius r0 (and the box relation); a target of
/// radius s r0 seen in the same box lies s times as far along the same ray, at c + s (z - c) from the camera centre c
/// (the tangent-plane solution is linear in the radius). Over a short window the target flies at constant
/// acceleration, so with w = 1 / s, in the detections' own space,
///     z_i - c_i = (p0 + v t_i + a t_i^2 / 2 - c_i) w + e_i,   e_i ~ N(0, R_i)      for every detection i,
/// which is linear in (w p0, w v, w a, w): a weighted least-squares fit with the prior w = 1 +- prior_rel. The scale
/// is observable when the camera's path relative to the target is not a parabola over the window: a follower that
/// weaves or zigzags across the line of sight. When the camera does not move, moves in lock step with the target, or
/// both fly straight or along the same curve, any size fits and the fit returns the prior (its sigma says so). A
/// leader that turns while its follower lags it bends the relative path the wrong way for the model: the fit's
/// chi-square per degree of freedom then exceeds kMaxFitChi2Dof and the tracker does not adopt it
/// (docs/localization.md, "Online size").
class SizeEstimator {
 public:
  /// Precondition: options.validate() is empty (std::invalid_argument otherwise).
  explicit SizeEstimator(SizeEstimatorOptions options = {});

  /// Adds a detection at `utime` (microseconds): z_in_world taken from camera centre c_in_world (metres, world
  /// frame), covariance R (m^2). Detections older than window_s before the newest are dropped.
  void add(int64_t utime, const Eigen::Vector3d& z_in_world, const Eigen::Matrix3d& R,
           const Eigen::Vector3d& c_in_world);

  /// The scale from the detections held (the prior when disabled, or with too few detections).
  SizeEstimate estimate() const;

  size_t size() const { return samples_.size(); }

 private:
  struct Sample {
    int64_t utime;
    Eigen::Vector3d r;  // z - c
    Eigen::Vector3d c;
    Eigen::Matrix3d R;
  };
  SizeEstimatorOptions options_;
  std::deque<Sample> samples_;
};

}  // namespace wingman::localizer
