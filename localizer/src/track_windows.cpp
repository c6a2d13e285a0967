// SPDX-License-Identifier: MIT
// Tracker-driven windows: a track's predicted box in the next image.
#include "wingman/localizer/track_windows.hpp"

#include <wingman/geometry/sphere_projection.hpp>

#include <Eigen/Eigenvalues>
#include <wingman/common/config.hpp>

#include <algorithm>
#include <cmath>

namespace wingman::localizer {

std::vector<std::string> TrackWindowOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (channel.empty()) p.push_back(problem("windows.channel", channel, "must not be empty"));
  if (max_windows < 1) p.push_back(problem("windows.max_windows", max_windows, "must be >= 1"));
  return p;
}

std::optional<wingman::track_window_t> predict_track_window(const TrackOutput& track, double radius_m,
                                                            const geometry::CameraModel& camera,
                                                            const CameraAtExposure& cam, const BoxRelation& relation) {
  const Eigen::Matrix3d R_world_to_cam = cam.R_cam_to_world.transpose();
  const Eigen::Vector3d p_target_in_cam = R_world_to_cam * (track.p_target_in_world - cam.p_cam_in_world);
  const double radius = track.size_scale * radius_m;
  const geometry::SphereImageBox sphere = geometry::project_sphere(camera, p_target_in_cam, radius);
  if (!sphere.valid) return std::nullopt;
  const geometry::PixelBox sphere_box = sphere.pixel_box();
  // The detector's box for this sphere: its ratios depend on the model box itself, reached in two steps.
  double w = sphere_box.w, h = sphere_box.h;
  for (int step = 0; step < 2; ++step) {
    const BoxScale s = relation.at(w, h, camera.width());
    w = sphere_box.w * s.width_ratio;
    h = sphere_box.h * s.height_ratio;
  }
  if (sphere_box.cx + 0.5 * w < 0 || sphere_box.cx - 0.5 * w > camera.width() || sphere_box.cy + 0.5 * h < 0 ||
      sphere_box.cy - 0.5 * h > camera.height())
    return std::nullopt;

  constexpr double kVelocityStep_s = 0.1;
  const Eigen::Vector3d p_later_in_cam =
      R_world_to_cam * (track.p_target_in_world + kVelocityStep_s * track.v_target_in_world -
                        (cam.p_cam_in_world + kVelocityStep_s * cam.v_cam_in_world));
  Eigen::Vector2d v_px = Eigen::Vector2d::Zero();
  if (p_later_in_cam.z() > 1e-3)
    v_px = (camera.project(p_later_in_cam) - camera.project(p_target_in_cam)) / kVelocityStep_s;

  const double z = p_target_in_cam.z();
  Eigen::Matrix<double, 2, 3> J;
  J << camera.fx() / z, 0, -camera.fx() * p_target_in_cam.x() / (z * z),  //
      0, camera.fy() / z, -camera.fy() * p_target_in_cam.y() / (z * z);
  const Eigen::Matrix3d cov_in_cam = R_world_to_cam * track.cov_p * cam.R_cam_to_world;
  const Eigen::Matrix2d S = J * cov_in_cam * J.transpose();
  const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(0.5 * (S + S.transpose())).eigenvalues()(1);

  wingman::track_window_t out{};
  out.track_id = track.track_id;
  out.confirmed = track.confirmed;
  out.cx = static_cast<float>(sphere_box.cx);
  out.cy = static_cast<float>(sphere_box.cy);
  out.vx = static_cast<float>(v_px.x());
  out.vy = static_cast<float>(v_px.y());
  out.w = static_cast<float>(w);
  out.h = static_cast<float>(h);
  out.sigma_px = static_cast<float>(std::sqrt(std::max(0.0, largest)));
  out.range_m = static_cast<float>(p_target_in_cam.norm());
  out.confidence = static_cast<float>(std::clamp(track.confidence, 0.0, 1.0));
  if (!std::isfinite(out.cx) || !std::isfinite(out.cy) || !std::isfinite(out.vx) || !std::isfinite(out.vy) ||
      !std::isfinite(out.sigma_px) || !(out.w > 0) || !(out.h > 0))
    return std::nullopt;
  return out;
}

}  // namespace wingman::localizer
