// SPDX-License-Identifier: MIT
// The thesis's 1-D follower: a PID on the horizontal position of the box centre in the image
// (eq. 34-37) commanding the velocity along one horizontal axis, the height held.
#pragma once

#include "wingman/follower_ctrl/height_mode.hpp"
#include "wingman/follower_ctrl/pid.hpp"
#include "wingman/follower_ctrl/velocity_command.hpp"
#include "wingman/follower_ctrl/velocity_limits.hpp"
#include "wingman/follower_ctrl/world_frame.hpp"

#include <wingman/detections_t.hpp>

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace wingman::follower_ctrl {

/// Along which horizontal world axis the 1-D follower moves.
enum class Pid1dAxis {
  kCameraRight,  ///< "camera_right": the camera's x axis (image right) in the world, projected on the horizontal
  kWorld,        ///< "world": pid_1d.world_axis
};

/// "camera_right" or "world"; nullopt for anything else.
std::optional<Pid1dAxis> parse_pid_1d_axis(const std::string& name);

/// Options of the 1-D follower (keys `pid_1d.*`). Defaults: the thesis's gains.
struct Pid1dOptions {
  double kp = 26.0;           ///< K_P, (m/s) per unit of normalised image width (eq. 35)
  double ki = 2.0;            ///< K_I, (m/s) per (unit s) (eq. 36)
  double kd = 2.0;            ///< K_D, (m/s) per (unit / s) (eq. 37)
  double integral_max = 0.1;  ///< e_I,max: clamp of sum(e dt), unit s (so |I| <= K_I e_I,max = 0.2 m/s)
  /// "camera_right" (default: the image's right-hand side, from the own pose and extrinsics.R_cam_to_body,
  /// projected on the horizontal; in the thesis's set-up, camera looking north, that is east = world +X)
  /// or "world" (world_axis).
  std::string axis = "camera_right";
  std::vector<double> world_axis = {1.0, 0.0};  ///< axis "world": horizontal direction ENU [east, north], normalised
  std::string height_mode = "start";            ///< "start" (first own pose) or "fixed" (height_m)
  double height_m = 2.0;                        ///< reference height for height_mode "fixed", world up, m
  double height_kp = 1.0;                       ///< vertical velocity per metre of height error, 1/s

  template <class V>
  void visit(V& v) {
    v("pid_1d.kp", kp, "K_P (eq. 35), (m/s) per normalised image width");
    v("pid_1d.ki", ki, "K_I (eq. 36), (m/s) per (normalised width s)");
    v("pid_1d.kd", kd, "K_D (eq. 37), (m/s) per (normalised width / s)");
    v("pid_1d.integral_max", integral_max, "e_I,max: clamp of the error integral sum(e dt), normalised width s");
    v("pid_1d.axis", axis,
      "direction of motion: camera_right (image right, from own pose and extrinsics, horizontal) or world");
    v("pid_1d.world_axis", world_axis, "axis world: horizontal direction [east, north] (normalised)");
    v("pid_1d.height_mode", height_mode, "height reference: start (first own pose) or fixed (height_m)");
    v("pid_1d.height_m", height_m, "reference height for height_mode fixed, world up, m");
    v("pid_1d.height_kp", height_kp, "vertical velocity per m of height error, 1/s");
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
  PidGains gains() const { return PidGains{kp, ki, kd, integral_max}; }
};

/// eq. 34: e = u - 0.5 with u = cx / image_width the normalised horizontal box centre (0 = left
/// edge, 1 = right edge). e > 0: the target is right of the image centre.
double box_centre_error(const wingman::detection_t& box, int32_t image_width);

/// The most confident drone box (class_id 0: other classes of a multi-class model are never followed) of
/// `detections` whose centre lies inside the image (0 <= cx <= image_width); nullopt when there is none.
/// Ties go to the first.
std::optional<wingman::detection_t> most_confident_box(const wingman::detections_t& detections);

/// One step of the 1-D follower.
struct Pid1dCommand {
  VelocityCommand command;                                   ///< after the limits; yaw rate 0 (the heading is held)
  std::optional<PidTerms> terms;                             ///< the PID's terms when a box was seen
  Eigen::Vector3d axis_in_world = Eigen::Vector3d::UnitX();  ///< unit horizontal axis of motion, ENU
};

/// The 1-D follower:
///
///     e = u - 0.5                                  (eq. 34)
///     v_axis = P + I + D                           (eq. 35-37, class Pid)
///     v = v_axis * a + height_kp (z_ref - z_own) z  (a: the horizontal axis of motion)
///
/// then the VelocityLimiter (floor, speed, acceleration). Without a box in a frame (inside the hold
/// timeout, which the Follower enforces) v_axis = 0 and the PID memory is kept, so a box in the next
/// frame continues the same loop; the acceleration limit ramps the velocity down.
class Pid1dController {
 public:
  /// Throws std::invalid_argument listing the problems of `options` or `limits`.
  Pid1dController(const Pid1dOptions& options, const LimitsOptions& limits, const Eigen::Matrix3d& R_cam_to_body);

  /// The unit horizontal axis of motion in the world (ENU) for the own attitude, or nullopt when the
  /// camera's x axis is within 6 degrees of vertical (axis "camera_right" with the camera rolled on its side).
  std::optional<Eigen::Vector3d> axis_in_world(const OwnState& own) const;

  /// The command at `utime` (microseconds). `error`: eq. 34 for the box seen in this frame, or
  /// nullopt. `axis_in_world`: from axis_in_world(). `own` at utime. `start_height_m`: height of the
  /// first own pose. Throws std::invalid_argument when utime is before the previous command's.
  Pid1dCommand update(std::optional<double> error, const Eigen::Vector3d& axis_in_world, const OwnState& own,
                      int64_t utime, double start_height_m);

  /// Forgets the PID memory and the previous command: on a hold.
  void reset();

 private:
  Pid1dOptions options_;
  Pid1dAxis axis_;
  HeightMode height_mode_;
  Eigen::Matrix3d R_cam_to_body_;
  Pid pid_;
  VelocityLimiter limiter_;
};

}  // namespace wingman::follower_ctrl
