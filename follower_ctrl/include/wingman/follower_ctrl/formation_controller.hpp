// SPDX-License-Identifier: MIT
// The formation follower: hold a world-frame offset from the followed target, with velocity
// feed-forward, limits, a floor, collision avoidance and the camera kept on the target.
#pragma once

#include "wingman/follower_ctrl/height_mode.hpp"
#include "wingman/follower_ctrl/pid.hpp"
#include "wingman/follower_ctrl/target_selection.hpp"
#include "wingman/follower_ctrl/velocity_command.hpp"
#include "wingman/follower_ctrl/velocity_limits.hpp"
#include "wingman/follower_ctrl/world_frame.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace wingman::follower_ctrl {

/// Options of the formation controller (keys `formation.*`). World frame ENU whatever the
/// autopilot's convention.
struct FormationOptions {
  /// Desired position of the follower relative to the target, ENU [east, north, up], metres. The
  /// default keeps the follower 6 m south of the target (behind a leader flying north), as in the
  /// thesis's 2-D experiment. Its z is used only with height_mode "target".
  std::vector<double> offset_m = {0.0, -6.0, 0.0};
  /// "start" (height of the first own pose), "fixed" (height_m) or "target" (target z + offset z).
  std::string height_mode = "start";
  double height_m = 2.0;          ///< reference height for height_mode "fixed", ENU z, metres
  double feedforward_gain = 1.0;  ///< K_ff on the target's velocity (vertical part only with height_mode "target")
  double kp = 1.0;                ///< position gain, (m/s) per m of error, per axis
  double ki = 0.0;                ///< integral gain, (m/s) per (m s)
  double kd = 0.0;                ///< derivative gain, (m/s) per (m/s)
  double integral_max_m_s = 1.0;  ///< clamp of the per-axis error integral, m s
  /// Which target to follow when none is followed yet or the followed track has gone:
  /// "most_confident" or "nearest". A followed track is kept while the tracker reports it.
  std::string select = "most_confident";
  /// After the followed track has gone, the longest wait, seconds of message time since its newest image, before
  /// another track may be chosen; the wait is as long as the gone track was followed (from its newest image when it
  /// was chosen), at most this, so a track followed briefly (a false one at the start) is not waited for long. Until
  /// then the follower coasts and then holds, and takes the followed track back if the localizer reports it again.
  /// The default is the tracker's memory for a lost track (the localizer's tracker.reacquire_s, 10 s): a track
  /// confirmed near where the lost one could be takes its id, so within that time another id is something else (a
  /// bird, a false track, another drone). 0: switch at once (>= 0, finite).
  double reselect_after_s = 10.0;
  /// Collision avoidance: while the target is closer than this (3-D distance, metres), the command
  /// has no component towards it and climbs at avoid_climb_mps. 0 disables.
  double avoid_radius_m = 3.0;
  double avoid_climb_mps = 0.5;  ///< climb rate while avoiding, m/s (<= limits.max_vertical_speed_mps)
  double yaw_kp = 1.0;           ///< yaw rate per radian between the optical axis and the target's bearing, 1/s
  /// Weave for the size: while the followed track's size is in doubt (target_t.radius_sigma_m / radius_m above
  /// weave_until_rel), the follower swings this far (metres, horizontally across the line of sight, positive to its
  /// left, a sine of weave_period_s and message time) about its formation position, so that the localizer can see the
  /// target's size from the parallax (docs/localization.md, "Online size"). In a straight formation the camera
  /// otherwise moves in lock step with the target and the size is not observable. 0 (default) disables: with the
  /// shipped CNN the weave found a 30 % wrong size within 12 % but, its sigma staying near 5 %, never stopped, and
  /// cost 1.6 m of formation error (docs/localization.md, "Online size").
  double weave_m = 0.0;
  double weave_period_s = 6.0;    ///< period of the weave, s
  double weave_until_rel = 0.05;  ///< weave while the size's relative sigma is above this

