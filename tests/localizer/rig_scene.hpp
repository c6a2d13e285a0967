// SPDX-License-Identifier: MIT
// A camera rig's view of spheres for localizer tests: each rig camera's image box of a sphere, the camera on its mount
// on a body at the origin with an identity ENU pose (body x east, y north, z up), cut by the image border as a detector
// would cut it.
#pragma once

#include "wingman/localizer/camera_to_world.hpp"

#include <wingman/detections_t.hpp>
#include <wingman/geometry/calibration.hpp>
#include <wingman/geometry/camera_rig.hpp>
#include <wingman/geometry/sphere_projection.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

namespace wingman::localizer::testing {

/// The rig's cameras as the localizer builds them, and the boxes they see.
struct RigScene {
  explicit RigScene(geometry::CameraRig r, double radius_m = 0.348) : rig(std::move(r)), radius(radius_m) {
    for (const geometry::RigCamera& c : rig.cameras) {
      models.push_back(geometry::make_camera(c.camera));
      mounts.push_back(geometry::Extrinsics::from_options(c.extrinsics));
    }
  }

  /// Camera `i`'s box of the sphere at `p_world` (ENU, m), each edge moved by N(0, noise_px) (when `rng` is given),
  /// then clipped to the image; nullopt when the sphere is behind the camera or its box misses the image.
  std::optional<wingman::detection_t> box(size_t i, const Eigen::Vector3d& p_world, std::mt19937* rng = nullptr,
                                          double noise_px = 0.0) const {
    const CameraPoseInWorld cam = camera_pose_in_world(mounts[i], PoseSample{});
    const Eigen::Vector3d p_in_cam = cam.R_cam_to_world.transpose() * (p_world - cam.p_cam_in_world);
    if (p_in_cam.z() <= radius) return std::nullopt;
    const geometry::SphereImageBox s = geometry::project_sphere(models[i], p_in_cam, radius);
    if (!s.valid) return std::nullopt;
    const geometry::PixelBox b = s.pixel_box();
    double l = b.cx - 0.5 * b.w, r = b.cx + 0.5 * b.w, t = b.cy - 0.5 * b.h, bottom = b.cy + 0.5 * b.h;
    if (rng != nullptr && noise_px > 0) {
      std::normal_distribution<double> n(0.0, noise_px);
      l += n(*rng), r += n(*rng), t += n(*rng), bottom += n(*rng);
    }
    const double w = models[i].width(), h = models[i].height();
    l = std::max(l, 0.0), r = std::min(r, w), t = std::max(t, 0.0), bottom = std::min(bottom, h);
    if (r - l < 2.0 || bottom - t < 2.0) return std::nullopt;
    wingman::detection_t d{};
    d.cx = static_cast<float>(0.5 * (l + r));
    d.cy = static_cast<float>(0.5 * (t + bottom));
    d.w = static_cast<float>(r - l);
    d.h = static_cast<float>(bottom - t);
    d.confidence = 0.9f;
    d.drone_score = 0.9f;
    return d;
  }

  /// Camera `i`'s detections_t at `utime` of the spheres at `targets` (ground-truth boxes: the sphere's).
  wingman::detections_t detections(size_t i, int64_t utime, const std::vector<Eigen::Vector3d>& targets,
                                   std::mt19937* rng = nullptr, double noise_px = 0.0) const {
    wingman::detections_t m{};
    m.source = wingman::detections_t::SOURCE_GROUND_TRUTH;
    m.utime = utime;
    m.camera_id = rig.cameras[i].camera.camera_id;
    m.image_width = models[i].width();
    m.image_height = models[i].height();
    for (const Eigen::Vector3d& p : targets)
      if (auto d = box(i, p, rng, noise_px)) m.detections.push_back(*d);
    m.num_detections = static_cast<int32_t>(m.detections.size());
    return m;
  }

  geometry::CameraRig rig;
  double radius;
  std::vector<geometry::CameraModel> models;
  std::vector<geometry::Extrinsics> mounts;
};

}  // namespace wingman::localizer::testing
