// SPDX-License-Identifier: MIT
// Messages of a simple scene for localizer tests: a pinhole camera looking east from an observer at the origin with an
// identity ENU pose (the default extrinsics), and the exact image boxes of spheres in front of it.
#pragma once

#include <wingman/detections_t.hpp>
#include <wingman/own_pose_t.hpp>

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace wingman::localizer::testing {

/// The pinhole (focal length f, principal point cx, cy, pixels) and the sphere radius (m) of a scene.
struct SphereScene {
  double f = 640, cx = 640, cy = 360, radius = 0.348;  ///< the process's built-in pinhole, the default radius

  /// The exact box of the sphere at `p_world` (ENU, m): camera x = -north, y = -up, z = east. Confidence 0.9, drone
  /// score 0.9 for class 0 and 0.05 for the others.
  wingman::detection_t sphere_box(const Eigen::Vector3d& p_world, int16_t class_id = 0) const {
    const double X = -p_world.y(), Y = -p_world.z(), Z = p_world.x();
    auto edges = [this](double a, double z) {  // tangent lines from the origin to a circle (a, z) of the radius
      const double centre = std::atan2(a, z), half = std::asin(radius / std::hypot(a, z));
      return std::make_pair(std::tan(centre - half), std::tan(centre + half));
    };
    const auto [xl, xr] = edges(X, Z);
    const auto [yt, yb] = edges(Y, Z);
    wingman::detection_t d{};
    d.cx = static_cast<float>(cx + f * 0.5 * (xl + xr));
    d.cy = static_cast<float>(cy + f * 0.5 * (yt + yb));
    d.w = static_cast<float>(f * (xr - xl));
    d.h = static_cast<float>(f * (yb - yt));
    d.confidence = 0.9f;
    d.class_id = class_id;
    d.drone_score = class_id == 0 ? 0.9f : 0.05f;
    return d;
  }
};

/// A detections_t of a 1280 x 720 image. The boxes are the exact sphere boxes: SOURCE_GROUND_TRUTH (the
/// localizer takes them as the sphere's, whatever target.box_relation says).
inline wingman::detections_t detections(int64_t utime, int64_t seq, std::vector<wingman::detection_t> boxes,
                                        int camera = 0) {
  wingman::detections_t m{};
  m.source = wingman::detections_t::SOURCE_GROUND_TRUTH;
  m.utime = utime;
  m.seq = seq;
  m.camera_id = camera;
  m.image_width = 1280;
  m.image_height = 720;
  m.detections = std::move(boxes);
  m.num_detections = static_cast<int32_t>(m.detections.size());
  return m;
}

/// The observer at the origin, unrotated, in ENU.
inline wingman::own_pose_t own_pose(int64_t utime) {
  wingman::own_pose_t p{};
  p.utime = utime;
  p.frame = wingman::own_pose_t::FRAME_ENU;
  p.q_body_to_world[0] = 1.0;
  return p;
}

}  // namespace wingman::localizer::testing
