// SPDX-License-Identifier: MIT
// Options of wingman-sim (config/sim.yaml).
#pragma once

#include "wingman/sim/mavlink_vehicle.hpp"
#include "wingman/sim/own_pose_error.hpp"
#include "wingman/sim/render_options.hpp"

#include <wingman/camera_driver/preview.hpp>
#include <wingman/geometry/camera_model_options.hpp>
#include <wingman/geometry/extrinsics.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace wingman::sim {

/// The simulated onboard camera: the camera.* keys every camera-building process shares (geometry::CameraModelOptions,
/// whose defaults are the localizer's built-in camera, so the pipeline works on embedded defaults; camera.camera_id
/// is the id the simulator publishes with) and the frame rate.
struct SimCameraOptions : geometry::CameraModelOptions {
  double rate_hz = 30.0;  ///< frames per simulated second, in (0, 1000]

  template <class V>
  void visit(V& v) {
    geometry::CameraModelOptions::visit(v);
    v("camera.rate_hz", rate_hz, "frames per simulated second");
  }
  /// The shared keys' problems, with width and height bounded by the largest image_t a subscriber accepts
  /// (common::ImageLimits), and rate_hz's.
  std::vector<std::string> validate() const;
};

/// Detections built from ground truth (for the pipeline until a trained detector exists).
struct TruthDetectionOptions {
  /// Publish detections_t from the truth boxes (source = SOURCE_GROUND_TRUTH) on output.detections_channel.
  bool from_ground_truth = false;
  /// silhouette: the truth box (the drone's projected outline, what a detector trained on rendered images boxes);
  /// sphere: the exact box of the drone's bounding sphere (the localizer's model), which isolates the pipeline from
  /// the sphere model's bias on real outlines.
  std::string box = "silhouette";
  double noise_px = 0.0;     ///< standard deviation of Gaussian noise added to each box edge, pixels (0 = exact)
  int64_t seed = 1;          ///< noise seed (with the frame number), >= 0
  double min_size_px = 2.0;  ///< boxes narrower or shorter than this (after noise and clipping) are left out, px
  double max_range_m = 0.0;  ///< drones farther than this are left out, metres (0 = no limit)

  template <class V>
  void visit(V& v) {
    v("detections.from_ground_truth", from_ground_truth,
      "publish detections_t built from the truth boxes (SOURCE_GROUND_TRUTH) until a trained detector exists");
    v("detections.box", box,
      "silhouette (the truth box: the drone's outline) or sphere (the bounding sphere's box, the localizer's model)");
    v("detections.noise_px", noise_px, "Gaussian noise on each box edge, standard deviation in pixels (0 = exact)");
    v("detections.seed", seed, "noise seed (combined with the frame number)");
    v("detections.min_size_px", min_size_px, "leave out boxes narrower or shorter than this, pixels");
    v("detections.max_range_m", max_range_m, "leave out drones farther than this, metres (0 = no limit)");
  }
  std::vector<std::string> validate() const;
};

/// How simulated time advances against the other processes (docs/simulation.md, "Sync").
struct SyncOptions {
  /// lockstep: after each frame wait for a SETPOINT with utime >= the frame's (when the camera vehicle takes
  /// setpoints); free: never wait; realtime: pace frames by the wall clock times `speed`.
  std::string mode = "lockstep";
  double timeout_s = 5.0;  ///< lockstep: longest wall-clock wait for the setpoint of a frame, s (> 0)
  double speed = 1.0;      ///< realtime: simulated seconds per wall-clock second (> 0)
  /// lockstep: at most this many simulated seconds per wall-clock second (frame k is published no earlier than
  /// wall_start + (t_k - t_0) / max_speed), so processes outside the loop (a logger) see a bounded message rate;
  /// 0 = no cap (as fast as the setpoints come back). >= 0.
  double max_speed = 0.0;
  /// Process instance names whose STATUS_<NAME> heartbeat must be seen before the first frame, e.g.
  /// [detector, localizer, follower_ctrl].
  std::vector<std::string> wait_for;
  double startup_timeout_s = 30.0;  ///< longest wall-clock wait for `wait_for`, s (> 0); then exit 1
  /// lockstep with a scripted camera vehicle (which takes no setpoints): still wait for each frame's SETPOINT (the
  /// follower publishes one per targets_t), so that a scripted flight through a live pipeline is deterministic too
  /// (the tracker-driven windows of the next frame come from this frame's tracks). false: nothing to wait for.
  bool scripted_lockstep = false;
  /// lockstep with several cameras rendered: publish the next camera's image only once the detections_t of the one
  /// before (its camera_id and the frame's utime, on its detections channel) has come back, at most timeout_s each, so
  /// that one image at a time is on the bus. Four raw 1280x720 images at once (11 MB) overflow the receive buffers of
  /// the sockets that are busy detecting, and a lost image costs a lockstep timeout. No effect with
  /// detections.from_ground_truth (the simulator publishes those itself), without rendering, or with one camera.
  bool image_by_image = false;

