// SPDX-License-Identifier: MIT
// The error of the camera vehicle's reported pose: what a flight controller's estimator gets wrong about itself.
#pragma once

#include "wingman/sim/multirotor.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace wingman::sim {

/// Options of the reported pose's error (keys `own_pose.*` of config/sim.yaml). Off by default (both standard
/// deviations 0): the simulator reports the true pose.
struct OwnPoseErrorOptions {
  /// Standard deviation of each world-frame position axis of the error, metres, >= 0.
  double position_std_m = 0.0;
  /// Standard deviation of each small rotation of the body about its own x, y, z axes (roll, pitch, yaw), rad, >= 0.
  double attitude_std_rad = 0.0;
  /// Correlation time of the error (each axis a first-order Gauss-Markov process, as an estimator's error drifts
  /// rather than jumps from sample to sample), seconds, > 0.
  double correlation_time_s = 2.0;
  /// Seed of the error's random numbers, >= 0.
  int64_t seed = 1;
  /// Report the error's covariance with the pose (own_pose_t.has_covariance; ODOMETRY.pose_covariance over
  /// MAVLink): position_std_m^2 on each position axis, attitude_std_rad^2 on each rotation. false: unknown.
  bool report_covariance = true;

  template <class V>
  void visit(V& v) {
    v("own_pose.position_std_m", position_std_m, "reported pose error: std of each world position axis, m (0 = exact)");
    v("own_pose.attitude_std_rad", attitude_std_rad,
      "reported pose error: std of each body rotation (roll, pitch, yaw), rad (0 = exact)");
    v("own_pose.correlation_time_s", correlation_time_s, "correlation time of the error (Gauss-Markov), s");
    v("own_pose.seed", seed, "seed of the error");
    v("own_pose.report_covariance", report_covariance,
      "report the error's covariance with the pose (own_pose_t.has_covariance, ODOMETRY.pose_covariance)");
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
  bool enabled() const { return position_std_m > 0 || attitude_std_rad > 0; }
};

/// The reported pose's error over time: each of the six axes (world position x, y, z; body rotations about x, y,
/// z) is an independent stationary first-order Gauss-Markov process, e(t + dt) = a e(t) + sqrt(1 - a^2) sigma n,
/// a = exp(-dt / correlation_time_s), started from its stationary distribution. Deterministic for a seed and a
/// sequence of query times.
class OwnPoseError {
 public:
  /// Throws std::invalid_argument listing options.validate() problems.
  explicit OwnPoseError(const OwnPoseErrorOptions& options);

  /// The reported state at `utime` (microseconds; queries must not go back in time, std::invalid_argument
  /// otherwise): the true position plus the position error, the true orientation turned by the rotation error
  /// (R_reported = R_true exp([dtheta]x), dtheta in the body frame); velocity and rates as they are.
  MultirotorState reported(const MultirotorState& truth, int64_t utime);

  const OwnPoseErrorOptions& options() const { return options_; }
  /// The error now: world position (m) and body rotation (rad).
  const Eigen::Vector3d& position_error() const { return dp_world_; }
  const Eigen::Vector3d& rotation_error() const { return dtheta_body_; }

 private:
  OwnPoseErrorOptions options_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  int64_t last_utime_ = 0;
  bool started_ = false;
  Eigen::Vector3d dp_world_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d dtheta_body_ = Eigen::Vector3d::Zero();
};

}  // namespace wingman::sim
