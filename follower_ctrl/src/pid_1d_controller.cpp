// SPDX-License-Identifier: MIT
// The thesis's 1-D follower.
#include "wingman/follower_ctrl/pid_1d_controller.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <wingman/common/config.hpp>
#include <wingman/common/detection_class.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wingman::follower_ctrl {
namespace {

constexpr double kMinHorizontalAxis = 0.1;  // camera x within ~6 degrees of vertical: no horizontal axis

Pid1dOptions checked(const Pid1dOptions& o, const LimitsOptions& limits) {
  auto problems = o.validate();
  const auto more = limits.validate();
  problems.insert(problems.end(), more.begin(), more.end());
  if (!problems.empty()) throw std::invalid_argument("invalid pid_1d options: " + problems.front());
  return o;
}

}  // namespace

std::optional<Pid1dAxis> parse_pid_1d_axis(const std::string& name) {
  if (name == "camera_right") return Pid1dAxis::kCameraRight;
  if (name == "world") return Pid1dAxis::kWorld;
  return std::nullopt;
}

std::vector<std::string> Pid1dOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  for (const auto& [key, value] : {std::pair{"pid_1d.kp", kp}, {"pid_1d.ki", ki}, {"pid_1d.kd", kd}})
    if (!std::isfinite(value)) p.push_back(problem(key, value, "must be finite"));
  if (!(integral_max >= 0) || !std::isfinite(integral_max))
    p.push_back(problem("pid_1d.integral_max", integral_max, "must be a finite number >= 0"));
  if (!parse_pid_1d_axis(axis)) p.push_back(problem("pid_1d.axis", axis, "must be camera_right or world"));
  const bool axis_ok = world_axis.size() == 2 && std::isfinite(world_axis[0]) && std::isfinite(world_axis[1]) &&
                       std::hypot(world_axis[0], world_axis[1]) > 1e-9;
  if (!axis_ok)
    p.push_back(problem("pid_1d.world_axis", fmt::format("[{}]", fmt::join(world_axis, ", ")),
                        "must be 2 finite numbers [east, north], not both zero"));
  const auto mode = parse_height_mode(height_mode);
  if (!mode || *mode == HeightMode::kTarget)
    p.push_back(problem("pid_1d.height_mode", height_mode, "must be start or fixed"));
  if (!std::isfinite(height_m)) p.push_back(problem("pid_1d.height_m", height_m, "must be finite"));
  if (!(height_kp >= 0) || !std::isfinite(height_kp))
    p.push_back(problem("pid_1d.height_kp", height_kp, "must be a finite number >= 0"));
  return p;
}

double box_centre_error(const wingman::detection_t& box, int32_t image_width) {
  const double u = static_cast<double>(box.cx) / static_cast<double>(image_width);
  return u - 0.5;  // eq. 34
}

std::optional<wingman::detection_t> most_confident_box(const wingman::detections_t& d) {
  std::optional<wingman::detection_t> best;
  for (const auto& box : d.detections) {
    if (box.class_id != common::kDroneClassId) continue;  // a bird or airplane is never followed
    if (!(box.cx >= 0 && box.cx <= static_cast<float>(d.image_width))) continue;
    if (!best || box.confidence > best->confidence) best = box;
  }
  return best;
}

Pid1dController::Pid1dController(const Pid1dOptions& options, const LimitsOptions& limits,
                                 const Eigen::Matrix3d& R_cam_to_body)
    : options_(checked(options, limits)),
      axis_(*parse_pid_1d_axis(options.axis)),
      height_mode_(*parse_height_mode(options.height_mode)),
      R_cam_to_body_(R_cam_to_body),
      pid_(options.gains()),
      limiter_(limits) {}

std::optional<Eigen::Vector3d> Pid1dController::axis_in_world(const OwnState& own) const {
  Eigen::Vector3d a = axis_ == Pid1dAxis::kWorld
                          ? Eigen::Vector3d(options_.world_axis[0], options_.world_axis[1], 0.0)
                          : Eigen::Vector3d(own.R_body_to_world * R_cam_to_body_ * Eigen::Vector3d::UnitX());
  a.z() = 0.0;
  const double n = a.norm();
  if (n < (axis_ == Pid1dAxis::kWorld ? 1e-9 : kMinHorizontalAxis)) return std::nullopt;
  return Eigen::Vector3d(a / n);
}

Pid1dCommand Pid1dController::update(std::optional<double> error, const Eigen::Vector3d& axis_in_world,
                                     const OwnState& own, int64_t utime, double start_height_m) {
  Pid1dCommand out;
  out.axis_in_world = axis_in_world;
  double v_axis = 0.0;
  if (error) {
    out.terms = pid_.update(*error, utime);
    v_axis = out.terms->output();  // v = P + I + D
  }
  const double z_ref = std::max(height_mode_ == HeightMode::kFixed ? options_.height_m : start_height_m,
                                limiter_.limits().floor_height_m);
  Eigen::Vector3d v_wanted = v_axis * axis_in_world;
  v_wanted.z() = options_.height_kp * (z_ref - own.p_body_in_world.z());
  out.command.v_body_in_world = limiter_.apply(v_wanted, utime, own);
  out.command.yaw_rad = own.yaw();
  out.command.yaw_rate_radps = 0.0;
  return out;
}

void Pid1dController::reset() {
  pid_.reset();
  limiter_.reset();
}

}  // namespace wingman::follower_ctrl
