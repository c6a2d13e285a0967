// SPDX-License-Identifier: MIT
// How the camera is mounted on the follower's body (rotation only): which way the image's right and
// the optical axis point.
#pragma once

#include <Eigen/Core>

#include <string>
#include <vector>

namespace wingman::follower_ctrl {

/// The camera's orientation on the body, with the same key and default as the localizer's
/// `extrinsics.R_cam_to_body` (docs/localization.md): camera optical frame (x right, y down,
/// z forward) -> body (FLU). The default looks along body +x with the image upright:
/// @code
///   [ 0  0  1 ]    body x (forward) = camera z
///   [-1  0  0 ]    body y (left)    = -camera x
///   [ 0 -1  0 ]    body z (up)      = -camera y
/// @endcode
/// The follower needs the rotation only: the pid_1d controller moves along the camera's x axis
/// (image right) and the formation controller turns the optical axis (camera z) towards the target.
/// The camera's offset from the body origin shifts the bearing by under 3 degrees at 6 m and is not used.
struct CameraMountOptions {
  /// Rotation camera -> body, 3x3 row-major (9 values); orthonormal (1e-6) with determinant +1.
  std::vector<double> R_cam_to_body = {0, 0, 1, -1, 0, 0, 0, -1, 0};

  template <class V>
  void visit(V& v) {
    v("extrinsics.R_cam_to_body", R_cam_to_body,
      "rotation camera optical frame (x right, y down, z fwd) -> body (FLU), 3x3 row-major; same as the localizer's");
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
  /// The rotation. Precondition: validate() is empty.
  Eigen::Matrix3d rotation() const;
};

}  // namespace wingman::follower_ctrl
