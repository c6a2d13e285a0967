// SPDX-License-Identifier: MIT
// Helpers shared by the renderer tests: cameras with real distortion, camera poses, boxes measured from pixels.
#pragma once

#include "test_support.hpp"

#include <wingman/geometry/camera_model.hpp>
#include <wingman/sim/renderer.hpp>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <sys/stat.h>
#include <cmath>
#include <string>
#include <vector>

namespace wingman::sim::test {

/// The problems of a validate(), one per line, for readable failures.
inline std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += x + "\n";
  return s;
}

/// "" when ../shared/<sub> exists, else the path that is missing (for GTEST_SKIP messages).
inline std::string missing_shared(const std::string& sub) {
  const std::string path = wingman::testing::source_path("../shared/" + sub);
  struct stat st {};
  return stat(path.c_str(), &st) == 0 ? "" : path;
}
inline std::string shared_path(const std::string& sub) { return wingman::testing::source_path("../shared/" + sub); }

/// A 1280x720 plumb_bob camera with strong barrel distortion (corners pulled in by ~60 px).
inline geometry::CameraModel strong_radtan() {
  return geometry::CameraModel(1280, 720, 820.0, 815.0, 645.3, 355.8, geometry::Distortion::kRadTan,
                               {-0.32, 0.11, 0.0012, -0.0009, -0.015}, "strong_radtan");
}

/// A 1280x720 equidistant (fisheye) camera, about 130 degrees across.
inline geometry::CameraModel fisheye() {
  return geometry::CameraModel(1280, 720, 560.0, 560.0, 639.5, 359.5, geometry::Distortion::kEquidistant,
                               {0.02, -0.01, 0.003, -0.0005}, "fisheye");
}

/// An ideal 1280x720 pinhole, 70 degrees across.
inline geometry::CameraModel pinhole() {
  return geometry::CameraModel::pinhole(1280, 720, 914.0, 914.0, 639.5, 359.5, "pinhole");
}

/// The camera-to-world pose of a camera at `eye` looking at `target` (world ENU), image x level with the horizon.
inline Eigen::Isometry3d look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - eye).normalized();
  Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ());
  if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitX();
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = y;
  T.linear().col(2) = z;
  T.translation() = eye;
  return T;
}

/// World position that the camera sees at calibration pixel `uv`, `range` metres away.
inline Eigen::Vector3d world_at_pixel(const geometry::CameraModel& camera, const Eigen::Isometry3d& T_cam_to_world,
                                      const Eigen::Vector2d& uv, double range) {
  return T_cam_to_world * (camera.unproject(uv) * range);
}

/// Tight box (box convention: pixel (i, j) spans [i, i + 1] x [j, j + 1]) of the non-zero pixels of `mask` (CV_8U).
/// visible = false when there are none.
inline RenderedBox box_of(const cv::Mat& mask) {
  RenderedBox box;
  int x0 = mask.cols, y0 = mask.rows, x1 = -1, y1 = -1;
  for (int y = 0; y < mask.rows; ++y) {
    for (int x = 0; x < mask.cols; ++x) {
      if (mask.at<uint8_t>(y, x) == 0) continue;
      x0 = std::min(x0, x);
      x1 = std::max(x1, x);
      y0 = std::min(y0, y);
      y1 = std::max(y1, y);
    }
  }
  if (x1 < 0) return box;
  box.visible = true;
  box.w = x1 + 1 - x0;
  box.h = y1 + 1 - y0;
  box.cx = x0 + 0.5 * box.w;
  box.cy = y0 + 0.5 * box.h;
  return box;
}

/// Largest difference between the edges (left, right, top, bottom) of two boxes, pixels.
inline double edge_error(const RenderedBox& a, const RenderedBox& b) {
  return std::max({std::abs((a.cx - a.w / 2) - (b.cx - b.w / 2)), std::abs((a.cx + a.w / 2) - (b.cx + b.w / 2)),
                   std::abs((a.cy - a.h / 2) - (b.cy - b.h / 2)), std::abs((a.cy + a.h / 2) - (b.cy + b.h / 2))});
}

/// Options for pixel-exact tests: a uniform white background, unlit surfaces, no noise.
inline RenderOptions flat_options() {
  RenderOptions o;
  o.background = "uniform";
  o.background_colour = {1.0, 1.0, 1.0};
  o.shading = "flat";
  o.noise_std = 0.0;
  o.shot_noise = 0.0;
  return o;
}

}  // namespace wingman::sim::test
