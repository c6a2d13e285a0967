// SPDX-License-Identifier: MIT
// The camera -> body -> world mapping of one measurement at the own pose of its exposure.
#pragma once

#include "wingman/localizer/measurement.hpp"
#include "wingman/localizer/pose_buffer.hpp"

#include <Eigen/Core>
#include <wingman/geometry/extrinsics.hpp>

#include <cstdint>

namespace wingman::localizer {

// Frames as in geometry/extrinsics.hpp: camera optical frame (x right, y down, z forward), body FLU, world ENU.

/// The camera's pose in the world frame at a body pose: R_cam_to_world = R_body_to_world R_cam_to_body and the optical
/// centre p_cam_in_world = R_body_to_world p_cam_in_body + p_body_in_world.
struct CameraPoseInWorld {
  Eigen::Matrix3d R_cam_to_world = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_cam_in_world = Eigen::Vector3d::Zero();  ///< metres
};
CameraPoseInWorld camera_pose_in_world(const geometry::Extrinsics& extrinsics, const PoseSample& pose);

/// Maps a camera-frame measurement into the world frame with the body pose at the image's exposure
/// time (`pose_at_exposure`, from PoseBuffer::at(image_utime)):
/// p_in_world = R_body_to_world (R_cam_to_body p_in_cam + p_cam_in_body) + p_body_in_world,
/// cov_in_world = R_cam_to_world cov_in_cam R_cam_to_world^T with R_cam_to_world = R_body_to_world R_cam_to_body,
/// plus the own pose's uncertainty to first order (both zero where the pose reports none):
/// + cov_p_body_in_world, the body position's, and
/// + R_body_to_world [p_b]x diag(var_rpy_body) [p_b]x^T R_body_to_world^T, the attitude's, with p_b the target in the
///   body frame (a small body rotation dtheta moves the target by -R_body_to_world [p_b]x dtheta).
/// `image_utime` and `camera_id` are copied to the result, as are p_target_in_cam, range and confidence.
WorldMeasurement to_world(const CameraMeasurement& m, const geometry::Extrinsics& extrinsics,
                          const PoseSample& pose_at_exposure, int64_t image_utime, int32_t camera_id);

}  // namespace wingman::localizer
