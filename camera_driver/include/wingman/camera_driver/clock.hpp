// SPDX-License-Identifier: MIT
// Injectable clocks and sleeping for sources, so tests of pacing and backoff run instantly.
#pragma once

#include <cstdint>

namespace wingman::camera_driver {

/// The clocks a source reads and the way it waits. Sources use these only to stamp frames at the
/// source (clock-domain conversion, synthetic file timestamps), to pace file playback and to time
/// reconnection backoff; pipeline logic downstream uses the frames' utime.
class Clock {
 public:
  virtual ~Clock() = default;
  /// CLOCK_REALTIME, microseconds since the Unix epoch.
  virtual int64_t realtime_utime() = 0;
  /// CLOCK_MONOTONIC, microseconds since an arbitrary start (boot); the domain of V4L2 timestamps.
  virtual int64_t monotonic_utime() = 0;
  /// Sleeps `duration_us` microseconds (<= 0: returns at once).
  virtual void sleep_us(int64_t duration_us) = 0;
};

/// The system clocks and std::this_thread::sleep_for.
class SystemClock : public Clock {
 public:
  int64_t realtime_utime() override;
  int64_t monotonic_utime() override;
  void sleep_us(int64_t duration_us) override;
};

}  // namespace wingman::camera_driver
