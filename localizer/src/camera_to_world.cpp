// SPDX-License-Identifier: MIT
// The camera -> body -> world mapping of one measurement.
#include "wingman/localizer/camera_to_world.hpp"

namespace wingman::localizer {

CameraPoseInWorld camera_pose_in_world(const geometry::Extrinsics& extrinsics, const PoseSample& pose) {
  const Eigen::Matrix3d R_body_to_world = pose.q_body_to_world.normalized().toRotationMatrix();
  CameraPoseInWorld c;
  c.R_cam_to_world = R_body_to_world * extrinsics.R_cam_to_body;
  c.p_cam_in_world = R_body_to_world * extrinsics.p_cam_in_body + pose.p_body_in_world;
  return c;
}

WorldMeasurement to_world(const CameraMeasurement& m, const geometry::Extrinsics& extrinsics,
                          const PoseSample& pose_at_exposure, int64_t image_utime, int32_t camera_id) {
  const Eigen::Matrix3d R_body_to_world = pose_at_exposure.q_body_to_world.normalized().toRotationMatrix();
  const CameraPoseInWorld camera = camera_pose_in_world(extrinsics, pose_at_exposure);
  const Eigen::Matrix3d& R_cam_to_world = camera.R_cam_to_world;
  WorldMeasurement w;
  w.utime = image_utime;
  w.camera_id = camera_id;
  const Eigen::Vector3d p_target_in_body = extrinsics.cam_to_body(m.p_target_in_cam);
  w.p_target_in_world = R_body_to_world * p_target_in_body + pose_at_exposure.p_body_in_world;
  w.cov_p_in_world = geometry::rotate_covariance(R_cam_to_world, m.cov_p_in_cam);
  if (!pose_at_exposure.var_rpy_body.isZero(0.0)) {
    Eigen::Matrix3d skew;
    skew << 0, -p_target_in_body.z(), p_target_in_body.y(),  //
        p_target_in_body.z(), 0, -p_target_in_body.x(),      //
        -p_target_in_body.y(), p_target_in_body.x(), 0;
    const Eigen::Matrix3d J = R_body_to_world * skew;  // d p_target_in_world / d dtheta, up to sign
    w.cov_p_in_world += J * pose_at_exposure.var_rpy_body.asDiagonal() * J.transpose();
  }
  w.cov_p_in_world += pose_at_exposure.cov_p_body_in_world;
  w.cov_p_in_world = 0.5 * (w.cov_p_in_world + w.cov_p_in_world.transpose());  // exact symmetry for the filter
  w.p_target_in_cam = m.p_target_in_cam;
  w.p_cam_in_world = camera.p_cam_in_world;
  w.range = m.range;
  w.confidence = m.confidence;
  return w;
}

}  // namespace wingman::localizer
