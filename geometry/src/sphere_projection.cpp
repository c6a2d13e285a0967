// SPDX-License-Identifier: MIT
// project_sphere(): coarse sampling of the silhouette circle, then golden-section search per extreme.
#include "wingman/geometry/sphere_projection.hpp"

#include <fmt/format.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>

namespace wingman::geometry {

PixelBox SphereImageBox::pixel_box() const {
  PixelBox b;
  b.cx = 0.5 * (u_min + u_max) + kBoxToCameraPixel;
  b.cy = 0.5 * (v_min + v_max) + kBoxToCameraPixel;
  b.w = u_max - u_min;
  b.h = v_max - v_min;
  return b;
}

namespace {

constexpr int kSamples = 48;

struct Cone {
  Eigen::Vector3d axis, e1, e2;
  double cos_beta, sin_beta;
  Eigen::Vector3d ray(double phi) const {
    return cos_beta * axis + sin_beta * (std::cos(phi) * e1 + std::sin(phi) * e2);
  }
};

}  // namespace

SphereImageBox project_sphere(const CameraModel& camera, const Eigen::Vector3d& p_centre_in_cam, double radius_m,
                              double min_ray_z) {
  SphereImageBox out;
  const double distance = p_centre_in_cam.norm();
  if (!(radius_m > 0) || !(distance > radius_m)) {
    out.reason = fmt::format("the camera is inside the sphere (|c| = {} m, r = {} m)", distance, radius_m);
    return out;
  }
  Cone cone;
  cone.axis = p_centre_in_cam / distance;
  cone.sin_beta = radius_m / distance;
  cone.cos_beta = std::sqrt(1 - cone.sin_beta * cone.sin_beta);
  // The lowest z of a silhouette ray: cos(theta + beta) with theta the axis's angle from the optical axis.
  const double theta = std::acos(std::clamp(cone.axis.z(), -1.0, 1.0));
  if (!(std::cos(theta + std::asin(cone.sin_beta)) >= min_ray_z) || theta + std::asin(cone.sin_beta) >= M_PI / 2) {
    out.reason =
        fmt::format("the sphere reaches behind the camera's field (axis {:.2f} deg off, half-angle {:.2f} deg)",
                    theta * 180 / M_PI, std::asin(cone.sin_beta) * 180 / M_PI);
    return out;
  }
  // e1, e2: an orthonormal basis of the plane normal to the axis.
  const Eigen::Vector3d helper = std::abs(cone.axis.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  cone.e1 = cone.axis.cross(helper).normalized();
  cone.e2 = cone.axis.cross(cone.e1);

  std::array<Eigen::Vector2d, kSamples> uv;
  for (int i = 0; i < kSamples; ++i) uv[i] = camera.project(cone.ray(2 * M_PI * i / kSamples));

  // Extreme k: 0 min u, 1 max u, 2 min v, 3 max v. value(k, uv) is minimised.
  auto value = [](int k, const Eigen::Vector2d& p) {
    switch (k) {
      case 0:
        return p.x();
      case 1:
        return -p.x();
      case 2:
        return p.y();
      default:
        return -p.y();
    }
  };
  double extreme[4];
  for (int k = 0; k < 4; ++k) {
    int best = 0;
    for (int i = 1; i < kSamples; ++i)
      if (value(k, uv[i]) < value(k, uv[best])) best = i;
    const double step = 2 * M_PI / kSamples;
    double a = (best - 1) * step, b = (best + 1) * step;
    const double g = 0.5 * (std::sqrt(5.0) - 1);
    double x1 = b - g * (b - a), x2 = a + g * (b - a);
    double f1 = value(k, camera.project(cone.ray(x1))), f2 = value(k, camera.project(cone.ray(x2)));
    while (b - a > 1e-10) {
      if (f1 < f2) {
        b = x2;
        x2 = x1;
        f2 = f1;
        x1 = b - g * (b - a);
        f1 = value(k, camera.project(cone.ray(x1)));
      } else {
        a = x1;
        x1 = x2;
        f1 = f2;
        x2 = a + g * (b - a);
        f2 = value(k, camera.project(cone.ray(x2)));
      }
    }
    const double phi = 0.5 * (a + b);
    out.tangent_ray_in_cam[k] = cone.ray(phi);
    extreme[k] = std::min({value(k, camera.project(cone.ray(phi))), f1, f2, value(k, uv[best])});
  }
  out.u_min = extreme[0];
  out.u_max = -extreme[1];
  out.v_min = extreme[2];
  out.v_max = -extreme[3];
  out.valid = true;
  return out;
}

}  // namespace wingman::geometry
