// SPDX-License-Identifier: MIT
// SizeEstimator: weighted least squares of the target's path (constant acceleration) and its inverse range scale over
// a window of detections, with a prior.
#include "wingman/localizer/size_estimator.hpp"

#include <fmt/format.h>
#include <Eigen/Cholesky>
#include <wingman/common/config.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wingman::localizer {

std::vector<std::string> SizeEstimatorOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (!(prior_rel > 0 && prior_rel <= 1))
    p.push_back(problem("tracker.size_prior_rel", prior_rel, "must be in (0, 1]"));
  if (!(window_s > 0 && std::isfinite(window_s)))
    p.push_back(problem("tracker.size_window_s", window_s, "must be finite and > 0"));
  if (min_detections < 3) p.push_back(problem("tracker.size_min_detections", min_detections, "must be >= 3"));
  if (!(accept_rel > 0 && accept_rel <= 1))
    p.push_back(problem("tracker.size_accept_rel", accept_rel, "must be in (0, 1]"));
  return p;
}

bool SizeEstimate::acceptable(double accept_rel) const {
  return from_data && sigma <= accept_rel * scale && chi2_dof <= kMaxFitChi2Dof && scale > 0.2 && scale < 5.0;
}

SizeEstimator::SizeEstimator(SizeEstimatorOptions options) : options_(std::move(options)) {
  const auto problems = options_.validate();
  if (!problems.empty())
    throw std::invalid_argument("invalid SizeEstimatorOptions: " + fmt::format("{}", fmt::join(problems, "; ")));
}

void SizeEstimator::add(int64_t utime, const Eigen::Vector3d& z_in_world, const Eigen::Matrix3d& R,
                        const Eigen::Vector3d& c_in_world) {
  if (!options_.enabled) return;
  // Time went back: start again (several cameras of one exposure add samples at the same time).
  if (!samples_.empty() && utime < samples_.back().utime) samples_.clear();
  samples_.push_back({utime, z_in_world - c_in_world, c_in_world, 0.5 * (R + R.transpose())});
  const int64_t window_us = static_cast<int64_t>(std::llround(options_.window_s * 1e6));
  while (!samples_.empty() && utime - samples_.front().utime > window_us) samples_.pop_front();
}

SizeEstimate SizeEstimator::estimate() const {
  const SizeEstimate prior{1.0, options_.prior_rel, false};
  if (!options_.enabled) return {1.0, 0.0, false};
  const double span_s =
      samples_.empty() ? 0.0 : 1e-6 * static_cast<double>(samples_.back().utime - samples_.front().utime);
  if (static_cast<int>(samples_.size()) < options_.min_detections || span_s < 0.9 * options_.window_s) return prior;

  using Matrix10d = Eigen::Matrix<double, 10, 10>;
  using Vector10d = Eigen::Matrix<double, 10, 1>;
  // In the detections' own space, with w = 1 / s: r_i = z_i - c_i = w p0 + w v t_i + w a t_i^2 / 2 - w c_i + e_i with
  // e_i ~ N(0, R_i), linear in (w p0, w v, w a, w). (Fitting p0 + v t_i = c_i + s r_i instead has a trap: s = 0 puts
  // the target on the camera and fits exactly.)
  const int64_t t_ref = samples_.back().utime;
  Matrix10d A = Matrix10d::Zero();
  Vector10d b = Vector10d::Zero();
  std::vector<Eigen::Matrix3d> W(samples_.size());
  std::vector<Eigen::Matrix<double, 3, 10>> J(samples_.size());
  for (size_t i = 0; i < samples_.size(); ++i) {
    const Sample& x = samples_[i];
    const double t = 1e-6 * static_cast<double>(x.utime - t_ref);
    J[i] << Eigen::Matrix3d::Identity(), t * Eigen::Matrix3d::Identity(), 0.5 * t * t * Eigen::Matrix3d::Identity(),
        -x.c;
    W[i] = x.R.ldlt().solve(Eigen::Matrix3d::Identity());
    A += J[i].transpose() * W[i] * J[i];
    b += J[i].transpose() * W[i] * x.r;
  }
  // The prior w = 1 +- prior_rel, then the data's chi-square per degree of freedom: it inflates the data's covariance
  // when the straight-path model fits worse than the detections' covariances say (a manoeuvre).
  const double prior_w = 1.0 / (options_.prior_rel * options_.prior_rel);
  Matrix10d A1 = A;
  Vector10d b1 = b;
  A1(9, 9) += prior_w;
  b1(9) += prior_w;
  const Vector10d theta1 = A1.ldlt().solve(b1);
  double chi2 = 0;
  for (size_t i = 0; i < samples_.size(); ++i) {
    const Eigen::Vector3d e = J[i] * theta1 - samples_[i].r;
    chi2 += e.dot(W[i] * e);
  }
  const double dof = std::max(1.0, 3.0 * static_cast<double>(samples_.size()) - 10.0);
  const double inflate = std::max(1.0, chi2 / dof);
  A /= inflate;
  b /= inflate;
  A(9, 9) += prior_w;
  b(9) += prior_w;
  const Eigen::LDLT<Matrix10d> full(A);
  const Vector10d theta = full.solve(b);
  const Matrix10d cov = full.solve(Matrix10d::Identity());
  const double w = theta(9);
  if (!theta.allFinite() || !(cov(9, 9) > 0) || !(w > 0)) return prior;
  SizeEstimate out;
  out.scale = std::clamp(1.0 / w, 0.2, 5.0);
  out.sigma = std::sqrt(cov(9, 9)) / (w * w);  // d(1/w) = -dw / w^2
  out.from_data = true;
  out.chi2_dof = chi2 / dof;
  return out;
}

}  // namespace wingman::localizer
