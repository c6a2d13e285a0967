// SPDX-License-Identifier: MIT
// CameraModel: projection with distortion, undistortion with OpenCV polished by Newton steps, scaling.
#include "wingman/geometry/camera_model.hpp"

#include <fmt/format.h>
#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <cmath>
#include <stdexcept>
#include <utility>

namespace wingman::geometry {

const char* distortion_name(Distortion d) {
  switch (d) {
    case Distortion::kNone:
      return "none";
    case Distortion::kRadTan:
      return "plumb_bob";
    case Distortion::kRationalPolynomial:
      return "rational_polynomial";
    case Distortion::kEquidistant:
      return "equidistant";
  }
  return "?";
}

namespace {

bool finite(double x) { return std::isfinite(x); }

}  // namespace

CameraModel::CameraModel(int width, int height, double fx, double fy, double cx, double cy, Distortion distortion,
                         std::vector<double> coefficients, std::string name)
    : width_(width),
      height_(height),
      fx_(fx),
      fy_(fy),
      cx_(cx),
      cy_(cy),
      distortion_(distortion),
      coefficients_(std::move(coefficients)),
      name_(std::move(name)) {
  if (width_ <= 0 || height_ <= 0)
    throw std::invalid_argument(fmt::format("image size {}x{}: both sides must be > 0", width_, height_));
  if (!(finite(fx_) && fx_ > 0)) throw std::invalid_argument(fmt::format("fx = {}: must be finite and > 0", fx_));
  if (!(finite(fy_) && fy_ > 0)) throw std::invalid_argument(fmt::format("fy = {}: must be finite and > 0", fy_));
  if (!finite(cx_)) throw std::invalid_argument(fmt::format("cx = {}: must be finite", cx_));
  if (!finite(cy_)) throw std::invalid_argument(fmt::format("cy = {}: must be finite", cy_));
  const std::size_t n = coefficients_.size();
  switch (distortion_) {
    case Distortion::kNone:
      if (n != 0) throw std::invalid_argument(fmt::format("distortion 'none' takes no coefficients, got {}", n));
      break;
    case Distortion::kRadTan:
      if (n == 4) coefficients_.push_back(0.0);  // k3 = 0
      if (coefficients_.size() != 5)
        throw std::invalid_argument(
            fmt::format("plumb_bob/radtan distortion needs 4 or 5 coefficients "
                        "(k1, k2, p1, p2[, k3]), got {}",
                        n));
      break;
    case Distortion::kRationalPolynomial:
      if (n != 8)
        throw std::invalid_argument(
            fmt::format("rational_polynomial distortion needs 8 coefficients "
                        "(k1, k2, p1, p2, k3, k4, k5, k6), got {}",
                        n));
      break;
    case Distortion::kEquidistant:
      if (n != 4)
        throw std::invalid_argument(
            fmt::format("equidistant distortion needs 4 coefficients (k1, k2, k3, k4), got {}", n));
      break;
  }
  for (std::size_t i = 0; i < coefficients_.size(); ++i)
    if (!finite(coefficients_[i]))
      throw std::invalid_argument(fmt::format("distortion coefficient {} = {}: must be finite", i, coefficients_[i]));
}

CameraModel CameraModel::pinhole(int width, int height, double fx, double fy, double cx, double cy, std::string name) {
  return CameraModel(width, height, fx, fy, cx, cy, Distortion::kNone, {}, std::move(name));
}

std::string CameraModel::describe() const {
  return fmt::format("{} {}x{} fx={:.6g} fy={:.6g} cx={:.6g} cy={:.6g} D=[{:.6g}]", model_name(), width_, height_, fx_,
                     fy_, cx_, cy_, fmt::join(coefficients_, ", "));
}

Eigen::Vector2d CameraModel::distort_normalized(const Eigen::Vector2d& xy) const {
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  const std::vector<double>& k = coefficients_;
  switch (distortion_) {
    case Distortion::kNone:
      return xy;
    case Distortion::kRadTan:
    case Distortion::kRationalPolynomial: {
      const double r4 = r2 * r2, r6 = r4 * r2;
      double radial = 1 + k[0] * r2 + k[1] * r4 + k[4] * r6;
      if (distortion_ == Distortion::kRationalPolynomial) radial /= 1 + k[5] * r2 + k[6] * r4 + k[7] * r6;
      const double p1 = k[2], p2 = k[3];
      return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x), y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
    }
    case Distortion::kEquidistant: {
      const double r = std::sqrt(r2);
      if (r < 1e-12) return xy;  // theta_d / r -> 1
      const double theta = std::atan(r);
      const double t2 = theta * theta;
      const double theta_d = theta * (1 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))));
      return xy * (theta_d / r);
    }
  }
  return xy;
}

