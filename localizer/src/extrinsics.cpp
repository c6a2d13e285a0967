// SPDX-License-Identifier: MIT
// Extrinsics options, validation, and the camera -> body -> world mapping.
#include "wingman/localizer/extrinsics.hpp"

#include <fmt/format.h>
#include <wingman/common/config.hpp>

#include <cmath>
#include <stdexcept>

namespace wingman::localizer {
namespace {

std::string list(const std::vector<double>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += fmt::format("{}{}", i ? ", " : "", v[i]);
  return s + "]";
}

bool all_finite(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

}  // namespace

std::vector<std::string> ExtrinsicsOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (p_cam_in_body.size() != 3 || !all_finite(p_cam_in_body))
    p.push_back(
        problem("extrinsics.p_cam_in_body", list(p_cam_in_body), "must be 3 finite numbers [x, y, z] in metres"));
  if (R_cam_to_body.size() != 9 || !all_finite(R_cam_to_body)) {
    p.push_back(problem("extrinsics.R_cam_to_body", list(R_cam_to_body), "must be 9 finite numbers (3x3 row-major)"));
  } else {
    const Eigen::Matrix3d R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R_cam_to_body.data());
    const double orth_err = (R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (orth_err > 1e-6)
      p.push_back(problem("extrinsics.R_cam_to_body", list(R_cam_to_body),
                          fmt::format("must be orthonormal (|R R^T - I| = {:.3g} > 1e-6)", orth_err)));
    else if (R.determinant() < 0)
      p.push_back(problem("extrinsics.R_cam_to_body", list(R_cam_to_body),
                          "must be a rotation (determinant +1, not a reflection)"));
  }
  return p;
}

Extrinsics Extrinsics::from_options(const ExtrinsicsOptions& options) {
  const auto problems = options.validate();
  if (!problems.empty()) {
    std::string all = "invalid ExtrinsicsOptions:";
    for (const auto& q : problems) all += " " + q + ";";
    throw std::invalid_argument(all);
  }
  Extrinsics e;
  e.R_cam_to_body = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(options.R_cam_to_body.data());
  e.p_cam_in_body = Eigen::Vector3d(options.p_cam_in_body[0], options.p_cam_in_body[1], options.p_cam_in_body[2]);
  return e;
}

CameraPoseInWorld camera_pose_in_world(const Extrinsics& extrinsics, const PoseSample& pose) {
  const Eigen::Matrix3d R_body_to_world = pose.q_body_to_world.normalized().toRotationMatrix();
  CameraPoseInWorld c;
  c.R_cam_to_world = R_body_to_world * extrinsics.R_cam_to_body;
  c.p_cam_in_world = R_body_to_world * extrinsics.p_cam_in_body + pose.p_body_in_world;
  return c;
}

WorldMeasurement to_world(const CameraMeasurement& m, const Extrinsics& extrinsics, const PoseSample& pose_at_exposure,
                          int64_t image_utime, int32_t camera_id) {
  const Eigen::Matrix3d R_body_to_world = pose_at_exposure.q_body_to_world.normalized().toRotationMatrix();
  const CameraPoseInWorld camera = camera_pose_in_world(extrinsics, pose_at_exposure);
  const Eigen::Matrix3d& R_cam_to_world = camera.R_cam_to_world;
  WorldMeasurement w;
  w.utime = image_utime;
  w.camera_id = camera_id;
  const Eigen::Vector3d p_target_in_body = extrinsics.cam_to_body(m.p_target_in_cam);
  w.p_target_in_world = R_body_to_world * p_target_in_body + pose_at_exposure.p_body_in_world;
  w.cov_p_in_world = rotate_covariance(R_cam_to_world, m.cov_p_in_cam);
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
