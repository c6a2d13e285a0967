// SPDX-License-Identifier: MIT
// Builds DroneModel geometry from primitives (boxes, cylinders, extruded polygons) with flat normals.
#pragma once

#include "wingman/sim/drone_model.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

namespace wingman::sim::detail {

/// Accumulates triangles with flat normals, in the body frame (metres). Opaque and translucent triangles are kept
/// apart so that build() can put the opaque ones first.
class MeshBuilder {
 public:
  /// A triangle p0, p1, p2 with its face normal (counter-clockwise seen from outside).
  void triangle(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                const Eigen::Vector4f& colour, int part);
  /// A planar convex quad p0..p3 (counter-clockwise seen from outside) as two triangles.
  void quad(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2, const Eigen::Vector3d& p3,
            const Eigen::Vector4f& colour, int part);
  /// A box of half sizes `half` (along its own x, y, z), placed by `T_box_to_body`.
  void box(const Eigen::Isometry3d& T_box_to_body, const Eigen::Vector3d& half, const Eigen::Vector4f& colour,
           int part);
  /// A closed cylinder along its own z from z0 to z1, placed by `T_cyl_to_body`.
  void cylinder(const Eigen::Isometry3d& T_cyl_to_body, double radius, double z0, double z1, int segments,
                const Eigen::Vector4f& colour, int part);
  /// A convex polygon (counter-clockwise in its own x-y plane) extruded from z0 to z1, placed by `T_to_body`.
  void prism(const Eigen::Isometry3d& T_to_body, const std::vector<Eigen::Vector2d>& polygon, double z0, double z1,
             const Eigen::Vector4f& colour, int part);

  /// The model: opaque triangles first, then translucent (colour alpha < 1) ones.
  DroneModel build(std::vector<Propeller> propellers, std::string name) const;

 private:
  std::vector<DroneVertex> vertices_;
  std::vector<uint32_t> opaque_;
  std::vector<uint32_t> translucent_;
};

}  // namespace wingman::sim::detail
