// SPDX-License-Identifier: MIT
// Simulated camera frame times: frame k is exposed at start_utime + round(k * 1e6 / rate_hz) microseconds.
#pragma once

#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace wingman::sim {

/// The camera's frame times in simulated time. Every part of the simulator takes frame times from here, so
/// comparisons between them are exact.
class FrameClock {
 public:
  /// `start_utime`: exposure of frame 0, microseconds since epoch (>= 0); `rate_hz`: frames per second (> 0).
  /// Throws std::invalid_argument otherwise.
  FrameClock(int64_t start_utime, double rate_hz) : start_utime_(start_utime), rate_hz_(rate_hz) {
    if (start_utime < 0) throw std::invalid_argument("FrameClock: start_utime must be >= 0");
    if (!(rate_hz > 0) || !std::isfinite(rate_hz)) throw std::invalid_argument("FrameClock: rate_hz must be > 0");
  }

  int64_t start_utime() const { return start_utime_; }
  double rate_hz() const { return rate_hz_; }

  /// Exposure utime of frame `k` (k >= 0), microseconds since epoch.
  int64_t utime(int64_t k) const {
    return start_utime_ + static_cast<int64_t>(std::llround(static_cast<double>(k) * 1e6 / rate_hz_));
  }
  /// Seconds from frame 0 to `utime`.
  double seconds_since_start(int64_t utime) const { return static_cast<double>(utime - start_utime_) * 1e-6; }
  /// Number of frames whose exposure lies before `end_utime` (frames 0 .. n-1 have utime(k) < end_utime).
  int64_t frames_before(int64_t end_utime) const {
    if (end_utime <= start_utime_) return 0;
    int64_t k = static_cast<int64_t>(std::floor(seconds_since_start(end_utime) * rate_hz_));
    while (k > 0 && utime(k) >= end_utime) --k;  // correct the floating-point estimate on both sides
    while (utime(k) < end_utime) ++k;
    return k;
  }

 private:
  int64_t start_utime_;
  double rate_hz_;
};

}  // namespace wingman::sim
