// SPDX-License-Identifier: MIT
// The formation follower.
#include "wingman/follower_ctrl/formation_controller.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <wingman/common/config.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wingman::follower_ctrl {
namespace {

constexpr double kMinBearingDistanceM = 0.05;  // below: the bearing to the target is undefined
constexpr double kMinHorizontalAxis = 0.1;     // optical axis within ~6 degrees of vertical: no yaw control

FormationOptions checked(const FormationOptions& o, const LimitsOptions& limits) {
  auto problems = o.validate();
  const auto more = limits.validate();
  problems.insert(problems.end(), more.begin(), more.end());
  if (!problems.empty()) throw std::invalid_argument("invalid formation options: " + problems.front());
  return o;
}

PidGains gains_of(const FormationOptions& o) { return PidGains{o.kp, o.ki, o.kd, o.integral_max_m_s}; }

}  // namespace

std::vector<std::string> FormationOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  auto finite_nonneg = [&](const char* key, double value) {
    if (!(value >= 0) || !std::isfinite(value)) p.push_back(problem(key, value, "must be a finite number >= 0"));
  };
  bool offset_ok = offset_m.size() == 3;
  for (double x : offset_m) offset_ok = offset_ok && std::isfinite(x);
  if (!offset_ok)
    p.push_back(problem("formation.offset_m", fmt::format("[{}]", fmt::join(offset_m, ", ")),
                        "must be 3 finite numbers [east, north, up] in metres"));
  if (!parse_height_mode(height_mode))
    p.push_back(problem("formation.height_mode", height_mode, "must be start, fixed or target"));
  if (!std::isfinite(height_m)) p.push_back(problem("formation.height_m", height_m, "must be finite"));
  finite_nonneg("formation.feedforward_gain", feedforward_gain);
  finite_nonneg("formation.kp", kp);
  finite_nonneg("formation.ki", ki);
  finite_nonneg("formation.kd", kd);
  finite_nonneg("formation.integral_max_m_s", integral_max_m_s);
  if (!parse_select_policy(select))
    p.push_back(problem("formation.select", select, "must be most_confident or nearest"));
  finite_nonneg("formation.reselect_after_s", reselect_after_s);
  finite_nonneg("formation.avoid_radius_m", avoid_radius_m);
  finite_nonneg("formation.avoid_climb_mps", avoid_climb_mps);
  finite_nonneg("formation.yaw_kp", yaw_kp);
  finite_nonneg("formation.weave_m", weave_m);
  if (!(weave_period_s >= 1.0) || !std::isfinite(weave_period_s))
    p.push_back(problem("formation.weave_period_s", weave_period_s, "must be a finite number >= 1"));
  finite_nonneg("formation.weave_until_rel", weave_until_rel);
  // The formation point must lie outside the avoidance sphere, or the follower would hover at its rim.
  if (offset_ok && parse_height_mode(height_mode) && avoid_radius_m > 0) {
    const bool with_z = *parse_height_mode(height_mode) == HeightMode::kTarget;
    const double separation =
        with_z ? std::sqrt(offset_m[0] * offset_m[0] + offset_m[1] * offset_m[1] + offset_m[2] * offset_m[2])
               : std::hypot(offset_m[0], offset_m[1]);
    if (separation <= avoid_radius_m)
      p.push_back(problem("formation.offset_m", fmt::format("[{}]", fmt::join(offset_m, ", ")),
                          fmt::format("must place the follower farther from the target ({:.3g} m{}) than "
                                      "formation.avoid_radius_m = {}",
                                      separation, with_z ? "" : " horizontally", avoid_radius_m)));
  }
  return p;
}

FormationController::FormationController(const FormationOptions& options, const LimitsOptions& limits,
                                         const Eigen::Matrix3d& R_cam_to_body)
    : options_(checked(options, limits)),
      height_mode_(*parse_height_mode(options.height_mode)),
      offset_in_world_(options.offset_m[0], options.offset_m[1], options.offset_m[2]),
      R_cam_to_body_(R_cam_to_body),
      pid_{Pid(gains_of(options)), Pid(gains_of(options)), Pid(gains_of(options))},
      limiter_(limits) {}

