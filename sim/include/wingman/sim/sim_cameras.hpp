// SPDX-License-Identifier: MIT
// The cameras wingman-sim renders and where each one's messages go: the single camera of camera.*, extrinsics.* and
// output.*, or the cameras of a rig file (cameras.rig).
#pragma once

#include "wingman/sim/sim_options.hpp"
#include "wingman/sim/simulator.hpp"

#include <wingman/geometry/camera_rig.hpp>

#include <string>
#include <vector>

namespace wingman::sim {

/// One camera the simulator renders, with its output channels.
struct SimCameraOutput {
  SimCamera camera;                ///< model, mount, frame rate and camera_id
  std::string image_channel;       ///< image_t channel (output.image_channel or the rig's channels.image)
  std::string detections_channel;  ///< detections_t channel for detections.from_ground_truth
};

/// The rig file of cameras.rig, checked for the simulator: geometry::load_camera_rig's problems, a camera larger
/// than an image_t subscriber accepts (common::ImageLimits), a channel that is also output.own_pose_channel or
/// output.ground_truth_channel. Throws common::ConfigError "cameras.rig: FILE: N problems ...: FILE:LINE:
/// cameras[i].KEY:
/// ...; ..." with every problem at once, on one line.
/// Precondition: options.camera_rig is not empty (std::invalid_argument otherwise).
geometry::CameraRig load_sim_rig(const SimOptions& options);

/// The cameras of `options`: without cameras.rig, the one camera of camera.*, extrinsics.*, output.image_channel and
/// output.detections_channel; with it, the rig file's cameras in file order (each its camera.*, mount and channels;
/// camera.rate_hz from the options for all, camera i exposing i x cameras.stagger_s after the frame's time). Reads
/// calibration files (geometry::make_camera). Throws what load_sim_rig() throws for a bad rig, common::ConfigError
/// naming cameras.stagger_s when the last camera would expose beyond the frame period, and what make_camera throws
/// for an unreadable calibration.
std::vector<SimCameraOutput> sim_cameras(const SimOptions& options);

}  // namespace wingman::sim
