// SPDX-License-Identifier: MIT
// Rotations shared by unit tests, defined once so that the test files of one unity-build batch do not each define
// their own.
#pragma once

#include "test_constants.hpp"

#include <Eigen/Geometry>

namespace wingman::testing {

/// A rotation of `deg` degrees about +z (a heading change: ENU x towards y).
inline Eigen::Quaterniond yaw(double deg) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(deg * kPi / 180, Eigen::Vector3d::UnitZ()));
}

}  // namespace wingman::testing
