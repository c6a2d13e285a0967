// SPDX-License-Identifier: MIT
// Validation of the camera mount rotation.
#include "wingman/follower_ctrl/camera_mount.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <wingman/common/config.hpp>

#include <Eigen/LU>

#include <cmath>

namespace wingman::follower_ctrl {

std::vector<std::string> CameraMountOptions::validate() const {
  using common::problem;
  const std::string value = fmt::format("[{}]", fmt::join(R_cam_to_body, ", "));
  bool finite = R_cam_to_body.size() == 9;
  for (double x : R_cam_to_body) finite = finite && std::isfinite(x);
  if (!finite) return {problem("extrinsics.R_cam_to_body", value, "must be 9 finite numbers (3x3 row-major)")};
  const Eigen::Matrix3d R = rotation();
  const double orth_err = (R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orth_err > 1e-6)
    return {problem("extrinsics.R_cam_to_body", value,
                    fmt::format("must be orthonormal (|R R^T - I| = {:.3g} > 1e-6)", orth_err))};
  if (R.determinant() < 0)
    return {problem("extrinsics.R_cam_to_body", value, "must be a rotation (determinant +1, not a reflection)")};
  return {};
}

Eigen::Matrix3d CameraMountOptions::rotation() const {
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R_cam_to_body.data());
}

}  // namespace wingman::follower_ctrl
