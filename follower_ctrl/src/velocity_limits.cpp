// SPDX-License-Identifier: MIT
// Speed, acceleration, no-approach and floor rules on velocity commands.
#include "wingman/follower_ctrl/velocity_limits.hpp"

#include <fmt/format.h>
#include <wingman/common/config.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wingman::follower_ctrl {
namespace {

/// Scales the horizontal part of v to at most `max` (direction kept).
Eigen::Vector3d cap_horizontal(Eigen::Vector3d v, double max) {
  const double h = std::hypot(v.x(), v.y());
  if (h > max) {
    v.x() *= max / h;
    v.y() *= max / h;
  }
  return v;
}

}  // namespace

std::vector<std::string> LimitsOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  auto positive = [&](const char* key, double value) {
    if (!(value > 0) || !std::isfinite(value)) p.push_back(problem(key, value, "must be a finite number > 0"));
  };
  positive("limits.max_horizontal_speed_mps", max_horizontal_speed_mps);
  positive("limits.max_vertical_speed_mps", max_vertical_speed_mps);
  positive("limits.max_horizontal_accel_mps2", max_horizontal_accel_mps2);
  positive("limits.max_vertical_accel_mps2", max_vertical_accel_mps2);
  positive("limits.max_yaw_rate_radps", max_yaw_rate_radps);
  if (!std::isfinite(floor_height_m)) p.push_back(problem("limits.floor_height_m", floor_height_m, "must be finite"));
  return p;
}

Eigen::Vector3d limit_speed(const Eigen::Vector3d& v, const LimitsOptions& limits) {
  Eigen::Vector3d out = cap_horizontal(v, limits.max_horizontal_speed_mps);
  out.z() = std::clamp(out.z(), -limits.max_vertical_speed_mps, limits.max_vertical_speed_mps);
  return out;
}

Eigen::Vector3d limit_acceleration(const Eigen::Vector3d& v_wanted, const Eigen::Vector3d& v_previous, double dt_s,
                                   const LimitsOptions& limits) {
  Eigen::Vector3d dv = cap_horizontal(v_wanted - v_previous, limits.max_horizontal_accel_mps2 * dt_s);
  const double max_dvz = limits.max_vertical_accel_mps2 * dt_s;
  dv.z() = std::clamp(dv.z(), -max_dvz, max_dvz);
  return v_previous + dv;
}

Eigen::Vector3d remove_approach(const Eigen::Vector3d& v, const Eigen::Vector3d& d_to_obstacle) {
  const double n = d_to_obstacle.norm();
  if (!(n > 0)) return v;
  const Eigen::Vector3d u = d_to_obstacle / n;
  const double closing = v.dot(u);
  return closing > 0 ? Eigen::Vector3d(v - closing * u) : v;
}

VelocityLimiter::VelocityLimiter(const LimitsOptions& limits) : limits_(limits) {
  const auto problems = limits.validate();
  if (!problems.empty()) throw std::invalid_argument("invalid LimitsOptions: " + problems.front());
}

Eigen::Vector3d VelocityLimiter::apply(const Eigen::Vector3d& v_wanted, int64_t utime, const OwnState& own,
                                       const std::optional<Eigen::Vector3d>& d_to_obstacle) {
  if (previous_ && utime < previous_->utime)
    throw std::invalid_argument(
        fmt::format("velocity command at utime {} is before the previous one ({})", utime, previous_->utime));
  // 4. acceleration (lowest priority, so first), from the previous command or the measured velocity.
  const Eigen::Vector3d v_from = previous_ ? previous_->v_in_world : own.v_body_in_world;
  const int64_t from_utime = previous_ ? previous_->utime : own.utime;
  const double dt_s = std::max<int64_t>(0, utime - from_utime) * 1e-6;
  Eigen::Vector3d v = limit_acceleration(limit_speed(v_wanted, limits_), v_from, dt_s, limits_);
  // 3. speed: the measured velocity a reset starts from may exceed the limits.
  v = limit_speed(v, limits_);
  // 2. no approach.
  if (d_to_obstacle) v = remove_approach(v, *d_to_obstacle);
  // 1. floor. Raising v_z can re-create a closing component when the obstacle is above: take it out of
  // the horizontal part (which leaves v_z alone), so both rules hold.
  if (own.p_body_in_world.z() <= limits_.floor_height_m && v.z() < 0) {
    v.z() = 0;
    if (d_to_obstacle) {
      const Eigen::Vector3d d = *d_to_obstacle;
      const double dh2 = d.x() * d.x() + d.y() * d.y();
      const double closing = v.dot(d);
      if (closing > 0 && dh2 > 0) {
        v.x() -= closing * d.x() / dh2;
        v.y() -= closing * d.y() / dh2;
      }
    }
  }
  previous_ = Previous{v, utime};
  return v;
}

double VelocityLimiter::limit_yaw_rate(double yaw_rate_radps) const {
  return std::clamp(yaw_rate_radps, -limits_.max_yaw_rate_radps, limits_.max_yaw_rate_radps);
}

}  // namespace wingman::follower_ctrl
