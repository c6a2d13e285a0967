// SPDX-License-Identifier: MIT
// Checks of decoded messages: sizes, enums, finite numbers. Messages name the field, value and rule.
#include "wingman/common/message_validation.hpp"

#include <fmt/format.h>

#include <cmath>

namespace wingman::common {
namespace {

template <size_t N>
bool all_finite(const double (&v)[N]) {
  for (double x : v) {
    if (!std::isfinite(x)) return false;
  }
  return true;
}

std::string check_utime(const char* type, int64_t utime) {
  if (utime < 0) return fmt::format("{}.utime = {}: must be >= 0 (microseconds since epoch)", type, utime);
  return "";
}

std::string check_frame(const char* type, int8_t frame) {
  if (frame != wingman::own_pose_t::FRAME_ENU && frame != wingman::own_pose_t::FRAME_NED) {
    return fmt::format("{}.frame = {}: must be FRAME_ENU (0) or FRAME_NED (1)", type, frame);
  }
  return "";
}

std::string check_source(const char* field, int8_t source) {
  if (source != wingman::detections_t::SOURCE_CNN && source != wingman::detections_t::SOURCE_GROUND_TRUTH) {
    return fmt::format("{} = {}: must be SOURCE_CNN (0) or SOURCE_GROUND_TRUTH (1)", field, source);
  }
  return "";
}

std::string check_quaternion(const char* type, const char* field, const double (&q)[4]) {
  if (!all_finite(q)) return fmt::format("{}.{}: must be finite", type, field);
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (std::abs(n - 1.0) > 1e-3) return fmt::format("{}.{}: norm {} must be 1 (±1e-3)", type, field, n);
  return "";
}

// own_pose_t's covariance: zero when has_covariance is false; otherwise finite, variances >= 0 and each position
// covariance within the Cauchy-Schwarz bound |c_ij| <= sqrt(c_ii c_jj) (1e-6 relative slack for rounding).
std::string check_pose_covariance(const wingman::own_pose_t& m) {
  if (!m.has_covariance) {
    for (double c : m.cov_p_body_in_world)
      if (c != 0.0) return "own_pose_t.cov_p_body_in_world: must be zero when has_covariance is false";
    for (double c : m.var_rpy_body)
      if (c != 0.0) return "own_pose_t.var_rpy_body: must be zero when has_covariance is false";
    return "";
  }
  if (!all_finite(m.cov_p_body_in_world)) return "own_pose_t.cov_p_body_in_world: must be finite";
  if (!all_finite(m.var_rpy_body)) return "own_pose_t.var_rpy_body: must be finite";
  for (int i = 0; i < 3; ++i)
    if (m.var_rpy_body[i] < 0)
      return fmt::format("own_pose_t.var_rpy_body[{}] = {}: must be >= 0", i, m.var_rpy_body[i]);
  // Upper triangle row by row: (0,0) (0,1) (0,2) (1,1) (1,2) (2,2).
  static constexpr int kIndex[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};
  for (int i = 0; i < 3; ++i) {
    const double d = m.cov_p_body_in_world[kIndex[i][i]];
    if (d < 0) return fmt::format("own_pose_t.cov_p_body_in_world[{}] = {}: a variance must be >= 0", kIndex[i][i], d);
  }
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j) {
      const double c = m.cov_p_body_in_world[kIndex[i][j]];
      const double bound = std::sqrt(m.cov_p_body_in_world[kIndex[i][i]] * m.cov_p_body_in_world[kIndex[j][j]]);
      if (std::abs(c) > bound * (1 + 1e-6) + 1e-300)
        return fmt::format("own_pose_t.cov_p_body_in_world[{}] = {}: a covariance must be within +-sqrt(var var) = {}",
                           kIndex[i][j], c, bound);
    }
  return "";
}

}  // namespace

int bytes_per_pixel(int8_t pixel_format) {
  switch (pixel_format) {
    case wingman::image_t::GRAY8:
      return 1;
    case wingman::image_t::BGR8:
      return 3;
    case wingman::image_t::YUYV:
      return 2;
    default:
      return 0;
  }
}

std::string pixel_format_name(int8_t pixel_format) {
  switch (pixel_format) {
    case wingman::image_t::GRAY8:
      return "GRAY8";
    case wingman::image_t::BGR8:
      return "BGR8";
    case wingman::image_t::YUYV:
      return "YUYV";
    case wingman::image_t::MJPEG:
      return "MJPEG";
    default:
      return fmt::format("unknown({})", pixel_format);
  }
}

