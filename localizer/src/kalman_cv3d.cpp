// SPDX-License-Identifier: MIT
// Constant-velocity Kalman filter: transition, CWNA process noise, Joseph-form update, gating distance.
#include "wingman/localizer/kalman_cv3d.hpp"

#include <Eigen/Cholesky>

#include <stdexcept>
#include <string>

namespace wingman::localizer {

Matrix6d cv_transition(double dt) {
  Matrix6d F = Matrix6d::Identity();
  F.topRightCorner<3, 3>() = dt * Eigen::Matrix3d::Identity();
  return F;
}

Matrix6d cv_process_noise(double accel_noise, double dt) {
  const double q = accel_noise * accel_noise;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  Matrix6d Q;
  Q.topLeftCorner<3, 3>() = q * dt * dt * dt / 3.0 * I;
  Q.topRightCorner<3, 3>() = q * dt * dt / 2.0 * I;
  Q.bottomLeftCorner<3, 3>() = q * dt * dt / 2.0 * I;
  Q.bottomRightCorner<3, 3>() = q * dt * I;
  return Q;
}

StateCov cv_initialize(const Eigen::Vector3d& z, const Eigen::Matrix3d& R, double velocity_std) {
  StateCov sc;
  sc.x.head<3>() = z;
  sc.x.tail<3>().setZero();
  sc.P.setZero();
  sc.P.topLeftCorner<3, 3>() = 0.5 * (R + R.transpose());
  sc.P.bottomRightCorner<3, 3>() = velocity_std * velocity_std * Eigen::Matrix3d::Identity();
  return sc;
}

StateCov predict(const StateCov& sc, double accel_noise, double dt) {
  if (!(dt >= 0)) throw std::invalid_argument("kalman_cv3d predict: dt = " + std::to_string(dt) + ": must be >= 0");
  const Matrix6d F = cv_transition(dt);
  StateCov out;
  out.x = F * sc.x;
  out.P = F * sc.P * F.transpose() + cv_process_noise(accel_noise, dt);
  out.P = 0.5 * (out.P + out.P.transpose());
  return out;
}

Eigen::Matrix3d innovation_covariance(const StateCov& sc, const Eigen::Matrix3d& R) {
  return sc.P.topLeftCorner<3, 3>() + R;
}

StateCov update(const StateCov& sc, const Eigen::Vector3d& z, const Eigen::Matrix3d& R) {
  const Eigen::Matrix3d S = innovation_covariance(sc, R);
  const Eigen::Matrix<double, 6, 3> PHt = sc.P.leftCols<3>();  // P H^T with H = [I 0]
  // K = P H^T S^-1, computed as (S^-1 H P)^T with a Cholesky solve (S is symmetric positive definite).
  const Eigen::Matrix<double, 6, 3> K = S.ldlt().solve(PHt.transpose()).transpose();
  StateCov out;
  out.x = sc.x + K * (z - sc.x.head<3>());
  Matrix6d IKH = Matrix6d::Identity();
  IKH.leftCols<3>() -= K;  // I - K H
  out.P = IKH * sc.P * IKH.transpose() + K * R * K.transpose();
  out.P = 0.5 * (out.P + out.P.transpose());
  return out;
}

double mahalanobis2(const StateCov& sc, const Eigen::Vector3d& z, const Eigen::Matrix3d& R) {
  const Eigen::Vector3d y = z - sc.x.head<3>();
  return y.dot(innovation_covariance(sc, R).ldlt().solve(y));
}

}  // namespace wingman::localizer
