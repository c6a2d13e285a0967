// SPDX-License-Identifier: MIT
// Builds DroneModel geometry from primitives with flat normals.
#include "mesh_builder.hpp"

#include <cmath>

namespace wingman::sim::detail {

void MeshBuilder::triangle(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                           const Eigen::Vector4f& colour, int part) {
  Eigen::Vector3d n = (p1 - p0).cross(p2 - p0);
  const double len = n.norm();
  if (len <= 0.0) return;  // degenerate
  n /= len;
  auto& list = colour.w() < 1.0f ? translucent_ : opaque_;
  for (const Eigen::Vector3d* p : {&p0, &p1, &p2}) {
    list.push_back(static_cast<uint32_t>(vertices_.size()));
    vertices_.push_back(DroneVertex{p->cast<float>(), n.cast<float>(), colour, part});
  }
}

void MeshBuilder::quad(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                       const Eigen::Vector3d& p3, const Eigen::Vector4f& colour, int part) {
  triangle(p0, p1, p2, colour, part);
  triangle(p0, p2, p3, colour, part);
}

void MeshBuilder::box(const Eigen::Isometry3d& T, const Eigen::Vector3d& h, const Eigen::Vector4f& colour, int part) {
  const auto c = [&](double sx, double sy, double sz) -> Eigen::Vector3d {
    return T * Eigen::Vector3d(sx * h.x(), sy * h.y(), sz * h.z());
  };
  quad(c(1, -1, -1), c(1, 1, -1), c(1, 1, 1), c(1, -1, 1), colour, part);      // +x
  quad(c(-1, 1, -1), c(-1, -1, -1), c(-1, -1, 1), c(-1, 1, 1), colour, part);  // -x
  quad(c(1, 1, -1), c(-1, 1, -1), c(-1, 1, 1), c(1, 1, 1), colour, part);      // +y
  quad(c(-1, -1, -1), c(1, -1, -1), c(1, -1, 1), c(-1, -1, 1), colour, part);  // -y
  quad(c(-1, -1, 1), c(1, -1, 1), c(1, 1, 1), c(-1, 1, 1), colour, part);      // +z
  quad(c(-1, 1, -1), c(1, 1, -1), c(1, -1, -1), c(-1, -1, -1), colour, part);  // -z
}

void MeshBuilder::cylinder(const Eigen::Isometry3d& T, double radius, double z0, double z1, int segments,
                           const Eigen::Vector4f& colour, int part) {
  std::vector<Eigen::Vector2d> polygon;
  for (int k = 0; k < segments; ++k) {
    const double a = 2.0 * M_PI * k / segments;
    polygon.emplace_back(radius * std::cos(a), radius * std::sin(a));
  }
  prism(T, polygon, z0, z1, colour, part);
}

void MeshBuilder::prism(const Eigen::Isometry3d& T, const std::vector<Eigen::Vector2d>& polygon, double z0, double z1,
                        const Eigen::Vector4f& colour, int part) {
  const size_t n = polygon.size();
  const auto at = [&](size_t k, double z) -> Eigen::Vector3d {
    return T * Eigen::Vector3d(polygon[k % n].x(), polygon[k % n].y(), z);
  };
  for (size_t k = 0; k < n; ++k) quad(at(k, z0), at(k + 1, z0), at(k + 1, z1), at(k, z1), colour, part);
  for (size_t k = 1; k + 1 < n; ++k) {
    triangle(at(0, z1), at(k, z1), at(k + 1, z1), colour, part);  // top, facing +z
    triangle(at(0, z0), at(k + 1, z0), at(k, z0), colour, part);  // bottom, facing -z
  }
}

DroneModel MeshBuilder::build(std::vector<Propeller> propellers, std::string name) const {
  std::vector<uint32_t> indices = opaque_;
  indices.insert(indices.end(), translucent_.begin(), translucent_.end());
  return DroneModel(vertices_, std::move(indices), opaque_.size(), std::move(propellers), std::move(name));
}

}  // namespace wingman::sim::detail
