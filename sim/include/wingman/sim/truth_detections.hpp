// SPDX-License-Identifier: MIT
// detections_t built from ground-truth boxes (SOURCE_GROUND_TRUTH), for the pipeline until a trained detector exists.
#pragma once

#include "wingman/sim/sim_options.hpp"

#include <wingman/detections_t.hpp>
#include <wingman/geometry/camera_model.hpp>
#include <wingman/ground_truth_t.hpp>

#include <Eigen/Geometry>

#include <cstdint>

namespace wingman::sim {

/// The detections a perfect detector would report for one frame: one detection_t per visible truth box of camera
/// `camera_id` (confidence 1, class 0, drone_score 1, pass_kind PASS_SINGLE), source =
/// detections_t::SOURCE_GROUND_TRUTH, utime and seq of the frame's image (`truth.utime`, `seq`), the camera's image
/// size, inference latency 0. The box is the truth box (options.box silhouette), or (sphere) the exact box of the
/// vehicle's bounding sphere (vehicle_truth_t.bounding_radius about p_body_in_world) seen by `camera` at
/// `T_cam_to_world` (optical frame to world, metres); either way only drones whose truth box is visible are detected.
/// With options.noise_px > 0 each box edge moves by independent Gaussian noise (standard deviation noise_px,
/// seeded by options.seed, `seq` and `camera_index`: 0 for a single camera or a rig's first, i for the rig's camera
/// i, so each camera's noise is its own), then the box is clipped to the image. Boxes narrower or shorter than
/// options.min_size_px, and drones farther than options.max_range_m (when > 0), are left out.
wingman::detections_t truth_detections(const wingman::ground_truth_t& truth, int64_t seq,
                                       const geometry::CameraModel& camera, const Eigen::Isometry3d& T_cam_to_world,
                                       int32_t camera_id, const TruthDetectionOptions& options, int camera_index = 0);

}  // namespace wingman::sim
