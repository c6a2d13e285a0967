// SPDX-License-Identifier: MIT
// Validation of the camera mount rotation.
#include "wingman/follower_ctrl/camera_mount.hpp"

#include <wingman/geometry/extrinsics.hpp>

namespace wingman::follower_ctrl {

std::vector<std::string> CameraMountOptions::validate() const {
  return geometry::rotation_problems("extrinsics.R_cam_to_body", R_cam_to_body);  // the localizer's check
}

Eigen::Matrix3d CameraMountOptions::rotation() const {
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R_cam_to_body.data());
}

}  // namespace wingman::follower_ctrl
