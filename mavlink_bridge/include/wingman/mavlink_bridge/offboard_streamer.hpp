// SPDX-License-Identifier: MIT
// The safety rules of the setpoint stream: when SET_POSITION_TARGET_LOCAL_NED is sent, with what, and clamped how.
#pragma once

#include "wingman/mavlink_bridge/bridge_options.hpp"
#include "wingman/mavlink_bridge/refusals.hpp"

#include <wingman/mavlink/messages.hpp>
#include <wingman/setpoint_t.hpp>

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

namespace wingman::mavlink_bridge {

/// What the autopilot said in its last HEARTBEAT.
struct AutopilotState {
  bool known = false;                         ///< a HEARTBEAT came and is not older than the heartbeat timeout
  AutopilotKind kind = AutopilotKind::kAuto;  ///< px4 or ardupilot once known (kAuto: neither)
  uint32_t custom_mode = 0;                   ///< HEARTBEAT.custom_mode
  bool armed = false;                         ///< MAV_MODE_FLAG_SAFETY_ARMED
  bool engaged = false;  ///< in the mode that takes offboard setpoints: PX4 OFFBOARD, ArduPilot GUIDED
  /// "OFFBOARD", "GUIDED", "POSCTL", "mode 5", ... for the status line.
  std::string mode_name() const;
};

/// The stream's state.
enum class StreamState {
  kIdle,       ///< not streaming: not engaged, or no live setpoints
  kReady,      ///< PX4 not in OFFBOARD but setpoints live: zero-velocity setpoints so the pilot can engage OFFBOARD
  kStreaming,  ///< engaged and live: the follower's setpoints, clamped
  kHover,      ///< the follower held, lost its target or stopped: zero velocity for hover_s
  kStopped,    ///< after the hover: nothing sent, so the autopilot's own failsafe applies; needs the mode re-engaged
};
const char* to_string(StreamState s);

/// Decides at every tick what to send. Rules (docs/autopilot.md):
/// - the follower's setpoints are sent only while the autopilot is known and engaged (PX4 OFFBOARD, ArduPilot GUIDED);
/// - a MODE_HOLD setpoint, or no setpoint for setpoint_timeout_s, while streaming: zero velocity for hover_s, then
///   nothing (kStopped) until the pilot leaves and re-engages the mode (or at once with resume_after_stop);
/// - leaving the mode stops the stream at once (the pilot has taken over);
/// - speeds, acceleration (change of commanded velocity between sent setpoints, over the setpoints' message times) and
///   the altitude band are clamped;
/// - every refusal or change is counted by reason (refusals()) and `log` is called the first time of each reason.
/// Clocks: `mono_us` (a monotonic clock, microseconds) paces the stream and judges liveness; setpoint ages are judged
/// on message times (setpoint_t.utime against the newest own pose's utime).
class OffboardStreamer {
 public:
  using Log = std::function<void(const std::string& reason, const std::string& message)>;
  OffboardStreamer(const BridgeOptions& options, Log log);

  /// A setpoint from the follower, received at `mono_us`. `newest_pose_utime`: utime of the newest own pose published
  /// (0: none yet). A setpoint that cannot be used is refused and counted.
  void on_setpoint(const wingman::setpoint_t& sp, int64_t mono_us, int64_t newest_pose_utime);
  /// The vehicle's altitude, metres up from the local origin (for the altitude band of velocity setpoints).
  void on_altitude(double altitude_m) { altitude_m_ = altitude_m; }
  /// The autopilot's state changed (HEARTBEAT, or its timeout).
  void on_autopilot(const AutopilotState& state);

  /// The setpoint to send at `mono_us`, or nullopt (nothing due, or not streaming). `force`: send now if streaming,
  /// whatever the rate (a new setpoint arrived). The caller fills time_boot_ms and the target ids.
  std::optional<mavlink::SetPositionTargetLocalNed> tick(int64_t mono_us, bool force = false);

  /// True while the follower's setpoints are live (received within setpoint_timeout_s) and not MODE_HOLD.
  bool wants_control(int64_t mono_us) const;
  /// When the newest usable setpoint arrived (monotonic us; 0 before the first).
  int64_t setpoint_mono_us() const { return setpoint_mono_us_; }
  StreamState state() const { return state_; }
  const Refusals& refusals() const { return refusals_; }
  int64_t sent() const { return sent_; }

 private:
  void refuse(const std::string& reason, const std::string& message);
  void update_state(int64_t mono_us);
  mavlink::SetPositionTargetLocalNed hover_target();
  mavlink::SetPositionTargetLocalNed follower_target(int64_t mono_us);

  BridgeOptions o_;
  Log log_;
  int64_t period_us_;
  AutopilotState autopilot_;
  std::optional<wingman::setpoint_t> setpoint_;
  int64_t setpoint_mono_us_ = 0;
  double altitude_m_ = NAN;
  StreamState state_ = StreamState::kIdle;
  int64_t hover_until_us_ = 0;
  bool left_mode_since_stop_ = false;
  int64_t last_sent_us_ = -1;
  Eigen::Vector3d last_v_ned_ = Eigen::Vector3d::Zero();  ///< velocity of the last sent setpoint (0 for position/hover)
  int64_t last_follower_utime_ = -1;  ///< utime of the follower's setpoint behind the last send; -1: not the follower's
  int64_t sent_ = 0;
  Refusals refusals_;
};

}  // namespace wingman::mavlink_bridge
