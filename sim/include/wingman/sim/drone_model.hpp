// SPDX-License-Identifier: MIT
// A drone's triangle mesh in its body frame, with per-vertex colour and propellers tagged so they can spin.
#pragma once

#include "wingman/sim/drone_spec.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <string>
#include <vector>

namespace wingman::sim {

/// The most propellers a DroneModel may have.
inline constexpr size_t kMaxPropellers = 16;

/// One propeller of a DroneModel: it spins about the body z axis through `axis_in_body`.
struct Propeller {
  Eigen::Vector2d axis_in_body = Eigen::Vector2d::Zero();  ///< (x, y) of the spin axis in the body frame, metres
  /// +1: the prop turns counter-clockwise seen from above (positive about body +z) as the prop angle grows; -1:
  /// clockwise.
  int direction = 1;
};

/// A vertex of a DroneModel. Frame: body FLU (x forward, y left, z up), metres.
struct DroneVertex {
  Eigen::Vector3f p_in_body;  ///< position, metres
  Eigen::Vector3f n_in_body;  ///< unit normal (triangles are drawn double-sided)
  Eigen::Vector4f colour;     ///< linear RGB in 0..1 and opacity (1 = opaque)
  /// 0: rigid with the body; k >= 1: belongs to propeller k - 1 (spins with it).
  int32_t part = 0;
};

/// A drone's surface: an indexed triangle mesh in the body frame, opaque triangles first, then translucent ones
/// (prop discs). Immutable once built; share one model between many DroneInstance values.
class DroneModel {
 public:
  /// The procedural multirotor of `spec` (frame quad, hex or octo): body, arms, motors, propellers, landing gear.
  /// Throws std::invalid_argument with spec.validate()'s problems if the spec is invalid or not procedural.
  static DroneModel procedural(const DroneSpec& spec);

  /// Loads spec.mesh_path with assimp (every mesh of every node, node transforms applied, then mesh_scale and
  /// mesh_rpy_deg). Colours come from the materials (base colour, else diffuse; glTF's are linear) times vertex
  /// colours. Parts whose node or mesh name matches spec.mesh_prop_pattern are propellers: each spins about the
  /// vertical axis through the mean of its vertices (its hub), or through spec.mesh_prop_axes_m.
  /// Throws std::runtime_error naming the file and the problem (unreadable, no triangles, too many propellers).
  static DroneModel from_mesh(const DroneSpec& spec);

  /// procedural() or from_mesh() by spec.frame.
  static DroneModel from_spec(const DroneSpec& spec);

  /// Builds a model from raw geometry. Preconditions: every index < vertices.size(), indices.size() % 3 == 0,
  /// at most kMaxPropellers propellers, every vertex part in 0..propellers.size(); `opaque_index_count` indices (a
  /// multiple of 3) come first, the rest are translucent. Throws std::invalid_argument if a precondition is violated.
  DroneModel(std::vector<DroneVertex> vertices, std::vector<uint32_t> indices, size_t opaque_index_count,
             std::vector<Propeller> propellers, std::string name);

  const std::vector<DroneVertex>& vertices() const { return vertices_; }
  /// Triangles as vertex index triples; [0, opaque_index_count()) opaque, the rest translucent.
  const std::vector<uint32_t>& indices() const { return indices_; }
  size_t opaque_index_count() const { return opaque_index_count_; }
  size_t triangle_count() const { return indices_.size() / 3; }
  const std::vector<Propeller>& propellers() const { return propellers_; }
  /// "quad", "hex", "octo" or the mesh file name.
  const std::string& name() const { return name_; }
  /// Identifies this geometry (unique per constructed model; copies share it, as they share the geometry). The
  /// renderer keys its GPU buffers by it.
  uint64_t id() const { return id_; }

  /// Radius of the smallest sphere about the body origin that holds the drone with its propellers at every
  /// angle (r_spin: a propeller vertex at distance rho from its axis, whose axis is d from the origin, sweeps
  /// out to sqrt((d + rho)^2 + z^2)), metres. This is the target radius the localizer needs.
  double bounding_radius() const { return bounding_radius_; }

  /// Largest vertex distance from the body origin with the propellers at rest (angle 0), metres.
  double bounding_radius_at_rest() const { return bounding_radius_at_rest_; }
  /// Radius of the smallest sphere about the body origin that holds the drone without its propellers (the frame:
  /// body, arms, motors, gear; the meshes' README's "r without props"), metres. What a detector sees of a drone whose
  /// spinning propellers are faint discs; at most bounding_radius().
  double frame_radius() const { return frame_radius_; }

  /// The model's distinct vertex positions (duplicates from split normals and colours removed), in the body frame,
  /// with propeller k turned by direction_k * prop_angle_rad about its axis: the points the truth box projects.
  /// `out` is resized to the number of distinct points.
  void posed_points(double prop_angle_rad, std::vector<Eigen::Vector3d>& out) const;

  /// The triangles as index triples into posed_points()' output (all triangles, opaque and translucent).
  const std::vector<uint32_t>& point_triangles() const { return point_triangles_; }

  /// The body-frame transform of part `part` (0: identity; k: propeller k - 1 turned by direction * angle).
  Eigen::Isometry3d part_transform(int part, double prop_angle_rad) const;

 private:
  std::vector<DroneVertex> vertices_;
  std::vector<uint32_t> indices_;
  size_t opaque_index_count_ = 0;
  std::vector<Propeller> propellers_;
  std::string name_;
  uint64_t id_ = 0;
  std::vector<Eigen::Vector3d> points_;    // distinct positions, body frame
  std::vector<int32_t> point_parts_;       // part of each distinct position
  std::vector<uint32_t> point_triangles_;  // indices() mapped to distinct positions
  double bounding_radius_ = 0.0;
  double bounding_radius_at_rest_ = 0.0;
  double frame_radius_ = 0.0;
};

}  // namespace wingman::sim
