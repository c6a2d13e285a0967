// SPDX-License-Identifier: MIT
// Body-to-world poses of the camera vehicle, buffered and interpolated at image exposure times.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

namespace wingman::localizer {

/// The camera vehicle's body pose in the world frame at one time (from own_pose_t).
///
/// Frames: Wingman's body frame is FLU (x forward, y left, z up) and its world frame ENU; see
/// pose_ned_frd_to_enu_flu() for an autopilot that reports NED/FRD. The buffer itself only
/// interpolates and does not care which convention the samples use, as long as it is one.
struct PoseSample {
  int64_t utime = 0;                                                    ///< time the pose refers to, microseconds
  Eigen::Vector3d p_body_in_world = Eigen::Vector3d::Zero();            ///< body origin in the world frame, metres
  Eigen::Quaterniond q_body_to_world = Eigen::Quaterniond::Identity();  ///< rotates body vectors into world
  Eigen::Vector3d v_body_in_world = Eigen::Vector3d::Zero();            ///< body velocity in the world frame, m/s
  /// Covariance of p_body_in_world, m^2, world frame (zero: exact or unknown, adds nothing).
  Eigen::Matrix3d cov_p_body_in_world = Eigen::Matrix3d::Zero();
  /// Variances of small rotations of the body about its own x, y, z axes (roll, pitch, yaw), rad^2 (zero: exact or
  /// unknown). The same numbers in FLU and FRD: the two bodies differ by signs of y and z only.
  Eigen::Vector3d var_rpy_body = Eigen::Vector3d::Zero();
};

/// Converts a pose reported in the NED world frame with an FRD body (PX4, ArduPilot) into Wingman's
/// ENU world frame with an FLU body: p_enu = (e, n, -d), R_flu_to_enu = R_ned_to_enu R_frd_to_ned R_flu_to_frd.
PoseSample pose_ned_frd_to_enu_flu(const PoseSample& ned_frd);

/// Options of the pose buffer (keys `pose.*` of config/localizer.yaml).
struct PoseBufferOptions {
  /// Largest time between the two samples that bracket a query; a longer gap means a dropped
  /// stream and the query is refused rather than interpolated across it. Seconds, > 0.
  double max_gap_s = 0.1;
  /// How far a query may lie after the newest (or before the oldest) sample; such a query holds the
  /// orientation and moves the position by the sample's velocity. Seconds, >= 0.
  double max_extrapolation_s = 0.05;
  /// Samples older than this, counted back from the newest sample, are dropped. Must cover the
  /// detector's latency. Seconds, > 0.
  double history_s = 2.0;
  /// Adds the own pose's reported uncertainty (own_pose_t.has_covariance: position covariance and attitude
  /// variances) to each measurement's world covariance, so the tracker trusts a measurement less when the vehicle
  /// knows its own pose less. false: own poses are taken as exact (as they are when none is reported).
  bool use_covariance = true;

  template <class V>
  void visit(V& v) {
    v("pose.max_gap_s", max_gap_s, "largest gap between the two own poses that bracket an image time, s");
    v("pose.max_extrapolation_s", max_extrapolation_s, "largest extrapolation beyond the newest/oldest own pose, s");
    v("pose.history_s", history_s, "own poses kept, counted back from the newest, s (must cover detector latency)");
    v("pose.use_covariance", use_covariance,
      "add the own pose's reported covariance (own_pose_t.has_covariance) to each measurement's world covariance");
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
};

/// A time-ordered buffer of own poses, queried at image exposure times (never at arrival times).
///
/// Position and velocity are interpolated linearly, orientation by slerp (shortest arc). Samples
/// must arrive with strictly increasing utime; duplicates and out-of-order samples are refused.
class PoseBuffer {
 public:
  /// Throws std::invalid_argument listing options.validate() problems.
  explicit PoseBuffer(PoseBufferOptions options = {});

  /// Adds a sample. Returns false and, when `why` is not null, sets the reason, if the sample is
  /// not newer than the newest one (duplicate or out of order), has non-finite values, or a
  /// quaternion whose norm is not within 1e-3 of 1 (accepted ones are normalised).
  bool add(const PoseSample& sample, std::string* why = nullptr);

  /// The pose at `utime`; the returned sample has `utime` set to the query time. Returns nullopt
  /// and, when `why` is not null, one line saying why: empty buffer, gap between the bracketing
  /// samples longer than max_gap_s, or query further than max_extrapolation_s beyond the samples.
  std::optional<PoseSample> at(int64_t utime, std::string* why = nullptr) const;

  /// Number of samples held.
  size_t size() const { return samples_.size(); }
  /// The newest sample's utime, if any.
  std::optional<int64_t> newest_utime() const;
  const PoseBufferOptions& options() const { return options_; }

 private:
  PoseBufferOptions options_;
  std::deque<PoseSample> samples_;  // strictly increasing utime
};

/// Interpolates between two samples at `utime` (a.utime <= utime <= b.utime, a.utime < b.utime):
/// position, velocity and the covariances linearly, orientation by slerp.
PoseSample interpolate(const PoseSample& a, const PoseSample& b, int64_t utime);

}  // namespace wingman::localizer
