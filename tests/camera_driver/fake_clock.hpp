// SPDX-License-Identifier: MIT
// A Clock for tests: time moves only when a source sleeps or the test advances it.
#pragma once

#include "wingman/camera_driver/clock.hpp"

#include <cstdint>
#include <vector>

namespace wingman::camera_driver::testing {

/// Realtime and monotonic clocks that advance together, only through sleep_us() and advance().
class FakeClock : public Clock {
 public:
  /// Start values, microseconds: wall clock at 2023-11-14T22:13:20Z, monotonic at 1000 s after boot.
  static constexpr int64_t kStartRealtimeUs = 1'700'000'000'000'000;
  static constexpr int64_t kStartMonotonicUs = 1'000'000'000;

  int64_t realtime_utime() override { return realtime_us_; }
  int64_t monotonic_utime() override { return monotonic_us_; }
  void sleep_us(int64_t duration_us) override {
    sleeps_us_.push_back(duration_us);
    if (duration_us > 0) advance(duration_us);
  }

  /// Moves both clocks forward by `us` microseconds.
  void advance(int64_t us) {
    realtime_us_ += us;
    monotonic_us_ += us;
  }
  /// Every sleep_us() argument, in call order.
  const std::vector<int64_t>& sleeps_us() const { return sleeps_us_; }

 private:
  int64_t realtime_us_ = kStartRealtimeUs;
  int64_t monotonic_us_ = kStartMonotonicUs;
  std::vector<int64_t> sleeps_us_;
};

}  // namespace wingman::camera_driver::testing
