// SPDX-License-Identifier: MIT
// The data that flows inside the localizer: a box's camera-frame localization and its world-frame form (the box
// itself is geometry::PixelBox).
#pragma once

#include <Eigen/Core>
#include <wingman/geometry/pixel_box.hpp>  // geometry::PixelBox, the detected box these come from

#include <cstdint>

namespace wingman::localizer {

/// One detection localized in the camera optical frame (x right, y down, z forward).
struct CameraMeasurement {
  Eigen::Vector3d p_target_in_cam = Eigen::Vector3d::Zero();   ///< target centre, metres
  Eigen::Matrix3d cov_p_in_cam = Eigen::Matrix3d::Identity();  ///< covariance of p_target_in_cam, m^2
  Eigen::Vector3d bearing_in_cam = Eigen::Vector3d::UnitZ();   ///< unit vector to the target centre
  double range = 0;                                            ///< camera centre to target centre, metres
  bool range_valid = true;  ///< false: the box was cut by the border on both axes (bearing only)
  double confidence = 1;    ///< detector confidence, 0..1
};

/// One detection in the world frame, as the tracker consumes it.
struct WorldMeasurement {
  int64_t utime = 0;  ///< exposure utime of the source image, microseconds since epoch
  int32_t camera_id = 0;
  Eigen::Vector3d p_target_in_world = Eigen::Vector3d::Zero();   ///< metres
  Eigen::Matrix3d cov_p_in_world = Eigen::Matrix3d::Identity();  ///< m^2
  Eigen::Vector3d p_target_in_cam = Eigen::Vector3d::Zero();     ///< kept for the output message, metres
  /// The camera's optical centre at the exposure, world frame, metres: a target of another size than configured lies
  /// along the ray from here (size_estimator.hpp).
  Eigen::Vector3d p_cam_in_world = Eigen::Vector3d::Zero();
  double range = 0;       ///< metres
  double confidence = 1;  ///< 0..1
};

}  // namespace wingman::localizer
