// SPDX-License-Identifier: MIT
// The discrete PID of eq. 34-37.
#include "wingman/follower_ctrl/pid.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wingman::follower_ctrl {

Pid::Pid(const PidGains& gains) : gains_(gains) {
  if (!std::isfinite(gains.kp) || !std::isfinite(gains.ki) || !std::isfinite(gains.kd))
    throw std::invalid_argument(
        fmt::format("PID gains must be finite (kp = {}, ki = {}, kd = {})", gains.kp, gains.ki, gains.kd));
  if (!(gains.integral_max >= 0) || !std::isfinite(gains.integral_max))
    throw std::invalid_argument(fmt::format("PID integral_max = {}: must be finite and >= 0", gains.integral_max));
}

PidTerms Pid::update(double error, int64_t utime) {
  PidTerms t;
  t.error = error;
  t.p = gains_.kp * error;  // eq. 35
  if (!started_) {
    started_ = true;
    integral_ = 0.0;
    last_d_ = 0.0;
  } else {
    if (utime < last_utime_)
      throw std::invalid_argument(
          fmt::format("PID sample at utime {} is before the previous one ({})", utime, last_utime_));
    t.dt_s = static_cast<double>(utime - last_utime_) * 1e-6;
    if (t.dt_s > 0) {
      integral_ = std::clamp(integral_ + error * t.dt_s, -gains_.integral_max, gains_.integral_max);  // eq. 36
      last_d_ = gains_.kd * (error - last_error_) / t.dt_s;                                           // eq. 37
    }
  }
  t.integral = integral_;
  t.i = gains_.ki * integral_;
  t.d = last_d_;
  last_error_ = error;
  last_utime_ = utime;
  return t;
}

void Pid::reset() {
  started_ = false;
  integral_ = 0.0;
  last_error_ = 0.0;
  last_d_ = 0.0;
  last_utime_ = 0;
}

}  // namespace wingman::follower_ctrl
