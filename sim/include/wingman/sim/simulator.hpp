// SPDX-License-Identifier: MIT
// The simulator: steps a scenario frame by frame, flies the vehicles, and yields the camera vehicle's pose, the
// ground truth and the image of each frame; accepts setpoints for the camera vehicle.
#pragma once

#include "wingman/sim/drone_model.hpp"
#include "wingman/sim/frame_clock.hpp"
#include "wingman/sim/motion_script.hpp"
#include "wingman/sim/multirotor.hpp"
#include "wingman/sim/own_pose_error.hpp"
#include "wingman/sim/scenario.hpp"
#include "wingman/sim/truth_box.hpp"

#include <wingman/geometry/camera_model.hpp>
#include <wingman/geometry/extrinsics.hpp>
#include <wingman/ground_truth_t.hpp>
#include <wingman/image_t.hpp>
#include <wingman/own_pose_t.hpp>
#include <wingman/setpoint_t.hpp>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <vector>

namespace wingman::sim {

class Renderer;

/// An onboard camera of the camera vehicle (id 0).
struct SimCamera {
  geometry::CameraModel model;  ///< intrinsics and distortion, for the image size the simulator renders
  geometry::Extrinsics mount;   ///< camera optical frame -> body (FLU); the camera tilts with the body
  double rate_hz = 30.0;        ///< frames per simulated second
  int32_t camera_id = 0;        ///< copied into images, truth boxes and detections
  /// When this camera exposes after its frame's time t_k, seconds, in [0, 1 / rate_hz): cameras that are not
  /// triggered together (each its own exposure utime). 0 = at t_k.
  double exposure_offset_s = 0.0;
};

/// What one camera saw of a frame.
struct SimCameraFrame {
  int32_t camera_id = 0;  ///< SimCamera::camera_id
  int64_t utime = 0;      ///< its exposure: t_k + its exposure_offset_s, microseconds since epoch
  cv::Mat bgr;            ///< the rendered image (CV_8UC3); empty when rendering is off
  Eigen::Isometry3d T_cam_to_world = Eigen::Isometry3d::Identity();  ///< the camera at its exposure (optical -> ENU)
};

/// The cameras of a frame that expose after t_k (SimCamera::exposure_offset_s > 0), one per exposure time: what
/// the vehicle reports and every vehicle's truth at that time, with those cameras' boxes.
struct SimExposure {
  int64_t utime = 0;                   ///< t_k + the offset, microseconds since epoch
  wingman::own_pose_t own_pose{};      ///< the camera vehicle's reported pose at utime
  MultirotorState own_reported;        ///< the same as a state
  wingman::ground_truth_t truth;       ///< every vehicle at utime; the boxes of the cameras exposed then
  std::vector<size_t> camera_indices;  ///< into SimFrame::cameras
};

/// One simulated camera frame: the cameras exposed at t_k (by default all), and those that expose after it.
struct SimFrame {
  int64_t index = 0;  ///< frame number k (the image's seq)
  int64_t utime = 0;  ///< exposure time t_k = start_utime + round(k * 1e6 / rate), microseconds since epoch
  wingman::own_pose_t own_pose{};  ///< the camera vehicle's reported body pose at t_k (ENU world, FLU body)
  MultirotorState own_reported;    ///< the same as a state (the pose error applied), for the MAVLink telemetry
  /// Every vehicle at t_k and every target's box in every camera exposed at t_k (truth_box_t.camera_id; the first
  /// camera's boxes first, in the order of the vehicles, then the second's, ...); image_seq -1 without images.
  wingman::ground_truth_t truth;
  cv::Mat bgr;  ///< the first camera's rendered image (CV_8UC3, = cameras[0].bgr); empty when rendering is off
  Eigen::Isometry3d T_cam_to_world = Eigen::Isometry3d::Identity();  ///< the first camera at its exposure
  std::vector<SimCameraFrame> cameras;                               ///< one per camera, in the simulator's order
  /// The cameras exposed after t_k, by exposure time (empty when every camera exposes at t_k).
  std::vector<SimExposure> later;
};

/// Counts of what happened to setpoints (the process reports them in its status).
struct SetpointCounts {
  int64_t queued = 0;   ///< applied at utime + command delay
  int64_t late = 0;     ///< utime + delay had already passed in simulated time: applied at once
  int64_t ignored = 0;  ///< the camera vehicle is scripted (takes no setpoints)
};

/// Steps a scenario. Deterministic: the same scenario, camera and setpoints (with the same utimes) give the same
/// frames, bit for bit (images too: the renderer is seeded per frame from Scenario::seed and the frame number).
///
/// Time: frame k is at t_k (FrameClock). step() integrates every vehicle from t_(k-1) to t_k: setpoint-controlled
/// and scripted vehicles with their multirotor dynamics (equal steps of at most dynamics.step_s, split at the times
/// setpoints take effect), kinematic scripts (teleport steps) placed exactly. The camera vehicle (id 0) hovers at
/// its initial pose until its first setpoint takes effect.
class Simulator {
 public:
  /// `renderer`: draws the images (not owned; must outlive the simulator), or nullptr: no images, and the truth
  /// boxes are projected from the drone models (TruthBoxProjector: no occlusion). Throws std::invalid_argument
  /// naming the problem (a vehicle's motion or dynamics invalid, a scenario that never ends), std::runtime_error
  /// when a drone mesh cannot be loaded.
  Simulator(Scenario scenario, SimCamera camera, Renderer* renderer = nullptr);
  /// Several cameras on the camera vehicle (a rig), each exposed at its frame's time plus its exposure_offset_s
  /// from the vehicle's pose then, through its own mount and lens. `renderers`: one per camera, in the same order
  /// (renderers[i] draws cameras[i]; not owned), or empty: no images. Frame k's sensor noise and exposure jitter are
  /// seeded per camera: the first camera with the seed a single camera has (so a rig's first camera gives that camera's
  /// images), camera i > 0 with a seed mixed from it and i. Throws std::invalid_argument, besides the above, for no
  /// camera, more than 8, two with the same camera_id, cameras with different rate_hz, an exposure_offset_s outside [0,
  /// frame period), or renderers that do not match the cameras one for one.
  Simulator(Scenario scenario, std::vector<SimCamera> cameras, std::vector<Renderer*> renderers);
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  const Scenario& scenario() const { return scenario_; }
  /// The first camera (the only one of the single-camera constructor).
  const SimCamera& camera() const { return cameras_.front(); }
  const std::vector<SimCamera>& cameras() const { return cameras_; }
  const FrameClock& clock() const { return clock_; }
  /// Frames in the scenario: those with t_k < start_utime + duration_s (or before the last script ends).
  int64_t frame_count() const { return frame_count_; }
  /// Number of the frame the next step() yields.
  int64_t next_index() const { return next_index_; }
  bool done() const { return next_index_ >= frame_count_; }
  /// Simulated time the vehicles are at, microseconds since epoch.
  int64_t now_utime() const { return now_utime_; }
  /// True when the camera vehicle takes setpoints (control: setpoints).
  bool takes_setpoints() const;