  template <class V>
  void visit(V& v) {
    v("formation.offset_m", offset_m,
      "desired follower position relative to the target, ENU [east, north, up], m (z only with height_mode target)");
    v("formation.height_mode", height_mode,
      "height reference: start (first own pose), fixed (height_m) or target (target z + offset z)");
    v("formation.height_m", height_m, "reference height for height_mode fixed, world up, m");
    v("formation.feedforward_gain", feedforward_gain,
      "gain on the target's velocity from the tracker (vertical part only with height_mode target)");
    v("formation.kp", kp, "position error gain, (m/s) per m, each axis");
    v("formation.ki", ki, "position error integral gain, (m/s) per (m s)");
    v("formation.kd", kd, "position error derivative gain, (m/s) per (m/s)");
    v("formation.integral_max_m_s", integral_max_m_s, "clamp of each axis's position error integral, m s");
    v("formation.select", select,
      "target choice when no track is followed or it has gone: most_confident or nearest (a followed track is kept)");
    v("formation.reselect_after_s", reselect_after_s,
      "after the followed track has gone, wait as long as it was followed, at most this (s since its newest image), "
      "before another");
    v("formation.avoid_radius_m", avoid_radius_m,
      "collision avoidance: target closer than this (3-D), m -> no approach and climb; 0 disables");
    v("formation.avoid_climb_mps", avoid_climb_mps, "climb rate while avoiding, m/s");
    v("formation.yaw_kp", yaw_kp, "yaw rate per radian of bearing error of the camera's optical axis, 1/s");
    v("formation.weave_m", weave_m,
      "while the target's size is in doubt, swing this far across the line of sight (parallax for the size), m; 0 off");
    v("formation.weave_period_s", weave_period_s, "period of that weave, s");
    v("formation.weave_until_rel", weave_until_rel, "weave while target_t.radius_sigma_m / radius_m is above this");
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
};

/// Holds the formation on one target. Per command, with target and own state brought to the command
/// time t (ENU):
///
///     p_des   = p_target + offset                (z per height_mode, raised to the floor)
///     v_ff    = K_ff v_target                    (z = 0 unless height_mode is "target")
///     v_wanted = v_ff + PID(p_des - p_own)       (per axis, the Pid of eq. 35-37 on metres)
///     avoiding: |p_target - p_own| < avoid_radius -> v_wanted.z = avoid_climb, no approach
///     v       = VelocityLimiter(v_wanted)        (floor, no approach, speed, acceleration)
///     yaw rate = yaw_kp * wrap(bearing(p_target - p_own) - azimuth(R_body_to_world R_cam_to_body z_cam)),
///                limited; 0 when the target is within 5 cm horizontally or the optical axis is
///                within 6 degrees of vertical.
class FormationController {
 public:
  /// Throws std::invalid_argument listing the problems of `options` or `limits`.
  FormationController(const FormationOptions& options, const LimitsOptions& limits,
                      const Eigen::Matrix3d& R_cam_to_body);

  /// The command at `utime` (microseconds). `target` and `own` must be at utime (predicted_to()).
  /// `start_height_m`: the height of the first own pose (height_mode "start"). Throws
  /// std::invalid_argument when utime is before the previous command's.
  VelocityCommand update(const TargetState& target, const OwnState& own, int64_t utime, double start_height_m);

  /// The desired position (before the floor check on the command) for `target` at the same time, ENU.
  Eigen::Vector3d desired_position(const TargetState& target, double start_height_m) const;

  /// Forgets the PID memory (integral, previous error): on a track switch.
  void reset_pid();
  /// Forgets the PID memory and the previous command: on a hold.
  void reset();

 private:
  FormationOptions options_;
  HeightMode height_mode_;
  Eigen::Vector3d offset_in_world_;
  Eigen::Matrix3d R_cam_to_body_;
  std::array<Pid, 3> pid_;
  VelocityLimiter limiter_;
};

}  // namespace wingman::follower_ctrl
