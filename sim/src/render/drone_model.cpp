// SPDX-License-Identifier: MIT
// DroneModel: geometry checks, posing of the propellers, bounding radii.
#include "wingman/sim/drone_model.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <stdexcept>

namespace wingman::sim {
namespace {

std::atomic<uint64_t> g_next_model_id{1};

}  // namespace

DroneModel::DroneModel(std::vector<DroneVertex> vertices, std::vector<uint32_t> indices, size_t opaque_index_count,
                       std::vector<Propeller> propellers, std::string name)
    : vertices_(std::move(vertices)),
      indices_(std::move(indices)),
      opaque_index_count_(opaque_index_count),
      propellers_(std::move(propellers)),
      name_(std::move(name)),
      id_(g_next_model_id.fetch_add(1)) {
  if (indices_.size() % 3 != 0) {
    throw std::invalid_argument(
        fmt::format("DroneModel '{}': {} indices is not a whole number of triangles", name_, indices_.size()));
  }
  if (opaque_index_count_ % 3 != 0 || opaque_index_count_ > indices_.size()) {
    throw std::invalid_argument(
        fmt::format("DroneModel '{}': opaque index count {} must be a multiple of 3 and at "
                    "most the {} indices",
                    name_, opaque_index_count_, indices_.size()));
  }
  if (indices_.empty()) throw std::invalid_argument(fmt::format("DroneModel '{}': no triangles", name_));
  for (uint32_t i : indices_) {
    if (i >= vertices_.size()) {
      throw std::invalid_argument(
          fmt::format("DroneModel '{}': index {} out of range ({} vertices)", name_, i, vertices_.size()));
    }
  }
  if (propellers_.size() > kMaxPropellers) {
    throw std::invalid_argument(fmt::format("DroneModel '{}': {} propellers, at most {} are supported", name_,
                                            propellers_.size(), kMaxPropellers));
  }
  for (const Propeller& prop : propellers_) {
    if (prop.direction != 1 && prop.direction != -1) {
      throw std::invalid_argument(fmt::format("DroneModel '{}': propeller direction must be +1 or -1", name_));
    }
  }
  for (const DroneVertex& v : vertices_) {
    if (v.part < 0 || static_cast<size_t>(v.part) > propellers_.size()) {
      throw std::invalid_argument(
          fmt::format("DroneModel '{}': vertex part {} out of range (0..{})", name_, v.part, propellers_.size()));
    }
    if (!v.p_in_body.allFinite()) throw std::invalid_argument(fmt::format("DroneModel '{}': non-finite vertex", name_));
    const Eigen::Vector3d p = v.p_in_body.cast<double>();
    bounding_radius_at_rest_ = std::max(bounding_radius_at_rest_, p.norm());
    if (v.part == 0) {
      bounding_radius_ = std::max(bounding_radius_, p.norm());
      frame_radius_ = std::max(frame_radius_, p.norm());
    } else {
      // A propeller vertex at rho from its axis (the axis d from the origin) sweeps out to sqrt((d + rho)^2 + z^2).
      const Eigen::Vector2d axis = propellers_[v.part - 1].axis_in_body;
      const double rho = (p.head<2>() - axis).norm();
      const double reach = axis.norm() + rho;
      bounding_radius_ = std::max(bounding_radius_, std::hypot(reach, p.z()));
    }
  }
  // Distinct positions per part, for the truth box (meshes repeat a position once per normal and colour).
  using Key = std::pair<int32_t, std::array<float, 3>>;
  std::vector<Key> keys;
  keys.reserve(vertices_.size());
  for (const DroneVertex& v : vertices_) keys.push_back({v.part, {v.p_in_body.x(), v.p_in_body.y(), v.p_in_body.z()}});
  std::vector<Key> distinct = keys;
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  points_.reserve(distinct.size());
  point_parts_.reserve(distinct.size());
  for (const auto& [part, p] : distinct) {
    points_.emplace_back(p[0], p[1], p[2]);
    point_parts_.push_back(part);
  }
  point_triangles_.reserve(indices_.size());
  for (uint32_t i : indices_) {
    const auto it = std::lower_bound(distinct.begin(), distinct.end(), keys[i]);
    point_triangles_.push_back(static_cast<uint32_t>(it - distinct.begin()));
  }
}

Eigen::Isometry3d DroneModel::part_transform(int part, double prop_angle_rad) const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (part <= 0 || static_cast<size_t>(part) > propellers_.size()) return T;
  const Propeller& prop = propellers_[part - 1];
  const Eigen::Vector3d axis(prop.axis_in_body.x(), prop.axis_in_body.y(), 0.0);
  // p' = axis + Rz(direction * angle) (p - axis)
  T.linear() = Eigen::AngleAxisd(prop.direction * prop_angle_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = axis - T.linear() * axis;
  return T;
}

void DroneModel::posed_points(double prop_angle_rad, std::vector<Eigen::Vector3d>& out) const {
  std::vector<Eigen::Isometry3d> parts(propellers_.size() + 1);
  for (size_t k = 0; k < parts.size(); ++k) parts[k] = part_transform(static_cast<int>(k), prop_angle_rad);
  out.resize(points_.size());
  for (size_t i = 0; i < points_.size(); ++i)
    out[i] = point_parts_[i] == 0 ? points_[i] : parts[point_parts_[i]] * points_[i];
}

DroneModel DroneModel::from_spec(const DroneSpec& spec) {
  return spec.frame == "mesh" ? from_mesh(spec) : procedural(spec);
}

}  // namespace wingman::sim
