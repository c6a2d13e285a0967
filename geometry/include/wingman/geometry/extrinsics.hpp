// SPDX-License-Identifier: MIT
// Camera-to-body extrinsics: where the camera sits on the body and which way it looks.
#pragma once

#include <Eigen/Core>

#include <string>
#include <vector>

namespace wingman::geometry {

/// Frames and sign conventions (docs/localization.md, "Frames"):
/// - camera optical frame: x right, y down, z forward (out of the lens), origin at the optical centre;
/// - body frame: FLU, x forward, y left, z up, origin at the body reference point of own_pose_t;
/// - world frame: ENU (own_pose_t.FRAME_ENU); NED/FRD poses are converted by the localizer's
///   pose_ned_frd_to_enu_flu() (with ned_enu.hpp).
/// The camera -> body -> world mapping of a measurement is the localizer's (localizer/camera_to_world.hpp).
///
/// A point maps as p_in_body = R_cam_to_body * p_in_cam + p_cam_in_body, where p_cam_in_body is the
/// camera's optical centre expressed in the body frame. Hand-worked case: a camera 0.24 m in front
/// of the body origin (p_cam_in_body = [0.24, 0, 0]) looking forward sees a target 10 m straight
/// ahead at p_in_cam = [0, 0, 10] and places it at p_in_body = [10.24, 0, 0] (the thesis subtracted
/// the offset).
///
/// The default R_cam_to_body (camera looking along body +x, image top towards body +z):
/// @code
///   [ 0  0  1 ]    body x (forward) = camera z
///   [-1  0  0 ]    body y (left)    = -camera x
///   [ 0 -1  0 ]    body z (up)      = -camera y
/// @endcode
/// Its columns are the camera axes written in the body frame.
struct ExtrinsicsOptions {
  /// Camera optical centre in the body frame (FLU), [x, y, z], metres.
  std::vector<double> p_cam_in_body = {0.0, 0.0, 0.0};
  /// Rotation from the camera optical frame to the body frame, 3x3 row-major (9 values); must be
  /// orthonormal with determinant +1 (tolerance 1e-6). Default: camera looking forward, upright.
  std::vector<double> R_cam_to_body = {0, 0, 1, -1, 0, 0, 0, -1, 0};

  template <class V>
  void visit(V& v) {
    v("extrinsics.p_cam_in_body", p_cam_in_body, "camera optical centre in the body frame (FLU) [x, y, z], m");
    v("extrinsics.R_cam_to_body", R_cam_to_body,
      "rotation camera optical frame (x right, y down, z fwd) -> body (FLU), 3x3 row-major; columns = camera axes "
      "in body");
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
};

/// The check of a camera -> body rotation given as 3x3 row-major values under `key` (the localizer's and the
/// follower's `extrinsics.R_cam_to_body`): 9 finite numbers, orthonormal (|R R^T - I| <= 1e-6), determinant +1.
/// Returns at most one "key = value: rule" line; empty when valid.
std::vector<std::string> rotation_problems(const std::string& key, const std::vector<double>& R_row_major);

/// A rigid camera mount on the body.
struct Extrinsics {
  Eigen::Matrix3d R_cam_to_body = Eigen::Matrix3d::Identity();  ///< rotates camera-frame vectors into body
  Eigen::Vector3d p_cam_in_body = Eigen::Vector3d::Zero();      ///< camera optical centre in body, metres

  /// Builds the mount from validated options. Throws std::invalid_argument listing validate() problems.
  static Extrinsics from_options(const ExtrinsicsOptions& options);

  /// p_in_body = R_cam_to_body * p_in_cam + p_cam_in_body, metres.
  Eigen::Vector3d cam_to_body(const Eigen::Vector3d& p_in_cam) const {
    return R_cam_to_body * p_in_cam + p_cam_in_body;
  }
};

/// Rotates a covariance: returns R cov R^T (the covariance of R x when cov is that of x).
inline Eigen::Matrix3d rotate_covariance(const Eigen::Matrix3d& R_a_to_b, const Eigen::Matrix3d& cov_in_a) {
  return R_a_to_b * cov_in_a * R_a_to_b.transpose();
}

}  // namespace wingman::geometry
