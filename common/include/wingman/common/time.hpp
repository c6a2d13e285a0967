// SPDX-License-Identifier: MIT
// Clock helpers. Pipeline logic uses message utimes; these are for stamping sources and monitoring.
#pragma once

#include <cstdint>

namespace wingman::common {

/// Wall-clock (CLOCK_REALTIME) time, microseconds since the Unix epoch.
int64_t wall_utime();
/// CLOCK_MONOTONIC time, microseconds since an arbitrary start (boot).
int64_t monotonic_utime();

}  // namespace wingman::common
