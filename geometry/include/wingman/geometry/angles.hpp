// SPDX-License-Identifier: MIT
// The one angle wrap of Wingman: headings and heading errors in (-pi, pi] (the follower, wingman-mavlink, the
// simulator).
#pragma once

#include <cmath>

namespace wingman::geometry {

/// Angle wrapped into (-pi, pi], radians: -pi maps to pi, 3 pi to pi, 2 pi to 0. NaN and infinities give NaN.
inline double wrap_pi(double angle_rad) {
  const double a = std::remainder(angle_rad, 2.0 * M_PI);  // [-pi, pi]
  return a <= -M_PI ? a + 2.0 * M_PI : a;
}

}  // namespace wingman::geometry
