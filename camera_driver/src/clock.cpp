// SPDX-License-Identifier: MIT
// SystemClock: CLOCK_REALTIME, CLOCK_MONOTONIC (from common) and sleep_for.
#include "wingman/camera_driver/clock.hpp"

#include <wingman/common/time.hpp>

#include <chrono>
#include <thread>

namespace wingman::camera_driver {

int64_t SystemClock::realtime_utime() { return common::wall_utime(); }
int64_t SystemClock::monotonic_utime() { return common::monotonic_utime(); }
void SystemClock::sleep_us(int64_t duration_us) {
  if (duration_us > 0) std::this_thread::sleep_for(std::chrono::microseconds(duration_us));
}

}  // namespace wingman::camera_driver