std::string validate_message(const wingman::image_t& m, const ImageLimits& limits) {
  if (auto e = check_utime("image_t", m.utime); !e.empty()) return e;
  if (m.width <= 0 || m.width > limits.max_width)
    return fmt::format("image_t.width = {}: must be in 1..{}", m.width, limits.max_width);
  if (m.height <= 0 || m.height > limits.max_height)
    return fmt::format("image_t.height = {}: must be in 1..{}", m.height, limits.max_height);
  if (m.size != static_cast<int32_t>(m.data.size()))
    return fmt::format("image_t.size = {}: does not match {} data bytes", m.size, m.data.size());
  if (m.pixel_format == wingman::image_t::MJPEG) {
    if (m.size < 4) return fmt::format("image_t.size = {}: an MJPEG frame needs a JPEG stream", m.size);
    if (m.data[0] != 0xFF || m.data[1] != 0xD8)
      return "image_t.data: MJPEG frame does not start with a JPEG SOI marker (FF D8)";
    return "";
  }
  const int bpp = bytes_per_pixel(m.pixel_format);
  if (bpp == 0)
    return fmt::format("image_t.pixel_format = {}: must be GRAY8 (1), BGR8 (2), YUYV (3) or MJPEG (4)", m.pixel_format);
  if (m.pixel_format == wingman::image_t::YUYV && m.width % 2 != 0)
    return fmt::format("image_t.width = {}: must be even for YUYV", m.width);
  const int64_t min_stride = static_cast<int64_t>(m.width) * bpp;
  if (m.stride < min_stride)
    return fmt::format("image_t.stride = {}: must be >= width * {} = {} for {}", m.stride, bpp, min_stride,
                       pixel_format_name(m.pixel_format));
  const int64_t need = static_cast<int64_t>(m.stride) * m.height;
  if (m.size != need)
    return fmt::format("image_t.size = {}: must be stride * height = {} * {} = {}", m.size, m.stride, m.height, need);
  return "";
}

std::string validate_message(const wingman::detections_t& m) {
  if (auto e = check_utime("detections_t", m.utime); !e.empty()) return e;
  if (m.image_width <= 0 || m.image_height <= 0)
    return fmt::format("detections_t.image_width x image_height = {} x {}: must be positive", m.image_width,
                       m.image_height);
  if (auto e = check_source("detections_t.source", m.source); !e.empty()) return e;
  if (m.num_detections != static_cast<int32_t>(m.detections.size()) || m.num_detections < 0)
    return fmt::format("detections_t.num_detections = {}: does not match {} detections", m.num_detections,
                       m.detections.size());
  for (size_t i = 0; i < m.detections.size(); ++i) {
    const auto& d = m.detections[i];
    if (!std::isfinite(d.cx) || !std::isfinite(d.cy) || !std::isfinite(d.w) || !std::isfinite(d.h))
      return fmt::format("detections_t.detections[{}]: cx, cy, w, h must be finite", i);
    if (d.w <= 0 || d.h <= 0)
      return fmt::format("detections_t.detections[{}].w x h = {} x {}: must be positive", i, d.w, d.h);
    if (!(d.confidence >= 0 && d.confidence <= 1))
      return fmt::format("detections_t.detections[{}].confidence = {}: must be in [0, 1]", i, d.confidence);
    if (!(d.drone_score >= 0 && d.drone_score <= 1))  // NaN fails both
      return fmt::format("detections_t.detections[{}].drone_score = {}: must be a finite number in [0, 1]", i,
                         d.drone_score);
    if (d.class_id < 0)
      return fmt::format("detections_t.detections[{}].class_id = {}: must be >= 0 (0 = drone)", i, d.class_id);
  }
  return "";
}

std::string validate_message(const wingman::own_pose_t& m) {
  if (auto e = check_utime("own_pose_t", m.utime); !e.empty()) return e;
  if (auto e = check_frame("own_pose_t", m.frame); !e.empty()) return e;
  if (!all_finite(m.p_body_in_world)) return "own_pose_t.p_body_in_world: must be finite";
  if (!all_finite(m.v_body_in_world)) return "own_pose_t.v_body_in_world: must be finite";
  if (auto e = check_quaternion("own_pose_t", "q_body_to_world", m.q_body_to_world); !e.empty()) return e;
  return check_pose_covariance(m);
}

std::string validate_message(const wingman::targets_t& m) {
  if (auto e = check_utime("targets_t", m.utime); !e.empty()) return e;
  if (auto e = check_frame("targets_t", m.frame); !e.empty()) return e;
  if (m.num_targets != static_cast<int32_t>(m.targets.size()) || m.num_targets < 0)
    return fmt::format("targets_t.num_targets = {}: does not match {} targets", m.num_targets, m.targets.size());
  for (size_t i = 0; i < m.targets.size(); ++i) {
    const auto& t = m.targets[i];
    if (!all_finite(t.p_target_in_cam) || !all_finite(t.p_target_in_world) || !all_finite(t.v_target_in_world) ||
        !all_finite(t.position_covariance) || !all_finite(t.velocity_covariance) || !std::isfinite(t.range))
      return fmt::format("targets_t.targets[{}]: positions, velocity, covariances and range must be finite", i);
    if (t.range < 0) return fmt::format("targets_t.targets[{}].range = {}: must be >= 0", i, t.range);
    if (auto e = check_source(fmt::format("targets_t.targets[{}].detection_source", i).c_str(), t.detection_source);
        !e.empty())
      return e;
  }
  return "";
}

