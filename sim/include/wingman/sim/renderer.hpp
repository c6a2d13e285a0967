// SPDX-License-Identifier: MIT
// The simulator's camera: offscreen OpenGL ES (EGL, Mesa llvmpipe) images of drones over a scene, through a
// calibrated lens, with each drone's exact projected box.
#pragma once

#include "wingman/sim/drone_model.hpp"
#include "wingman/sim/render_options.hpp"
#include "wingman/sim/truth_box.hpp"

#include <wingman/geometry/camera_model.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace wingman::sim {

/// One drone in a frame.
struct DroneInstance {
  int vehicle_id = 0;                 ///< copied into RenderedBox::vehicle_id
  const DroneModel* model = nullptr;  ///< not owned; must outlive the render() call
  /// Body (FLU) to world (ENU) at the frame's time (the middle of the exposure), metres.
  Eigen::Isometry3d T_body_to_world = Eigen::Isometry3d::Identity();
  Eigen::Vector3d v_body_in_world = Eigen::Vector3d::Zero();  ///< velocity, m/s (motion blur only)
  Eigen::Vector3d w_body_in_body = Eigen::Vector3d::Zero();   ///< angular velocity, rad/s (motion blur only)
  double prop_angle_rad = 0.0;   ///< propeller angle at the frame's time (each prop turns by direction * angle)
  double prop_rate_rad_s = 0.0;  ///< propeller angular speed, rad/s (motion blur only; ~600 in hover)
};

/// Motion of the camera during the exposure (motion blur only).
struct CameraMotion {
  Eigen::Vector3d v_cam_in_world = Eigen::Vector3d::Zero();  ///< velocity, m/s
  Eigen::Vector3d w_cam_in_cam = Eigen::Vector3d::Zero();    ///< angular velocity in the optical frame, rad/s
};

/// A rendered frame.
struct RenderResult {
  cv::Mat bgr;  ///< CV_8UC3, camera width x height, distortion applied
  /// CV_8UC1, camera width x height: 0 where no drone is seen at the pixel centre, else 1 + the index of the
  /// nearest drone seen there in render()'s `drones` (at the exposure's middle, without motion blur).
  cv::Mat mask;
  std::vector<RenderedBox> boxes;  ///< one per drone, in the order of `drones`
  double exposure_gain = 1.0;      ///< the gain this frame was rendered with (after jitter and drift)
};

/// Renders one calibrated camera. Owns an EGL context (surfaceless, no window system, no X or Wayland; or shares
/// another renderer's) and its GL objects; not copyable. render() may be called from any one thread at a time (it makes
/// its context current). Pixels are deterministic: the same inputs and frame_seed give the same bytes, whatever
/// LP_NUM_THREADS.
///
/// How: the scene is drawn into an ideal pinhole image that covers the camera's whole field of view at
/// supersampling times its pixel density, then remapped to the camera through a per-pixel map computed at
/// construction from CameraModel::undistort_to_normalized (each output pixel averages supersampling^2 samples).
class Renderer {
 public:
  /// Throws std::invalid_argument naming the option (options.validate()), std::runtime_error with one clear line
  /// when no EGL display or OpenGL ES 3 context can be made, or when the camera's field of view exceeds what
  /// can be rendered in one pinhole image (the pixels beyond max_half_fov_deg are then black; only if the whole
  /// central region cannot be covered is it an error).
  Renderer(const geometry::CameraModel& camera, const RenderOptions& options);
  /// The same, for another camera of a rig, in `share_context`'s EGL context instead of a new one: the context (and
  /// the display) is made once for all cameras; the lens map, render targets, shader programs and the GPU copies of
  /// the drone models are this renderer's own. The context lives as long as any renderer that uses it. The renderers
  /// sharing a context must be used from one thread at a time, all of them together. The pixels are those of a
  /// renderer with its own context (tested).
  Renderer(const geometry::CameraModel& camera, const RenderOptions& options, const Renderer& share_context);
  ~Renderer();
  Renderer(Renderer&&) noexcept;
  Renderer& operator=(Renderer&&) noexcept;
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Renders the drones seen from the camera.
  /// T_cam_to_world: camera optical frame (x right, y down, z forward) to world (ENU, z up), metres, at `utime`
  /// (the middle of the exposure). utime: microseconds (drives the exposure drift). frame_seed: sensor noise and
  /// exposure jitter of this frame. Preconditions: every model non-null, at most 254 drones (else
  /// std::invalid_argument).
  RenderResult render(const Eigen::Isometry3d& T_cam_to_world, const std::vector<DroneInstance>& drones, int64_t utime,
                      uint64_t frame_seed, const CameraMotion& camera_motion = {});

  /// Replaces the options (validated; std::invalid_argument naming the option). Scene, lighting and sensor options
  /// take effect at the next render(); a new supersampling or max_half_fov_deg rebuilds the lens map and the
  /// render targets, which costs as much as construction.
  void set_options(const RenderOptions& options);

  const geometry::CameraModel& camera() const;
  const RenderOptions& options() const;
  /// The OpenGL renderer string, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
  std::string gl_renderer() const;
  /// Size of the intermediate pinhole image, pixels (what the scene is drawn at).
  cv::Size pinhole_size() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace wingman::sim
