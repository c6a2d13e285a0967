// SPDX-License-Identifier: MIT
// Constants shared by unit tests (message times, angles), defined once so that the test files of one unity-build
// batch do not each define their own.
#pragma once

#include <cstdint>

namespace wingman::testing {

constexpr int64_t kT0 = 1'700'000'000'000'000;  ///< a message time (utime, microseconds: November 2023)
constexpr int64_t kMs = 1000;                   ///< one millisecond in utime units
constexpr int64_t kFrameUs = 33'333;            ///< one frame at 30 frames/s, in utime units
constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;  ///< one degree in radians (the same double as M_PI / 180.0)

}  // namespace wingman::testing
