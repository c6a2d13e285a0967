// SPDX-License-Identifier: MIT
// detections_t from ground-truth boxes, with optional edge noise.
#include "wingman/sim/truth_detections.hpp"

#include "trapezoid.hpp"

#include <wingman/geometry/message_eigen.hpp>
#include <wingman/geometry/sphere_projection.hpp>

#include <algorithm>

namespace wingman::sim {

namespace {

/// The exact box of vehicle `vehicle_id`'s bounding sphere in the camera (PixelBox convention, not clipped); false
/// when the vehicle is unknown or its sphere reaches behind the camera.
bool sphere_box(const wingman::ground_truth_t& truth, int32_t vehicle_id, const geometry::CameraModel& camera,
                const Eigen::Isometry3d& T_cam_to_world, geometry::PixelBox* box) {
  for (const auto& v : truth.vehicles) {
    if (v.vehicle_id != vehicle_id) continue;
    const Eigen::Vector3d p_in_world = geometry::to_vector3(v.p_body_in_world);
    const geometry::SphereImageBox s =
        geometry::project_sphere(camera, T_cam_to_world.inverse() * p_in_world, v.bounding_radius);
    if (!s.valid) return false;
    *box = s.pixel_box();
    return true;
  }
  return false;
}

}  // namespace

wingman::detections_t truth_detections(const wingman::ground_truth_t& truth, int64_t seq,
                                       const geometry::CameraModel& camera, const Eigen::Isometry3d& T_cam_to_world,
                                       int32_t camera_id, const TruthDetectionOptions& options, int camera_index) {
  const int32_t width = camera.width(), height = camera.height();
  const bool sphere = options.box == "sphere";
  wingman::detections_t d{};
  d.utime = truth.utime;
  d.seq = seq;
  d.camera_id = camera_id;
  d.image_width = width;
  d.image_height = height;
  d.source = wingman::detections_t::SOURCE_GROUND_TRUTH;
  d.inference_latency_us = 0;
  uint64_t noise_seed = detail::mix_seed(static_cast<uint64_t>(options.seed), static_cast<uint64_t>(seq));
  if (camera_index != 0) noise_seed = detail::mix_seed(noise_seed, static_cast<uint64_t>(camera_index));
  detail::PortableRandom noise(noise_seed);
  for (const auto& b : truth.boxes) {
    if (!b.visible || b.camera_id != camera_id) continue;
    if (options.max_range_m > 0 && b.range > options.max_range_m) continue;
    geometry::PixelBox box{b.cx, b.cy, b.w, b.h};
    if (sphere && !sphere_box(truth, b.vehicle_id, camera, T_cam_to_world, &box)) continue;
    double left = box.cx - 0.5 * box.w, right = box.cx + 0.5 * box.w;
    double top = box.cy - 0.5 * box.h, bottom = box.cy + 0.5 * box.h;
    if (options.noise_px > 0) {  // always four draws per box, so one box's noise does not depend on another's
      left += options.noise_px * noise.normal();
      right += options.noise_px * noise.normal();
      top += options.noise_px * noise.normal();
      bottom += options.noise_px * noise.normal();
    }
    left = std::clamp(left, 0.0, static_cast<double>(width));
    right = std::clamp(right, 0.0, static_cast<double>(width));
    top = std::clamp(top, 0.0, static_cast<double>(height));
    bottom = std::clamp(bottom, 0.0, static_cast<double>(height));
    const double w = right - left, h = bottom - top;
    if (!(w >= options.min_size_px && h >= options.min_size_px) || w <= 0 || h <= 0) continue;
    wingman::detection_t det{};
    det.cx = static_cast<float>(0.5 * (left + right));
    det.cy = static_cast<float>(0.5 * (top + bottom));
    det.w = static_cast<float>(w);
    det.h = static_cast<float>(h);
    det.confidence = 1.0f;
    det.class_id = 0;  // every simulated vehicle is a drone
    det.pass_kind = wingman::detection_t::PASS_SINGLE;
    det.drone_score = 1.0f;  // = confidence, as for every class-0 box
    d.detections.push_back(det);
  }
  d.num_detections = static_cast<int32_t>(d.detections.size());
  return d;
}

}  // namespace wingman::sim
