// SPDX-License-Identifier: MIT
// PoseBuffer: ordered own poses, linear + slerp interpolation, refusals with reasons.
#include "wingman/localizer/pose_buffer.hpp"

#include <fmt/format.h>
#include <wingman/common/config.hpp>
#include <wingman/geometry/ned_enu.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wingman::localizer {
namespace {

int64_t seconds_to_us(double s) { return static_cast<int64_t>(std::llround(s * 1e6)); }
double us_to_seconds(int64_t us) { return static_cast<double>(us) * 1e-6; }

void set(std::string* why, std::string text) {
  if (why) *why = std::move(text);
}

// Holds the orientation and moves the position by the velocity over (utime - s.utime).
PoseSample extrapolate(const PoseSample& s, int64_t utime) {
  PoseSample out = s;
  out.utime = utime;
  out.p_body_in_world = s.p_body_in_world + s.v_body_in_world * us_to_seconds(utime - s.utime);
  return out;
}

}  // namespace

std::vector<std::string> PoseBufferOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (!(max_gap_s > 0)) p.push_back(problem("pose.max_gap_s", max_gap_s, "must be > 0"));
  if (!(max_extrapolation_s >= 0))
    p.push_back(problem("pose.max_extrapolation_s", max_extrapolation_s, "must be >= 0"));
  if (!(history_s > 0)) p.push_back(problem("pose.history_s", history_s, "must be > 0"));
  return p;
}

PoseSample pose_ned_frd_to_enu_flu(const PoseSample& ned_frd) {  // geometry/ned_enu.hpp: the one conversion
  PoseSample out;
  out.utime = ned_frd.utime;
  out.p_body_in_world = geometry::swap_ned_enu(ned_frd.p_body_in_world);
  out.v_body_in_world = geometry::swap_ned_enu(ned_frd.v_body_in_world);
  out.q_body_to_world = geometry::swap_ned_frd_enu_flu(ned_frd.q_body_to_world);
  out.cov_p_body_in_world = geometry::swap_ned_enu_covariance(ned_frd.cov_p_body_in_world);
  out.var_rpy_body = ned_frd.var_rpy_body;
  return out;
}

PoseSample interpolate(const PoseSample& a, const PoseSample& b, int64_t utime) {
  const double s = static_cast<double>(utime - a.utime) / static_cast<double>(b.utime - a.utime);
  PoseSample out;
  out.utime = utime;
  out.p_body_in_world = a.p_body_in_world + s * (b.p_body_in_world - a.p_body_in_world);
  out.v_body_in_world = a.v_body_in_world + s * (b.v_body_in_world - a.v_body_in_world);
  out.q_body_to_world = a.q_body_to_world.slerp(s, b.q_body_to_world).normalized();  // Eigen: shortest arc
  out.cov_p_body_in_world = a.cov_p_body_in_world + s * (b.cov_p_body_in_world - a.cov_p_body_in_world);
  out.var_rpy_body = a.var_rpy_body + s * (b.var_rpy_body - a.var_rpy_body);
  return out;
}

PoseBuffer::PoseBuffer(PoseBufferOptions options) : options_(options) {
  const auto problems = options_.validate();
  if (!problems.empty()) {
    std::string all = "invalid PoseBufferOptions:";
    for (const auto& q : problems) all += " " + q + ";";
    throw std::invalid_argument(all);
  }
}

bool PoseBuffer::add(const PoseSample& sample, std::string* why) {
  const bool finite = sample.p_body_in_world.allFinite() && sample.v_body_in_world.allFinite() &&
                      sample.q_body_to_world.coeffs().allFinite() && sample.cov_p_body_in_world.allFinite() &&
                      sample.var_rpy_body.allFinite();
  if (!finite) {
    set(why, fmt::format("own pose at utime {} has non-finite values", sample.utime));
    return false;
  }
  const double norm = sample.q_body_to_world.norm();
  if (std::abs(norm - 1.0) > 1e-3) {
    set(why, fmt::format("own pose at utime {} has a quaternion of norm {:.6f}, not 1", sample.utime, norm));
    return false;
  }
  if (!samples_.empty() && sample.utime <= samples_.back().utime) {
    const int64_t newest = samples_.back().utime;
    set(why, sample.utime == newest ? fmt::format("own pose at utime {} is a duplicate", sample.utime)
                                    : fmt::format("own pose at utime {} is out of order ({} s before the newest, {})",
                                                  sample.utime, us_to_seconds(newest - sample.utime), newest));
    return false;
  }
  PoseSample s = sample;
  s.q_body_to_world.normalize();
  samples_.push_back(s);
  const int64_t oldest_kept = s.utime - seconds_to_us(options_.history_s);
  while (samples_.size() > 1 && samples_.front().utime < oldest_kept) samples_.pop_front();
  return true;
}

std::optional<int64_t> PoseBuffer::newest_utime() const {
  if (samples_.empty()) return std::nullopt;
  return samples_.back().utime;
}

std::optional<PoseSample> PoseBuffer::at(int64_t utime, std::string* why) const {
  if (samples_.empty()) {
    set(why, "no own pose received yet");
    return std::nullopt;
  }
  const int64_t max_extrapolation_us = seconds_to_us(options_.max_extrapolation_s);
  auto it = std::lower_bound(samples_.begin(), samples_.end(), utime,
                             [](const PoseSample& s, int64_t t) { return s.utime < t; });
  if (it != samples_.end() && it->utime == utime) {
    PoseSample exact = *it;
    return exact;
  }
  if (it == samples_.end()) {
    const PoseSample& newest = samples_.back();
    if (utime - newest.utime <= max_extrapolation_us) return extrapolate(newest, utime);
    set(why, fmt::format("newest own pose ({}) is {:.3f} s older than utime {} (pose.max_extrapolation_s = {})",
                         newest.utime, us_to_seconds(utime - newest.utime), utime, options_.max_extrapolation_s));
    return std::nullopt;
  }
  if (it == samples_.begin()) {
    const PoseSample& oldest = samples_.front();
    if (oldest.utime - utime <= max_extrapolation_us) return extrapolate(oldest, utime);
    set(why, fmt::format("utime {} is {:.3f} s before the oldest own pose kept ({}; pose.history_s = {}, "
                         "pose.max_extrapolation_s = {})",
                         utime, us_to_seconds(oldest.utime - utime), oldest.utime, options_.history_s,
                         options_.max_extrapolation_s));
    return std::nullopt;
  }
  const PoseSample& b = *it;
  const PoseSample& a = *(it - 1);
  if (b.utime - a.utime > seconds_to_us(options_.max_gap_s)) {
    set(why, fmt::format("own poses around utime {} are {:.3f} s apart ({} to {}; pose.max_gap_s = {})", utime,
                         us_to_seconds(b.utime - a.utime), a.utime, b.utime, options_.max_gap_s));
    return std::nullopt;
  }
  return interpolate(a, b, utime);
}

}  // namespace wingman::localizer
