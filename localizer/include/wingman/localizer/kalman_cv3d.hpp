// SPDX-License-Identifier: MIT
// A stateless 3D constant-velocity Kalman filter: one model serves every track (mrs_lib style).
#pragma once

#include <Eigen/Core>

namespace wingman::localizer {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// A track's estimate: state x = [p_target_in_world (m); v_target_in_world (m/s)] and its
/// covariance P (m^2, m^2/s, m^2/s^2 blocks). The filter functions take and return it by value and
/// keep nothing between calls.
struct StateCov {
  Vector6d x = Vector6d::Zero();
  Matrix6d P = Matrix6d::Identity();

  Eigen::Vector3d p() const { return x.head<3>(); }
  Eigen::Vector3d v() const { return x.tail<3>(); }
};

/// State transition of the constant-velocity model over dt seconds: F = [I, dt I; 0, I].
Matrix6d cv_transition(double dt);

/// Process noise of the continuous white-noise-acceleration model (Bar-Shalom, Li, Kirubarajan 2001,
/// sec. 6.2.2), per axis q [dt^3/3, dt^2/2; dt^2/2, dt] with q = accel_noise^2, so that predicting
/// over dt1 then dt2 equals predicting over dt1 + dt2. accel_noise: standard deviation density of
/// the target's acceleration, m/s^2 per sqrt(Hz) (= m s^-1.5); larger follows manoeuvres faster.
Matrix6d cv_process_noise(double accel_noise, double dt);

/// Starts a track at a position measurement z (world, m) with covariance R (m^2): position from z
/// and R, velocity zero with standard deviation velocity_std (m/s) on each axis, uncorrelated.
StateCov cv_initialize(const Eigen::Vector3d& z, const Eigen::Matrix3d& R, double velocity_std);

/// Predicts over dt seconds: x' = F x, P' = F P F^T + Q(accel_noise, dt).
/// Precondition: dt >= 0 (throws std::invalid_argument otherwise), accel_noise >= 0.
StateCov predict(const StateCov& sc, double accel_noise, double dt);

/// Updates with a position measurement z (world, m) of covariance R (m^2, symmetric positive
/// definite), H = [I 0]: K = P H^T S^-1, x' = x + K (z - H x), P' by the Joseph form
/// (I - K H) P (I - K H)^T + K R K^T, which stays symmetric positive semi-definite.
StateCov update(const StateCov& sc, const Eigen::Vector3d& z, const Eigen::Matrix3d& R);

/// Innovation covariance S = H P H^T + R = P_pp + R, m^2.
Eigen::Matrix3d innovation_covariance(const StateCov& sc, const Eigen::Matrix3d& R);

/// Squared Mahalanobis distance of the innovation, (z - p)^T S^-1 (z - p); chi-square with 3
/// degrees of freedom for a consistent filter (gate: 11.34 keeps 99 %, 7.81 keeps 95 %).
double mahalanobis2(const StateCov& sc, const Eigen::Vector3d& z, const Eigen::Matrix3d& R);

}  // namespace wingman::localizer
