// SPDX-License-Identifier: MIT
// SystemClock: CLOCK_REALTIME, CLOCK_MONOTONIC and sleep_for.
#include "wingman/camera_driver/clock.hpp"

#include <chrono>
#include <ctime>
#include <thread>

namespace wingman::camera_driver {
namespace {
int64_t clock_utime(clockid_t id) {
  timespec ts{};
  clock_gettime(id, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000000 + ts.tv_nsec / 1000;
}
}  // namespace

int64_t SystemClock::realtime_utime() { return clock_utime(CLOCK_REALTIME); }
int64_t SystemClock::monotonic_utime() { return clock_utime(CLOCK_MONOTONIC); }
void SystemClock::sleep_us(int64_t duration_us) {
  if (duration_us > 0) std::this_thread::sleep_for(std::chrono::microseconds(duration_us));
}

}  // namespace wingman::camera_driver