  /// Advances to the next frame's time and returns the frame; with cameras that expose later, on to the last of
  /// their exposures (now_utime()). Precondition: !done() (std::logic_error otherwise).
  SimFrame step();

  /// The error of the reported own pose from now on (SimFrame::own_pose, own_reported); none by default.
  /// Throws std::invalid_argument listing options.validate() problems.
  void set_own_pose_error(const OwnPoseErrorOptions& options);

  /// A setpoint for the camera vehicle: it takes effect at setpoint.utime + command_delay_s, or at once when that
  /// time has passed (counted as late). Setpoints taking effect at the same time apply in arrival order.
  /// Precondition: the message passed validate_message() (std::invalid_argument otherwise).
  void on_setpoint(const wingman::setpoint_t& setpoint);
  const SetpointCounts& setpoint_counts() const { return setpoint_counts_; }

  /// State of vehicle `id` at now_utime(). Throws std::out_of_range for an unknown id.
  const MultirotorState& vehicle_state(int id) const;
  /// Body-to-world transform of a state (FLU body -> ENU world).
  static Eigen::Isometry3d body_to_world(const MultirotorState& state);

 private:
  struct Vehicle;
  void advance_to(int64_t utime);
  void integrate(Vehicle& v, int64_t from_utime, int64_t to_utime);
  void apply_due_setpoints();
  /// At now_utime(): the reported own pose and every vehicle's truth; the cameras `indices` rendered (or projected)
  /// into `views` and their boxes into `truth`. `frame_index` seeds the images.
  void expose(int64_t frame_index, const std::vector<size_t>& indices, wingman::own_pose_t& own_pose,
              MultirotorState& own_reported, wingman::ground_truth_t& truth, std::vector<SimCameraFrame>& views);

  Scenario scenario_;
  std::vector<SimCamera> cameras_;
  std::vector<Renderer*> renderers_;  ///< one per camera, or empty (no images)
  FrameClock clock_;
  std::vector<TruthBoxProjector> projectors_;       ///< one per camera (the boxes without rendering)
  std::vector<std::unique_ptr<Vehicle>> vehicles_;  ///< scenario order
  Vehicle* camera_vehicle_ = nullptr;
  int64_t frame_count_ = 0;
  int64_t next_index_ = 0;
  int64_t now_utime_ = 0;
  int64_t command_delay_us_ = 0;
  std::multimap<int64_t, VehicleCommand> pending_;  ///< setpoint commands by the utime they take effect
  SetpointCounts setpoint_counts_;
  std::optional<OwnPoseError> own_pose_error_;
};

/// The image message of a rendered frame: BGR8, stride = 3 * width, as wingman-camera-driver publishes.
/// Precondition: bgr is CV_8UC3 (std::invalid_argument otherwise).
wingman::image_t to_image_message(const cv::Mat& bgr, int64_t utime, int64_t seq, int32_t camera_id);

}  // namespace wingman::sim
