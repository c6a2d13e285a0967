// SPDX-License-Identifier: MIT
// The forward model: the exact bounding box of a sphere's image through a calibrated camera (distortion included).
#pragma once

#include "wingman/geometry/camera_model.hpp"
#include "wingman/geometry/pixel_box.hpp"

#include <Eigen/Core>

#include <string>

namespace wingman::geometry {

/// The bounding box of a sphere's image: the extremes in u and v of the projected silhouette (the tangent cone
/// from the camera centre), in calibration pixel coordinates (see CameraModel).
struct SphereImageBox {
  bool valid = false;  ///< false: the sphere contains the camera or reaches behind it (see reason)
  std::string reason;  ///< why not valid
  double u_min = 0, u_max = 0, v_min = 0, v_max = 0;  ///< calibration pixels
  /// Unit rays (camera optical frame) of the silhouette points that touch the box: left, right, top, bottom.
  Eigen::Vector3d tangent_ray_in_cam[4];

  /// The box in PixelBox coordinates (origin at the top-left pixel's corner), not clipped to the image.
  PixelBox pixel_box() const;
};

/// Projects the sphere of radius `radius_m` centred at `p_centre_in_cam` (metres, camera optical frame) and
/// returns the exact bounding box of its image with the camera's distortion applied. The silhouette is the circle
/// of rays d(phi) = cos(beta) c_hat + sin(beta) (cos(phi) e1 + sin(phi) e2), sin(beta) = r / |c|; each extreme
/// is found by sampling phi coarsely, then golden-section search (|d phi| < 1e-9 rad).
/// Precondition for a valid result: |c| > r and every silhouette ray in front of the camera with at least
/// `min_ray_z` (z of the unit ray; 0.02 = 88.9 degrees off-axis).
SphereImageBox project_sphere(const CameraModel& camera, const Eigen::Vector3d& p_centre_in_cam, double radius_m,
                              double min_ray_z = 0.02);

}  // namespace wingman::geometry