std::string validate_message(const wingman::track_windows_t& m) {
  if (auto e = check_utime("track_windows_t", m.utime); !e.empty()) return e;
  if (m.utime_predicted < m.utime)
    return fmt::format("track_windows_t.utime_predicted = {}: must be >= utime ({})", m.utime_predicted, m.utime);
  if (m.image_width <= 0 || m.image_height <= 0)
    return fmt::format("track_windows_t.image_width x image_height = {}x{}: must be positive", m.image_width,
                       m.image_height);
  if (m.num_windows != static_cast<int32_t>(m.windows.size()) || m.num_windows < 0)
    return fmt::format("track_windows_t.num_windows = {}: does not match {} windows", m.num_windows, m.windows.size());
  for (size_t i = 0; i < m.windows.size(); ++i) {
    const auto& w = m.windows[i];
    const float values[] = {w.cx, w.cy, w.vx, w.vy, w.w, w.h, w.sigma_px, w.range_m, w.confidence};
    for (const float v : values)
      if (!std::isfinite(v)) return fmt::format("track_windows_t.windows[{}]: every number must be finite", i);
    if (!(w.w > 0) || !(w.h > 0) || !(w.range_m > 0))
      return fmt::format("track_windows_t.windows[{}]: w = {}, h = {}, range_m = {}: must be > 0", i, w.w, w.h,
                         w.range_m);
    if (w.sigma_px < 0) return fmt::format("track_windows_t.windows[{}].sigma_px = {}: must be >= 0", i, w.sigma_px);
    if (w.confidence < 0 || w.confidence > 1)
      return fmt::format("track_windows_t.windows[{}].confidence = {}: must be in [0, 1]", i, w.confidence);
  }
  return "";
}

std::string validate_message(const wingman::setpoint_t& m) {
  if (auto e = check_utime("setpoint_t", m.utime); !e.empty()) return e;
  if (auto e = check_frame("setpoint_t", m.frame); !e.empty()) return e;
  if (m.mode != wingman::setpoint_t::MODE_HOLD && m.mode != wingman::setpoint_t::MODE_POSITION &&
      m.mode != wingman::setpoint_t::MODE_VELOCITY)
    return fmt::format("setpoint_t.mode = {}: must be MODE_HOLD (0), MODE_POSITION (1) or MODE_VELOCITY (2)", m.mode);
  if (!all_finite(m.position) || !all_finite(m.velocity) || !std::isfinite(m.yaw) || !std::isfinite(m.yaw_rate))
    return "setpoint_t: position, velocity, yaw and yaw_rate must be finite";
  if (auto e = check_source("setpoint_t.detection_source", m.detection_source); !e.empty()) return e;
  return "";
}

std::string validate_message(const wingman::status_t& m) {
  if (m.num_channels != static_cast<int32_t>(m.channels.size()) || m.num_channels < 0)
    return fmt::format("status_t.num_channels = {}: does not match {} channels", m.num_channels, m.channels.size());
  if (m.state < wingman::status_t::STATE_STARTING || m.state > wingman::status_t::STATE_STOPPING)
    return fmt::format("status_t.state = {}: must be one of STATE_STARTING (0) .. STATE_STOPPING (4)", m.state);
  if (m.process.empty()) return "status_t.process: must not be empty";
  return "";
}

std::string validate_message(const wingman::ground_truth_t& m) {
  if (auto e = check_utime("ground_truth_t", m.utime); !e.empty()) return e;
  if (auto e = check_frame("ground_truth_t", m.frame); !e.empty()) return e;
  if (m.num_vehicles != static_cast<int32_t>(m.vehicles.size()) || m.num_vehicles < 0)
    return fmt::format("ground_truth_t.num_vehicles = {}: does not match {} vehicles", m.num_vehicles,
                       m.vehicles.size());
  if (m.num_boxes != static_cast<int32_t>(m.boxes.size()) || m.num_boxes < 0)
    return fmt::format("ground_truth_t.num_boxes = {}: does not match {} boxes", m.num_boxes, m.boxes.size());
  for (size_t i = 0; i < m.vehicles.size(); ++i) {
    if (auto e = check_quaternion("ground_truth_t", "vehicles[].q_body_to_world", m.vehicles[i].q_body_to_world);
        !e.empty())
      return e + fmt::format(" (vehicle index {})", i);
  }
  return "";
}

}  // namespace wingman::common