Eigen::Vector3d FormationController::desired_position(const TargetState& target, double start_height_m) const {
  Eigen::Vector3d p_des = target.p_target_in_world + offset_in_world_;
  if (height_mode_ == HeightMode::kStart) p_des.z() = start_height_m;
  if (height_mode_ == HeightMode::kFixed) p_des.z() = options_.height_m;
  p_des.z() = std::max(p_des.z(), limiter_.limits().floor_height_m);
  return p_des;
}

VelocityCommand FormationController::update(const TargetState& target, const OwnState& own, int64_t utime,
                                            double start_height_m) {
  Eigen::Vector3d p_des = desired_position(target, start_height_m);
  Eigen::Vector3d v_weave = Eigen::Vector3d::Zero();
  if (options_.weave_m > 0 && target.size_sigma_rel > options_.weave_until_rel) {
    // Across the line of sight, horizontally: a sine of message time (its phase from utime modulo the period).
    const Eigen::Vector3d los = target.p_target_in_world - own.p_body_in_world;
    const Eigen::Vector3d across = Eigen::Vector3d(-los.y(), los.x(), 0.0);
    if (across.norm() > kMinBearingDistanceM) {
      const int64_t period_us = static_cast<int64_t>(std::llround(options_.weave_period_s * 1e6));
      const double phase = 2.0 * M_PI * static_cast<double>(((utime % period_us) + period_us) % period_us) /
                           static_cast<double>(period_us);
      const Eigen::Vector3d n = across.normalized();
      p_des += options_.weave_m * std::sin(phase) * n;
      v_weave = options_.weave_m * (2.0 * M_PI / options_.weave_period_s) * std::cos(phase) * n;
    }
  }
  const Eigen::Vector3d e = p_des - own.p_body_in_world;
  Eigen::Vector3d v_wanted = options_.feedforward_gain * target.v_target_in_world + v_weave;
  if (height_mode_ != HeightMode::kTarget) v_wanted.z() = 0.0;  // a constant height ignores the target's climb
  for (int i = 0; i < 3; ++i) v_wanted[i] += pid_[i].update(e[i], utime).output();

  VelocityCommand cmd;
  const Eigen::Vector3d d_to_target = target.p_target_in_world - own.p_body_in_world;
  cmd.avoiding = options_.avoid_radius_m > 0 && d_to_target.norm() < options_.avoid_radius_m;
  if (cmd.avoiding) v_wanted.z() = options_.avoid_climb_mps;
  cmd.v_body_in_world =
      limiter_.apply(v_wanted, utime, own, cmd.avoiding ? std::optional<Eigen::Vector3d>(d_to_target) : std::nullopt);

  // Keep the camera on the target: turn the optical axis's azimuth towards the target's bearing.
  cmd.yaw_rad = own.yaw();
  double bearing = 0.0, camera_azimuth = 0.0;
  const Eigen::Vector3d optical_axis_in_world = own.R_body_to_world * R_cam_to_body_ * Eigen::Vector3d::UnitZ();
  if (horizontal_azimuth(d_to_target, kMinBearingDistanceM, &bearing) &&
      horizontal_azimuth(optical_axis_in_world, kMinHorizontalAxis, &camera_azimuth)) {
    const double error = wrap_pi(bearing - camera_azimuth);
    cmd.yaw_rad = wrap_pi(own.yaw() + error);
    cmd.yaw_rate_radps = limiter_.limit_yaw_rate(options_.yaw_kp * error);
  }
  return cmd;
}

void FormationController::reset_pid() {
  for (auto& p : pid_) p.reset();
}

void FormationController::reset() {
  reset_pid();
  limiter_.reset();
}

}  // namespace wingman::follower_ctrl
