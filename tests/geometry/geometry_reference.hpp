// SPDX-License-Identifier: MIT
// Test cameras for the four distortion models and an independent sphere projection through OpenCV.
#pragma once

#include <wingman/geometry/camera_model.hpp>
#include <wingman/geometry/pixel_box.hpp>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <cmath>
#include <string>
#include <vector>

namespace wingman::geometry::testing {

/// One test camera per distortion model. The distortion is monotonic well beyond each image's corners.
struct TestCamera {
  std::string label;
  CameraModel camera;
};

inline std::vector<TestCamera> test_cameras() {
  return {
      // The thesis's setting: an ideal pinhole, f = 640 px, 1280x720.
      {"pinhole", CameraModel::pinhole(1280, 720, 640, 640, 639.5, 359.5)},
      // A Raspberry Pi camera v2 (1280x720 mode) calibration, rounded.
      {"plumb_bob", CameraModel(1280, 720, 1276.7, 1274.3, 634.9, 379.8, Distortion::kRadTan,
                                {0.1465, -0.2847, 0.00134, -0.00431, 0.0})},
      // A moderate wide lens (about 77 x 48 degrees) in the rational model, k4..k6 active.
      {"rational_polynomial", CameraModel(1280, 720, 800, 800, 641.2, 358.7, Distortion::kRationalPolynomial,
                                          {0.25, -0.1, 0.0005, -0.0008, 0.01, 0.3, -0.05, 0.01})},
      // A FLIR Firefly S with a fisheye lens (the vswarm drones), 720x540, about 150 degrees across.
      {"equidistant", CameraModel(720, 540, 260.27, 260.04, 330.08, 261.90, Distortion::kEquidistant,
                                  {-0.02016, 0.00607, -0.00675, 0.00158})},
  };
}

/// Projects 3D points with OpenCV (cv::projectPoints or cv::fisheye::projectPoints): independent of
/// CameraModel::project().
inline std::vector<cv::Point2d> opencv_project(const CameraModel& camera, const std::vector<cv::Point3d>& points) {
  std::vector<cv::Point2d> out;
  const cv::Matx33d K(camera.fx(), 0, camera.cx(), 0, camera.fy(), camera.cy(), 0, 0, 1);
  const cv::Vec3d zero(0, 0, 0);
  if (camera.distortion() == Distortion::kEquidistant) {
    cv::fisheye::projectPoints(points, out, zero, zero, K, camera.coefficients());
  } else {
    cv::projectPoints(points, zero, zero, K, camera.coefficients(), out);
  }
  return out;
}

/// Independent reference of a sphere's image bounding box: `samples` points on the silhouette circle (the tangent
/// cone's circle of tangency on the sphere) projected with OpenCV, min/max of u and v. Calibration pixels.
/// Error from the sampling <= R_px (pi / samples)^2 / 2 for a silhouette of radius R_px pixels.
struct ReferenceBox {
  double u_min, u_max, v_min, v_max;
  PixelBox pixel_box() const {
    return {0.5 * (u_min + u_max) + kBoxToCameraPixel, 0.5 * (v_min + v_max) + kBoxToCameraPixel, u_max - u_min,
            v_max - v_min};
  }
};

inline ReferenceBox reference_sphere_box(const CameraModel& camera, const Eigen::Vector3d& centre, double radius,
                                         int samples = 20000) {
  const double l = centre.norm();
  const Eigen::Vector3d axis = centre / l;
  const Eigen::Vector3d e1 = axis.unitOrthogonal();
  const Eigen::Vector3d e2 = axis.cross(e1);
  // The circle of tangency: centre at distance (l^2 - r^2) / l along the axis, radius r sqrt(l^2 - r^2) / l.
  const double along = (l * l - radius * radius) / l;
  const double rho = radius * std::sqrt(l * l - radius * radius) / l;
  std::vector<cv::Point3d> points(samples);
  for (int i = 0; i < samples; ++i) {
    const double phi = 2 * M_PI * i / samples;
    const Eigen::Vector3d p = along * axis + rho * (std::cos(phi) * e1 + std::sin(phi) * e2);
    points[i] = cv::Point3d(p.x(), p.y(), p.z());
  }
  ReferenceBox box{1e300, -1e300, 1e300, -1e300};
  for (const cv::Point2d& uv : opencv_project(camera, points)) {
    box.u_min = std::min(box.u_min, uv.x);
    box.u_max = std::max(box.u_max, uv.x);
    box.v_min = std::min(box.v_min, uv.y);
    box.v_max = std::max(box.v_max, uv.y);
  }
  return box;
}

/// Angle between two vectors, degrees.
inline double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI;
}

}  // namespace wingman::geometry::testing
