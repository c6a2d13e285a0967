// SPDX-License-Identifier: MIT
// Internal: the trapezoidal speed profile of a straight leg (accelerate, cruise, decelerate) and portable random
// numbers for the scripts.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

namespace wingman::sim::detail {

/// Distance along a leg of length `distance` (m) flown from rest to rest with cruise speed `speed` (m/s) and
/// acceleration `accel` (m/s^2); a triangle when the leg is too short to reach the cruise speed.
class Trapezoid {
 public:
  Trapezoid(double distance, double speed, double accel) : distance_(std::max(distance, 0.0)), accel_(accel) {
    peak_ = std::min(speed, std::sqrt(distance_ * accel_));
    t_ramp_ = peak_ / accel_;
    const double cruise_distance = distance_ - peak_ * t_ramp_;
    t_cruise_ = peak_ > 0 ? std::max(cruise_distance, 0.0) / peak_ : 0.0;
  }
  /// Total time, s.
  double duration() const { return 2.0 * t_ramp_ + t_cruise_; }
  /// Distance covered at time t (clamped to [0, duration()]), metres.
  double s(double t) const {
    t = std::clamp(t, 0.0, duration());
    if (t < t_ramp_) return 0.5 * accel_ * t * t;
    if (t < t_ramp_ + t_cruise_) return 0.5 * peak_ * t_ramp_ + peak_ * (t - t_ramp_);
    const double r = duration() - t;  // time left
    return distance_ - 0.5 * accel_ * r * r;
  }
  /// Speed at time t, m/s.
  double v(double t) const {
    if (t <= 0 || t >= duration()) return 0.0;
    if (t < t_ramp_) return accel_ * t;
    if (t < t_ramp_ + t_cruise_) return peak_;
    return accel_ * (duration() - t);
  }
  /// Acceleration at time t, m/s^2.
  double a(double t) const {
    if (t <= 0 || t >= duration()) return 0.0;
    if (t < t_ramp_) return accel_;
    if (t < t_ramp_ + t_cruise_) return 0.0;
    return -accel_;
  }

 private:
  double distance_, accel_, peak_ = 0, t_ramp_ = 0, t_cruise_ = 0;
};

/// Uniform numbers in [0, 1) from a 64-bit Mersenne twister, the same on every standard library
/// (std::uniform_real_distribution is not specified bit for bit).
class PortableRandom {
 public:
  explicit PortableRandom(uint64_t seed) : engine_(seed) {}
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Standard normal (Box-Muller).
  double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::mt19937_64 engine_;
};

/// SplitMix64: a well-mixed 64-bit value from a seed and an index (per-frame seeds).
inline uint64_t mix_seed(uint64_t seed, uint64_t index) {
  uint64_t z = seed + 0x9E3779B97F4A7C15ull * (index + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

}  // namespace wingman::sim::detail