Eigen::Vector2d CameraModel::project(const Eigen::Vector3d& p_in_cam) const {
  const Eigen::Vector2d xy_d = distort_normalized(p_in_cam.head<2>() / p_in_cam.z());
  return {fx_ * xy_d.x() + cx_, fy_ * xy_d.y() + cy_};
}

Eigen::Vector2d CameraModel::undistort_to_normalized(const Eigen::Vector2d& uv) const {
  const Eigen::Vector2d xy_d((uv.x() - cx_) / fx_, (uv.y() - cy_) / fy_);
  if (distortion_ == Distortion::kNone) return xy_d;

  // OpenCV first (iterative, with tight criteria instead of the default 5 fixed iterations).
  cv::Point2d src(uv.x(), uv.y()), dst(0, 0);
  cv::Mat src_mat(1, 1, CV_64FC2, &src);
  cv::Mat dst_mat(1, 1, CV_64FC2, &dst);
  const cv::Matx33d K(fx_, 0, cx_, 0, fy_, cy_, 0, 0, 1);
  const cv::Mat D(1, static_cast<int>(coefficients_.size()), CV_64F, const_cast<double*>(coefficients_.data()));
  if (distortion_ == Distortion::kEquidistant) {
    cv::fisheye::undistortPoints(src_mat, dst_mat, K, D, cv::noArray(), cv::noArray(),
                                 cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 50, 1e-12));
  } else {
    cv::undistortPoints(src_mat, dst_mat, K, D, cv::noArray(), cv::noArray(),
                        cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 50, 1e-12));
  }
  const cv::Point2d out = dst_mat.at<cv::Point2d>(0, 0);  // dst_mat may have been reallocated
  Eigen::Vector2d xy(out.x, out.y);

  // Newton polish on distort_normalized(xy) = xy_d. OpenCV's fixed-point iteration stops at its own tolerance and
  // can diverge near the corners of strongly distorted lenses; start from the better of its result and xy_d, and
  // take damped Newton steps so that project(unproject(uv)) round-trips to ~1e-9 px.
  Eigen::Vector2d residual = distort_normalized(xy) - xy_d;
  const Eigen::Vector2d residual_d = distort_normalized(xy_d) - xy_d;
  if (!(xy.allFinite() && residual.allFinite() && residual.norm() <= residual_d.norm())) {
    xy = xy_d;
    residual = residual_d;
  }
  for (int iteration = 0; iteration < 30 && residual.norm() > 1e-15; ++iteration) {
    const double h = 1e-7 * std::max(1.0, xy.norm());
    Eigen::Matrix2d J;
    J.col(0) =
        (distort_normalized(xy + Eigen::Vector2d(h, 0)) - distort_normalized(xy - Eigen::Vector2d(h, 0))) / (2 * h);
    J.col(1) =
        (distort_normalized(xy + Eigen::Vector2d(0, h)) - distort_normalized(xy - Eigen::Vector2d(0, h))) / (2 * h);
    const Eigen::Vector2d step = J.partialPivLu().solve(residual);
    bool improved = false;
    for (double scale = 1.0; scale > 1e-3 && step.allFinite(); scale *= 0.5) {
      const Eigen::Vector2d candidate = xy - scale * step;
      const Eigen::Vector2d candidate_residual = distort_normalized(candidate) - xy_d;
      if (candidate_residual.norm() < residual.norm()) {
        xy = candidate;
        residual = candidate_residual;
        improved = true;
        break;
      }
    }
    if (!improved) break;  // not invertible here (or converged to rounding): keep the best so far
  }
  return xy;
}

Eigen::Vector3d CameraModel::unproject(const Eigen::Vector2d& uv) const {
  const Eigen::Vector2d xy = undistort_to_normalized(uv);
  return Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized();
}

CameraModel CameraModel::scaled_to(int width, int height) const {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument(fmt::format("scaled_to({}x{}): both sides must be > 0", width, height));
  const double sx = static_cast<double>(width) / width_;
  const double sy = static_cast<double>(height) / height_;
  return CameraModel(width, height, sx * fx_, sy * fy_, sx * (cx_ + 0.5) - 0.5, sy * (cy_ + 0.5) - 0.5, distortion_,
                     coefficients_, name_);
}

std::string CameraModel::check_image_size(int width, int height) const {
  if (width == width_ && height == height_) return "";
  return fmt::format(
      "the calibration is for {}x{} images but the images are {}x{} (use a calibration for this size, or scale it "
      "if the images are a resize of the calibrated ones)",
      width_, height_, width, height);
}

}  // namespace wingman::geometry
