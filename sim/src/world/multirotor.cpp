// SPDX-License-Identifier: MIT
// Multirotor dynamics: first-order velocity response with speed, acceleration and yaw-rate limits; tilt from the
// acceleration.
#include "wingman/sim/multirotor.hpp"

#include <wingman/common/config.hpp>
#include <wingman/geometry/angles.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wingman::sim {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

/// Scales the horizontal part of `v` down to norm `max_xy` and clamps |v_z| to `max_z`.
Eigen::Vector3d clamp_xy_z(Eigen::Vector3d v, double max_xy, double max_z) {
  const double n = std::hypot(v.x(), v.y());
  if (n > max_xy) {
    v.x() *= max_xy / n;
    v.y() *= max_xy / n;
  }
  v.z() = std::clamp(v.z(), -max_z, max_z);
  return v;
}

}  // namespace

std::vector<std::string> MultirotorLimits::validate(const std::string& prefix) const {
  using common::problem;
  std::vector<std::string> p;
  auto positive = [&](const char* key, double value) {
    if (!(value > 0) || !std::isfinite(value)) p.push_back(problem(prefix + key, value, "must be > 0"));
  };
  positive("max_speed_xy", max_speed_xy);
  positive("max_speed_z", max_speed_z);
  positive("max_accel_xy", max_accel_xy);
  positive("max_accel_z", max_accel_z);
  if (max_accel_z >= 0.9 * kGravity)
    p.push_back(
        problem(prefix + "max_accel_z", max_accel_z, "must be < 0.9 g = 8.83 m/s^2 (the model needs upward thrust)"));
  positive("velocity_time_constant_s", velocity_time_constant_s);
  positive("position_gain", position_gain);
  positive("yaw_gain", yaw_gain);
  positive("max_yaw_rate_deg", max_yaw_rate_deg);
  if (!(step_s > 0 && step_s <= 0.1)) p.push_back(problem(prefix + "step_s", step_s, "must be in (0, 0.1] seconds"));
  return p;
}

Eigen::Quaterniond attitude_from_acceleration(const Eigen::Vector3d& a_in_world, double yaw_rad) {
  Eigen::Vector3d thrust = a_in_world + Eigen::Vector3d(0, 0, kGravity);
  thrust.z() = std::max(thrust.z(), 0.1 * kGravity);
  const Eigen::Vector3d z_body = thrust.normalized();
  const Eigen::Vector3d x_heading(std::cos(yaw_rad), std::sin(yaw_rad), 0.0);
  const Eigen::Vector3d y_body = z_body.cross(x_heading).normalized();  // z_body is never horizontal
  const Eigen::Vector3d x_body = y_body.cross(z_body);
  Eigen::Matrix3d R_body_to_world;
  R_body_to_world.col(0) = x_body;
  R_body_to_world.col(1) = y_body;
  R_body_to_world.col(2) = z_body;
  return Eigen::Quaterniond(R_body_to_world).normalized();
}

Multirotor::Multirotor(const MultirotorLimits& limits, const Eigen::Vector3d& p_initial_in_world, double yaw_rad)
    : limits_(limits) {
  const auto problems = limits_.validate();
  if (!problems.empty()) throw std::invalid_argument("multirotor limits: " + problems.front());
  if (!p_initial_in_world.allFinite() || !std::isfinite(yaw_rad))
    throw std::invalid_argument("multirotor: initial position and yaw must be finite");
  teleport(p_initial_in_world, yaw_rad);
  holding_ = false;  // a first MODE_HOLD captures the position the vehicle then has
}

void Multirotor::set_command(const VehicleCommand& command) {
  if (command.mode == VehicleCommand::Mode::kHold) {
    if (holding_) return;  // a hold after a hold keeps the first hold point
    command_ = VehicleCommand{};
    command_.mode = VehicleCommand::Mode::kPosition;
    command_.p_ref_in_world = state_.p_body_in_world;
    command_.yaw_ref_rad = state_.yaw_rad;
    holding_ = true;
    return;
  }
  command_ = command;
  holding_ = false;
}

void Multirotor::teleport(const Eigen::Vector3d& p_in_world, double yaw_rad) {
  state_ = MultirotorState{};
  state_.p_body_in_world = p_in_world;
  state_.yaw_rad = geometry::wrap_pi(yaw_rad);
  state_.q_body_to_world = attitude_from_acceleration(Eigen::Vector3d::Zero(), state_.yaw_rad);
  command_ = VehicleCommand{};
  command_.mode = VehicleCommand::Mode::kPosition;
  command_.p_ref_in_world = p_in_world;
  command_.yaw_ref_rad = state_.yaw_rad;
  holding_ = true;
}

void Multirotor::advance(double dt_s) {
  if (!(dt_s >= 0)) throw std::invalid_argument("Multirotor::advance: dt must be >= 0");
  if (dt_s == 0) return;
  const int n = std::max(1, static_cast<int>(std::ceil(dt_s / limits_.step_s - 1e-9)));
  const double h = dt_s / n;
  for (int i = 0; i < n; ++i) step(h);
}

void Multirotor::step(double h) {
  const MultirotorLimits& L = limits_;
  const double tau = L.velocity_time_constant_s;
  Eigen::Vector3d v_cmd;
  double yaw_rate_cmd;
  if (command_.mode == VehicleCommand::Mode::kVelocity) {
    v_cmd = command_.v_ref_in_world;
    yaw_rate_cmd = command_.yaw_rate_ref;
  } else {  // kPosition (holds are resolved to positions by set_command)
    v_cmd = command_.v_ref_in_world + tau * command_.a_ref_in_world +
            L.position_gain * (command_.p_ref_in_world - state_.p_body_in_world);
    yaw_rate_cmd = L.yaw_gain * geometry::wrap_pi(command_.yaw_ref_rad - state_.yaw_rad);
  }
  v_cmd = clamp_xy_z(v_cmd, L.max_speed_xy, L.max_speed_z);

  // Exact first-order response over h towards v_cmd, then the acceleration limits. The new velocity stays on the
  // segment from the old velocity to v_cmd (per horizontal and vertical part), so speed limits hold exactly.
  const Eigen::Vector3d& v = state_.v_body_in_world;
  const Eigen::Vector3d v_free = v_cmd + (v - v_cmd) * std::exp(-h / tau);
  const Eigen::Vector3d a = clamp_xy_z((v_free - v) / h, L.max_accel_xy, L.max_accel_z);
  const Eigen::Vector3d v_new = v + a * h;
  state_.p_body_in_world += 0.5 * (v + v_new) * h;  // exact for constant acceleration over the step
  state_.v_body_in_world = v_new;
  state_.a_body_in_world = a;

  const double max_rate = L.max_yaw_rate_deg * kDegToRad;
  state_.yaw_rad = geometry::wrap_pi(state_.yaw_rad + std::clamp(yaw_rate_cmd, -max_rate, max_rate) * h);

  const Eigen::Quaterniond q_old = state_.q_body_to_world;
  state_.q_body_to_world = attitude_from_acceleration(a, state_.yaw_rad);
  if (state_.q_body_to_world.dot(q_old) < 0) state_.q_body_to_world.coeffs() *= -1.0;  // keep the sign continuous
  const Eigen::AngleAxisd delta(q_old.conjugate() * state_.q_body_to_world);           // rotation in the old body frame
  state_.w_body_in_body = delta.axis() * (delta.angle() / h);
}

}  // namespace wingman::sim
