// SPDX-License-Identifier: MIT
// Ground-truth boxes: a drone's exact projected bounding box in a calibrated camera image.
#pragma once

#include "wingman/sim/drone_model.hpp"

#include <wingman/geometry/camera_model.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

namespace wingman::sim {

/// A drone's box in one camera image, in the detections_t convention: pixels, origin at the top-left CORNER of
/// the top-left pixel (u_box = u_camera + 0.5), so a box spans [cx - w/2, cx + w/2] x [cy - h/2, cy + h/2].
struct RenderedBox {
  int vehicle_id = 0;
  double cx = 0.0, cy = 0.0, w = 0.0, h = 0.0;  ///< tight box of the part of the drone's projection in the image
  /// In front of the camera, overlapping the image, and (when rendered) seen at one pixel centre at least.
  bool visible = false;
  bool truncated = false;  ///< part of the drone is outside the image (the box bounds the part inside)
  double range_m = 0.0;    ///< distance from the camera centre to the body origin, metres
  /// Pixels whose centre sees this drone (nearer drones occlude it); -1 when not rendered.
  int visible_pixels = -1;
};

/// Projects drones through one calibrated camera and returns their exact boxes.
///
/// A point is in the field of view when it is in front of the camera, at most max_half_fov_deg off the optical
/// axis, and inside the region where the lens distortion is one-to-one (a radtan polynomial folds back beyond some
/// radius: points there would otherwise project into the image by mistake). A vertex outside the field of view
/// stands for the point where its direction leaves it, which lies beyond the image border for any usable
/// calibration, so the box reaches the border on that side and is clipped there.
class TruthBoxProjector {
 public:
  /// Precondition: 0 < max_half_fov_deg < 90 (std::invalid_argument otherwise).
  explicit TruthBoxProjector(const geometry::CameraModel& camera, double max_half_fov_deg = 80.0);

  /// The tight box of the drone's projection in the image: its vertices (propellers at `prop_angle_rad`) projected
  /// with CameraModel::project (distortion applied); where the drone is cut by the image border, its triangles
  /// (straight-edged between projected vertices) clipped to the image, so the box bounds only what is inside.
  /// visible: the box has positive area and a vertex is in the field of view; truncated: some of the drone is
  /// outside the image; visible_pixels = -1. T_cam_to_world: optical frame to world; T_body_to_world: FLU body to
  /// world; metres.
  RenderedBox project(const DroneModel& model, const Eigen::Isometry3d& T_cam_to_world,
                      const Eigen::Isometry3d& T_body_to_world, double prop_angle_rad, int vehicle_id = 0) const;

  /// Whether a point in the camera optical frame (metres) is in the field of view (see the class comment).
  bool in_field_of_view(const Eigen::Vector3d& p_in_cam) const;

  /// Largest normalized radius |(x, y)| in the field of view in the direction atan2(y, x) of `xy`.
  double max_normalized_radius(const Eigen::Vector2d& xy) const;

  const geometry::CameraModel& camera() const { return camera_; }

 private:
  geometry::CameraModel camera_;
  double max_half_fov_deg_;
  std::vector<double> r_max_;  // max normalized radius per direction, kDirections entries over [0, 2 pi)
};

}  // namespace wingman::sim
