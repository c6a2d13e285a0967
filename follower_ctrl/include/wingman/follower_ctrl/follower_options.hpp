// SPDX-License-Identifier: MIT
// Options of wingman-follower-ctrl (config/follower_ctrl.yaml).
#pragma once

#include "wingman/follower_ctrl/camera_mount.hpp"
#include "wingman/follower_ctrl/formation_controller.hpp"
#include "wingman/follower_ctrl/pid_1d_controller.hpp"
#include "wingman/follower_ctrl/velocity_limits.hpp"

#include <wingman/common/time_sanity.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace wingman::follower_ctrl {

/// Which controller flies the follower.
enum class ControllerMode {
  kFormation,  ///< "formation": hold an offset from a tracked target (targets_t + own_pose_t)
  kPid1d,      ///< "pid_1d": the thesis's 1-D PID on the box centre (detections_t + own_pose_t)
};

/// "formation" or "pid_1d"; nullopt for anything else.
std::optional<ControllerMode> parse_controller_mode(const std::string& name);

/// Options of the follower process.
struct FollowerOptions {
  std::string targets_channel = "TARGETS";             ///< targets_t input (mode formation)
  std::string own_pose_channel = "OWN_POSE";           ///< own_pose_t input (both modes)
  std::string detections_channel = "DETECTIONS_CAM0";  ///< detections_t input (mode pid_1d)
  std::string output_channel = "SETPOINT";             ///< setpoint_t output
  std::string mode = "formation";                      ///< "formation" or "pid_1d"
  /// Lost-target and lost-input timeout, seconds of message time (> 0). Past it the follower
  /// publishes MODE_HOLD: no usable target for longer (input utime - newest image of the last usable
  /// target), an own pose older than this at the input's time, or no driving input for longer at an
  /// own pose's time.
  double hold_timeout_s = 0.5;
  /// Localizer watchdog (mode formation): the localizer instance whose heartbeats (STATUS_<NAME>,
  /// status_t) are watched; "" switches the watchdog off.
  std::string localizer_instance = "localizer";
  /// No localizer heartbeat for longer than this, seconds of the follower's message time (own-pose and
  /// targets utimes, > 0) -> MODE_HOLD. Heartbeats come every second of wall time: this must exceed the
  /// localizer's status period times the simulator's sync.speed when it runs faster than real time.
  double localizer_heartbeat_timeout_s = 3.0;
  /// Time sanity of the inputs (own poses and driving inputs): future-dated messages dropped, the resync bound.
  common::TimeSanityOptions time;
  LimitsOptions limits;
  CameraMountOptions camera_mount;
  FormationOptions formation;
  Pid1dOptions pid_1d;

  template <class V>
  void visit(V& v) {
    v("input.targets_channel", targets_channel, "targets_t channel from wingman-localizer (mode formation)");
    v("input.own_pose_channel", own_pose_channel, "own_pose_t channel with this vehicle's pose (both modes)");
    v("input.detections_channel", detections_channel, "detections_t channel from wingman-detector (mode pid_1d)");
    v("output.channel", output_channel, "setpoint_t channel to command the autopilot on");
    v("controller.mode", mode, "formation (offset from a tracked target) or pid_1d (thesis 1-D PID on the box centre)");
    v("hold.timeout_s", hold_timeout_s,
      "no usable target, no fresh own pose or no driving input for longer than this (message time, s) -> MODE_HOLD");
    v("localizer.instance", localizer_instance,
      "mode formation: hold unless this localizer instance's heartbeat (STATUS_<NAME>) is alive; \"\" = no watchdog");
    v("localizer.heartbeat_timeout_s", localizer_heartbeat_timeout_s,
      "no localizer heartbeat for longer than this (own-pose/targets time, s), or STOPPING/ERROR -> MODE_HOLD");
    time.visit(v);
    limits.visit(v);
    camera_mount.visit(v);
    formation.visit(v);
    pid_1d.visit(v);
  }
  /// One "key = value: rule" line per problem (every section); empty when valid.
  std::vector<std::string> validate() const;

  /// The mode. Precondition: validate() is empty.
  ControllerMode controller_mode() const { return *parse_controller_mode(mode); }
  /// hold_timeout_s in microseconds.
  int64_t hold_timeout_us() const;
  /// localizer_heartbeat_timeout_s in microseconds.
  int64_t localizer_heartbeat_timeout_us() const;
};

}  // namespace wingman::follower_ctrl
