// SPDX-License-Identifier: MIT
// TruthBoxProjector: exact projected boxes of drones through a calibrated camera.
#include "wingman/sim/truth_box.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace wingman::sim {
namespace {

constexpr int kDirections = 720;  // directions of the field-of-view table, over [0, 2 pi)

}  // namespace

TruthBoxProjector::TruthBoxProjector(const geometry::CameraModel& camera, double max_half_fov_deg)
    : camera_(camera), max_half_fov_deg_(max_half_fov_deg) {
  if (!(max_half_fov_deg > 0.0 && max_half_fov_deg < 90.0)) {
    throw std::invalid_argument(fmt::format("max_half_fov_deg = {}: must be in (0, 90)", max_half_fov_deg));
  }
  // Per direction, walk outwards in normalized radius while the distorted radius keeps growing: beyond the first
  // point where it stops, the lens model folds back and is not a lens any more.
  const double r_fov = std::tan(max_half_fov_deg * M_PI / 180.0);
  r_max_.resize(kDirections);
  for (int k = 0; k < kDirections; ++k) {
    const double phi = 2.0 * M_PI * k / kDirections;
    const Eigen::Vector2d dir(std::cos(phi), std::sin(phi));
    double r = 0.0, rd = 0.0;
    while (r < r_fov) {
      const double next = std::min(r_fov, r + 2e-3 * std::max(1.0, r));
      const double next_rd = camera_.distort_normalized(next * dir).norm();
      if (!(next_rd > rd)) break;
      r = next;
      rd = next_rd;
    }
    r_max_[k] = r;
  }
}

double TruthBoxProjector::max_normalized_radius(const Eigen::Vector2d& xy) const {
  double f = std::atan2(xy.y(), xy.x()) / (2.0 * M_PI) * kDirections;
  if (f < 0.0) f += kDirections;
  const int k0 = static_cast<int>(std::floor(f)) % kDirections;
  const int k1 = (k0 + 1) % kDirections;
  const double t = f - std::floor(f);
  return (1.0 - t) * r_max_[k0] + t * r_max_[k1];
}

bool TruthBoxProjector::in_field_of_view(const Eigen::Vector3d& p_in_cam) const {
  if (!(p_in_cam.z() > 0.0)) return false;
  const Eigen::Vector2d xy = p_in_cam.head<2>() / p_in_cam.z();
  return xy.norm() <= max_normalized_radius(xy);
}

namespace {

// Clips a convex polygon (n <= 3 vertices in, at most 7 out) to [0, w] x [0, h]; returns the vertex count.
int clip_to_rect(std::array<Eigen::Vector2d, 8>& poly, int n, double w, double h) {
  std::array<Eigen::Vector2d, 8> out;
  for (int edge = 0; edge < 4; ++edge) {
    const int axis = edge / 2;
    const double limit = edge % 2 == 0 ? 0.0 : (axis == 0 ? w : h);
    const auto inside = [&](const Eigen::Vector2d& p) { return edge % 2 == 0 ? p[axis] >= limit : p[axis] <= limit; };
    int m = 0;
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d& a = poly[i];
      const Eigen::Vector2d& b = poly[(i + 1) % n];
      if (inside(a)) out[m++] = a;
      if (inside(a) != inside(b)) {
        const double t = (limit - a[axis]) / (b[axis] - a[axis]);
        out[m++] = a + t * (b - a);
        out[m - 1][axis] = limit;
      }
    }
    n = m;
    poly = out;
    if (n == 0) break;
  }
  return n;
}

}  // namespace

RenderedBox TruthBoxProjector::project(const DroneModel& model, const Eigen::Isometry3d& T_cam_to_world,
                                       const Eigen::Isometry3d& T_body_to_world, double prop_angle_rad,
                                       int vehicle_id) const {
  const Eigen::Isometry3d T_body_to_cam = T_cam_to_world.inverse() * T_body_to_world;
  RenderedBox box;
  box.vehicle_id = vehicle_id;
  box.range_m = T_body_to_cam.translation().norm();

  // Every distinct vertex in box pixels (the calibration's plus 0.5), and whether it is in the field of view.
  enum State : uint8_t { kNoDirection, kOutOfView, kInView };
  std::vector<Eigen::Vector3d> points;
  model.posed_points(prop_angle_rad, points);
  std::vector<Eigen::Vector2d> uv(points.size());
  std::vector<uint8_t> state(points.size());
  const double W = camera_.width(), H = camera_.height();
  const auto in_image = [&](const Eigen::Vector2d& p) {
    return p.x() >= 0.0 && p.x() <= W && p.y() >= 0.0 && p.y() <= H;
  };
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double u0 = kInf, v0 = kInf, u1 = -kInf, v1 = -kInf;
  const auto include = [&](const Eigen::Vector2d& p) {
    u0 = std::min(u0, p.x());
    u1 = std::max(u1, p.x());
    v0 = std::min(v0, p.y());
    v1 = std::max(v1, p.y());
  };
  const Eigen::Vector2d to_box = Eigen::Vector2d::Constant(geometry::kBoxToCameraPixel);
  bool any_in_view = false, any_outside = false;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d p = T_body_to_cam * points[i];
    if (in_field_of_view(p)) {
      uv[i] = camera_.project(p) + to_box;
      state[i] = kInView;
      any_in_view = true;
      if (in_image(uv[i])) {
        include(uv[i]);
      } else {
        any_outside = true;
      }
      continue;
    }
    // Outside the field of view: the point where this direction leaves it (beyond the image border).
    any_outside = true;
    const Eigen::Vector2d xy = p.z() > 0.0 ? Eigen::Vector2d(p.head<2>() / p.z()) : Eigen::Vector2d(p.head<2>());
    const double n = xy.norm();
    state[i] = n < 1e-12 ? kNoDirection : kOutOfView;  // straight behind the camera: no direction
    if (state[i] == kOutOfView) {
      const Eigen::Vector2d edge = xy / n * max_normalized_radius(xy);
      uv[i] = camera_.project(Eigen::Vector3d(edge.x(), edge.y(), 1.0)) + to_box;
    }
  }
  if (!any_in_view) return box;
  // Where the drone is cut by the border, the box is that of the triangles clipped to the image (the box of all
  // vertices clipped to the image would count parts outside the image).
  if (any_outside) {
    const std::vector<uint32_t>& tri = model.point_triangles();
    std::array<Eigen::Vector2d, 8> poly;
    for (size_t t = 0; t + 2 < tri.size(); t += 3) {
      const uint32_t a = tri[t], b = tri[t + 1], c = tri[t + 2];
      const bool all_inside = state[a] == kInView && state[b] == kInView && state[c] == kInView && in_image(uv[a]) &&
                              in_image(uv[b]) && in_image(uv[c]);
      if (all_inside) continue;  // its vertices are in the box already
      if (state[a] != kInView && state[b] != kInView && state[c] != kInView) continue;
      if (state[a] == kNoDirection || state[b] == kNoDirection || state[c] == kNoDirection) continue;
      poly[0] = uv[a];
      poly[1] = uv[b];
      poly[2] = uv[c];
      const int n = clip_to_rect(poly, 3, W, H);
      for (int k = 0; k < n; ++k) include(poly[k]);
    }
  }
  box.truncated = any_outside;
  box.visible = u1 > u0 && v1 > v0;
  if (!box.visible) return box;
  box.cx = 0.5 * (u0 + u1);
  box.cy = 0.5 * (v0 + v1);
  box.w = u1 - u0;
  box.h = v1 - v0;
  return box;
}

}  // namespace wingman::sim
