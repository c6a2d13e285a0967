// SPDX-License-Identifier: MIT
// The thesis's discrete PID (eq. 34-37) on one scalar error, timed by message utimes.
#pragma once

#include <cstdint>

namespace wingman::follower_ctrl {

/// Gains of one PID loop. The output unit is whatever the gains make of the error unit (m/s per
/// normalised image unit for the thesis's 1-D follower, 1/s for the formation's position loop).
struct PidGains {
  double kp = 0.0;  ///< K_P, output per error unit (eq. 35); finite
  double ki = 0.0;  ///< K_I, output per (error unit * s) (eq. 36); finite
  double kd = 0.0;  ///< K_D, output per (error unit / s) (eq. 37); finite
  /// e_I,max: the accumulated integral sum(e * dt) is clamped to [-integral_max, +integral_max]
  /// (error unit * s), so |I| <= K_I * integral_max. >= 0; 0 disables the integral.
  double integral_max = 0.0;
};

/// The three terms of one step. output() is the command before any limit: v = P + I + D.
struct PidTerms {
  double error = 0.0;     ///< e_t, error unit
  double dt_s = 0.0;      ///< time since the previous sample, s (0 on the first sample after a reset)
  double integral = 0.0;  ///< sum(e * dt) after the clamp, error unit * s
  double p = 0.0;         ///< K_P e_t (eq. 35)
  double i = 0.0;         ///< K_I * integral (eq. 36)
  double d = 0.0;         ///< K_D (e_t - e_{t-1}) / dt (eq. 37)
  double output() const { return p + i + d; }
};

/// The thesis's PID, discretised on irregular message times:
///
///     e_t = (the caller's error; eq. 34 for the 1-D follower: e = u - 0.5)
///     P   = K_P e_t                                             (eq. 35)
///     S_t = clamp(S_{t-1} + e_t dt, -e_I,max, +e_I,max),  I = K_I S_t    (eq. 36)
///     D   = K_D (e_t - e_{t-1}) / dt                            (eq. 37)
///     dt  = (utime_t - utime_{t-1}) * 1e-6 s
///
/// The integral is a right (backward) Riemann sum: each sample's error is weighted by the time
/// since the previous sample. The clamp acts on the accumulated sum (anti-windup), so unwinding
/// starts at the first sample of the other sign. On the first sample after construction or
/// reset() there is no previous sample: S stays 0, so I = 0 and D = 0 and the output is P alone.
/// A sample at the same utime as the previous one (dt = 0) leaves S unchanged and repeats the
/// previous D; its error becomes e_{t-1} for the next sample.
class Pid {
 public:
  /// Throws std::invalid_argument when a gain is not finite or integral_max < 0.
  explicit Pid(const PidGains& gains);

  /// One step with error `error` at message time `utime` (microseconds). Throws
  /// std::invalid_argument when utime is before the previous sample's (the state is unchanged).
  PidTerms update(double error, int64_t utime);

  /// Forgets the integral and the previous error (the next update() is a first sample).
  void reset();

  bool started() const { return started_; }
  double integral() const { return integral_; }
  const PidGains& gains() const { return gains_; }

 private:
  PidGains gains_;
  bool started_ = false;
  int64_t last_utime_ = 0;
  double last_error_ = 0.0;
  double last_d_ = 0.0;
  double integral_ = 0.0;
};

}  // namespace wingman::follower_ctrl
