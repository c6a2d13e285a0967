// SPDX-License-Identifier: MIT
// Extrinsics options and their validation (the camera -> body rotation's check shared with the follower).
#include "wingman/geometry/extrinsics.hpp"

#include <fmt/format.h>
#include <wingman/common/config.hpp>

#include <Eigen/LU>

#include <cmath>
#include <stdexcept>
#include <utility>

namespace wingman::geometry {
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

std::vector<std::string> rotation_problems(const std::string& key, const std::vector<double>& R_row_major) {
  using common::problem;
  if (R_row_major.size() != 9 || !all_finite(R_row_major))
    return {problem(key, list(R_row_major), "must be 9 finite numbers (3x3 row-major)")};
  const Eigen::Matrix3d R = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R_row_major.data());
  const double orth_err = (R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orth_err > 1e-6)
    return {
        problem(key, list(R_row_major), fmt::format("must be orthonormal (|R R^T - I| = {:.3g} > 1e-6)", orth_err))};
  if (R.determinant() < 0)
    return {problem(key, list(R_row_major), "must be a rotation (determinant +1, not a reflection)")};
  return {};
}

std::vector<std::string> ExtrinsicsOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (p_cam_in_body.size() != 3 || !all_finite(p_cam_in_body))
    p.push_back(
        problem("extrinsics.p_cam_in_body", list(p_cam_in_body), "must be 3 finite numbers [x, y, z] in metres"));
  for (std::string& q : rotation_problems("extrinsics.R_cam_to_body", R_cam_to_body)) p.push_back(std::move(q));
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

}  // namespace wingman::geometry
