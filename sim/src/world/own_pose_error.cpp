// SPDX-License-Identifier: MIT
// OwnPoseError: first-order Gauss-Markov errors on the reported position and attitude.
#include "wingman/sim/own_pose_error.hpp"

#include <wingman/common/config.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <stdexcept>

namespace wingman::sim {

std::vector<std::string> OwnPoseErrorOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (!(position_std_m >= 0 && position_std_m <= 1000))
    p.push_back(problem("own_pose.position_std_m", position_std_m, "must be in [0, 1000]"));
  if (!(attitude_std_rad >= 0 && attitude_std_rad <= 1))
    p.push_back(problem("own_pose.attitude_std_rad", attitude_std_rad, "must be in [0, 1] (a small rotation)"));
  if (!(correlation_time_s > 0 && correlation_time_s <= 1e6))
    p.push_back(problem("own_pose.correlation_time_s", correlation_time_s, "must be in (0, 1e6]"));
  if (seed < 0) p.push_back(problem("own_pose.seed", seed, "must be >= 0"));
  return p;
}

OwnPoseError::OwnPoseError(const OwnPoseErrorOptions& options)
    : options_(options), rng_(static_cast<uint64_t>(options.seed)) {
  const auto problems = options_.validate();
  if (!problems.empty()) {
    std::string all = "invalid OwnPoseErrorOptions:";
    for (const auto& q : problems) all += " " + q + ";";
    throw std::invalid_argument(all);
  }
}

MultirotorState OwnPoseError::reported(const MultirotorState& truth, int64_t utime) {
  const double sp = options_.position_std_m, sa = options_.attitude_std_rad;
  if (!started_) {  // the stationary distribution
    for (int i = 0; i < 3; ++i) dp_world_[i] = sp * normal_(rng_);
    for (int i = 0; i < 3; ++i) dtheta_body_[i] = sa * normal_(rng_);
    started_ = true;
  } else {
    if (utime < last_utime_)
      throw std::invalid_argument("OwnPoseError::reported: utime " + std::to_string(utime) + " is before " +
                                  std::to_string(last_utime_));
    const double a = std::exp(-static_cast<double>(utime - last_utime_) * 1e-6 / options_.correlation_time_s);
    const double b = std::sqrt(std::max(0.0, 1.0 - a * a));
    for (int i = 0; i < 3; ++i) dp_world_[i] = a * dp_world_[i] + b * sp * normal_(rng_);
    for (int i = 0; i < 3; ++i) dtheta_body_[i] = a * dtheta_body_[i] + b * sa * normal_(rng_);
  }
  last_utime_ = utime;
  MultirotorState s = truth;
  s.p_body_in_world += dp_world_;
  const double angle = dtheta_body_.norm();
  if (angle > 0)
    s.q_body_to_world =
        (truth.q_body_to_world * Eigen::Quaterniond(Eigen::AngleAxisd(angle, dtheta_body_ / angle))).normalized();
  const Eigen::Vector3d x_body = s.q_body_to_world * Eigen::Vector3d::UnitX();
  s.yaw_rad = std::atan2(x_body.y(), x_body.x());
  return s;
}

}  // namespace wingman::sim