  template <class V>
  void visit(V& v) {
    v("sync.mode", mode, "lockstep (wait for each frame's SETPOINT), free (never wait) or realtime (wall clock)");
    v("sync.timeout_s", timeout_s, "lockstep: longest wall-clock wait for a frame's setpoint, s (then go on)");
    v("sync.speed", speed, "realtime: simulated seconds per wall-clock second");
    v("sync.max_speed", max_speed, "lockstep: at most this many simulated seconds per wall-clock second (0: no cap)");
    v("sync.wait_for", wait_for, "process instances whose STATUS_<NAME> must be seen before the first frame");
    v("sync.startup_timeout_s", startup_timeout_s, "longest wait for sync.wait_for, s (then exit 1 naming them)");
    v("sync.scripted_lockstep", scripted_lockstep,
      "lockstep: wait for each frame's SETPOINT even when the camera vehicle is scripted (deterministic replays)");
    v("sync.image_by_image", image_by_image,
      "lockstep, several cameras: publish a camera's image once the camera before it has its detections back (one "
      "image on the bus at a time)");
  }
  std::vector<std::string> validate() const;
};

/// Options of the simulator process.
struct SimOptions {
  /// Scenario file (config/scenarios/*.yaml); --scenario FILE overrides it. Required to run.
  std::string scenario;
  std::string setpoint_channel = "SETPOINT";           ///< setpoint_t input channel (camera vehicle commands)
  std::string image_channel = "IMAGE_CAM0";            ///< image_t output channel (BGR8)
  std::string own_pose_channel = "OWN_POSE";           ///< own_pose_t output channel (camera vehicle)
  std::string ground_truth_channel = "GROUND_TRUTH";   ///< ground_truth_t output channel
  std::string detections_channel = "DETECTIONS_CAM0";  ///< detections_t output (detections.from_ground_truth)
  /// Who stands in for the camera vehicle's autopilot: lcm (the simulator takes SETPOINT and publishes OWN_POSE
  /// itself) or mavlink (it is a MAVLink vehicle on `mavlink.url`: wingman-mavlink publishes OWN_POSE from its
  /// telemetry and sends it the setpoints; docs/autopilot.md, "Try it against the simulator").
  std::string autopilot = "lcm";
  MavlinkVehicleOptions mavlink;
  /// The error of the camera vehicle's reported pose (OWN_POSE over LCM, the telemetry over MAVLink); the camera
  /// sees from the true pose.
  OwnPoseErrorOptions own_pose_error;
  /// Render and publish images. Off: no image is published, no EGL is needed, and truth boxes are projected from
  /// the drone models (no occlusion).
  bool render = true;
  /// A camera rig file (geometry::load_camera_rig, e.g. config/rigs/surround4.yaml): the simulator renders all its
  /// cameras, which replace camera.* (except camera.rate_hz, the frame rate of them all), extrinsics.*,
  /// output.image_channel and output.detections_channel. "" = the single camera of those keys.
  std::string camera_rig;
  /// Rig cameras not triggered together: the rig's camera i (file order) exposes i x stagger_s after its frame's
  /// time, each with its own image utime, own pose and ground truth, as free-running cameras would. Seconds, >= 0,
  /// (cameras - 1) x stagger_s below the frame period; 0 = every camera at the frame's time. Needs cameras.rig.
  double camera_stagger_s = 0.0;
  SimCameraOptions camera;
  geometry::ExtrinsicsOptions extrinsics;
  TruthDetectionOptions detections;
  SyncOptions sync;
  RenderOptions render_options;
  /// The monitoring preview of the rendered camera, as wingman-camera-driver publishes it (PREVIEW_CAM0, 1 Hz of
  /// simulated time, 320 px JPEG): flight logs keep it (they leave IMAGE_* out), lcm-spy shows it.
  camera_driver::PreviewOptions preview;

  template <class V>
  void visit(V& v) {
    v("scenario.file", scenario, "scenario YAML (config/scenarios/); --scenario FILE overrides it");
    v("input.setpoint_channel", setpoint_channel, "setpoint_t channel from wingman-follower-ctrl");
    v("output.image_channel", image_channel, "image_t channel (BGR8), as wingman-camera-driver publishes");
    v("output.own_pose_channel", own_pose_channel, "own_pose_t channel: the camera vehicle's pose at each frame");
    v("output.ground_truth_channel", ground_truth_channel, "ground_truth_t channel: every vehicle and its box");
    v("output.detections_channel", detections_channel, "detections_t channel for detections.from_ground_truth");
    v("autopilot", autopilot,
      "lcm (take SETPOINT, publish OWN_POSE) or mavlink (a MAVLink vehicle for wingman-mavlink, keys mavlink.*)");
    mavlink.visit(v);
    own_pose_error.visit(v);
    v("cameras.rig", camera_rig,
      "camera rig file (e.g. config/rigs/surround4.yaml): render all its cameras, which replace camera.* (but "
      "camera.rate_hz), extrinsics.*, output.image_channel and output.detections_channel; \"\" = one camera");
    v("cameras.stagger_s", camera_stagger_s,
      "rig: camera i exposes i x this after its frame's time (cameras not triggered together), s; 0 = together");
    camera.visit(v);
    extrinsics.visit(v);
    detections.visit(v);
    sync.visit(v);
    v("render.enabled", render, "render and publish images (false: no images, no EGL; boxes projected from models)");
    render_options.visit(v);
    preview.visit(v);
  }
  std::vector<std::string> validate() const;
};

}  // namespace wingman::sim
