// SPDX-License-Identifier: MIT
// Tracker-driven windows (issue 31): where each track will be in a camera's image at its next exposure.
#pragma once

#include <wingman/geometry/camera_model.hpp>
#include "wingman/localizer/box_relation.hpp"
#include "wingman/localizer/tracker.hpp"

#include <Eigen/Core>
#include <wingman/track_window_t.hpp>

#include <optional>
#include <string>
#include <vector>

namespace wingman::localizer {

/// Options of the windows the localizer publishes (keys `windows.*` of config/localizer.yaml).
struct TrackWindowOptions {
  /// Publish, after every detections_t with a fresh own pose, where each track (tentative and confirmed) will be in
  /// the camera's next image (track_windows_t), for wingman-detector's windows.* (docs/detector.md).
  bool publish = false;
  std::string channel = "WINDOWS_CAM0";  ///< track_windows_t output channel
  int max_windows = 8;                   ///< windows per message at most (confirmed tracks first), >= 1

  template <class V>
  void visit(V& v) {
    v("windows.publish", publish,
      "publish where each track will be in the camera's next image (track_windows_t) for the detector's windows");
    v("windows.channel", channel, "track_windows_t output channel");
    v("windows.max_windows", max_windows, "windows per message at most, confirmed tracks first (>= 1)");
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
};

/// The camera at the predicted exposure: its pose in the world frame and its velocity.
struct CameraAtExposure {
  Eigen::Matrix3d R_cam_to_world = Eigen::Matrix3d::Identity();  ///< rotates camera-frame vectors into world
  Eigen::Vector3d p_cam_in_world = Eigen::Vector3d::Zero();      ///< optical centre, world frame, m
  Eigen::Vector3d v_cam_in_world = Eigen::Vector3d::Zero();      ///< optical centre's velocity, world frame, m/s
};

/// One track predicted into the image (`track` from Tracker::predicted_tracks() at the exposure time):
/// - box: centred on the box of the sphere of radius track.size_scale x `radius_m` there (project_sphere(), distortion
/// applied, PixelBox
///   coordinates), its size times `relation`'s
///   ratios (the detector's box for that sphere: the ratios are looked up at the model box itself, by two fixed-point
///   steps from the sphere box); the sphere relation keeps the sphere box;
/// - image velocity: the centre's motion over the next 0.1 s with the track's and the camera's velocities
///   (rotation held), pixels/s;
/// - sigma_px: the square root of the largest eigenvalue of J cov_p J^T, J the pinhole Jacobian (fx, fy) at the
///   centre, cov_p rotated into the camera frame.
/// nullopt when the sphere does not lie in front of the camera (project_sphere() invalid) or its box lies wholly
/// outside the image.
std::optional<wingman::track_window_t> predict_track_window(const TrackOutput& track, double radius_m,
                                                            const geometry::CameraModel& camera,
                                                            const CameraAtExposure& cam, const BoxRelation& relation);

}  // namespace wingman::localizer
