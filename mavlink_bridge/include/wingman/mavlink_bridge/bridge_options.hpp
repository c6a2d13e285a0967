// SPDX-License-Identifier: MIT
// Options of wingman-mavlink (config/mavlink_bridge.yaml).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace wingman::mavlink_bridge {

/// Which autopilot's offboard rules apply.
enum class AutopilotKind {
  kAuto,       ///< "auto": from the autopilot's HEARTBEAT (MAV_AUTOPILOT_PX4 or MAV_AUTOPILOT_ARDUPILOTMEGA)
  kPx4,        ///< "px4": OFFBOARD (custom main mode 6) is the engaged mode
  kArdupilot,  ///< "ardupilot": GUIDED (copter mode 4) is the engaged mode
};

/// Options of the bridge process. Times are seconds, speeds m/s, altitudes metres up from the autopilot's local origin.
struct BridgeOptions {
  // link
  std::string link_url =
      "udp://:14540";                ///< udp://:PORT (listen, answer the sender), udp://HOST:PORT, or a serial path
  int baud = 921600;                 ///< serial baud rate (serial links only)
  double reopen_period_s = 1.0;      ///< a lost serial port / socket is reopened this often
  int system_id = 1;                 ///< our MAVLink system id (the vehicle's, as companion computers use)
  int component_id = 191;            ///< our component id (MAV_COMP_ID_ONBOARD_COMPUTER)
  int autopilot_system_id = 0;       ///< the autopilot's system id; 0 = the first autopilot HEARTBEAT's
  int autopilot_component_id = 1;    ///< the autopilot's component id (MAV_COMP_ID_AUTOPILOT1)
  std::string autopilot = "auto";    ///< auto, px4 or ardupilot: whose offboard rules apply
  double heartbeat_timeout_s = 3.0;  ///< no autopilot HEARTBEAT for longer (monotonic clock) = link lost
  // LCM
  std::string setpoint_channel = "SETPOINT";  ///< setpoint_t input from wingman-follower-ctrl
  std::string own_pose_channel = "OWN_POSE";  ///< own_pose_t output
  std::string own_pose_frame = "enu";         ///< frame of the published own pose: enu (FLU body) or ned (FRD body)
  // own pose
  std::string pose_source = "auto";  ///< auto (ODOMETRY once seen, else the pair), odometry, or attitude_position
  double max_attitude_age_s =
      0.1;  ///< attitude_position: attitude and position this far apart at most (autopilot time)
  // rates asked for with MAV_CMD_SET_MESSAGE_INTERVAL (0: not asked)
  double attitude_rate_hz = 50.0;        ///< ATTITUDE_QUATERNION
  double local_position_rate_hz = 50.0;  ///< LOCAL_POSITION_NED
  double odometry_rate_hz = 0.0;         ///< ODOMETRY
  // time
  double timesync_period_s = 0.5;    ///< TIMESYNC requests this often
  double timesync_max_rtt_s = 0.05;  ///< samples whose round trip is longer are not used
  int timesync_window = 16;          ///< the offset is the median of this many recent samples (jitter: their spread)
  // setpoint stream
  double stream_rate_hz = 20.0;  ///< SET_POSITION_TARGET_LOCAL_NED rate while streaming (>= 2: autopilots drop below)
  double setpoint_timeout_s = 0.5;  ///< no setpoint for longer (monotonic clock) = the stream stopped
  double max_setpoint_age_s = 0.5;  ///< a setpoint older than the newest own pose by more (message time) is refused
  double hover_s = 1.0;             ///< on hold, target loss or stream stop: hover this long, then stop streaming
  bool px4_ready_stream =
      true;  ///< PX4 only: zero-velocity setpoints while not in OFFBOARD, so the pilot can engage it
  bool resume_after_stop = false;  ///< after a stop, stream again without the pilot re-engaging the mode
  bool allow_mode_switch = false;  ///< may request OFFBOARD / GUIDED itself (MAV_CMD_DO_SET_MODE)
  bool allow_arm = false;          ///< may arm itself (MAV_CMD_COMPONENT_ARM_DISARM)
  // limits applied again here
  double max_horizontal_speed_mps = 5.0;  ///< commanded horizontal speed at most
  double max_vertical_speed_mps = 2.0;    ///< commanded vertical speed at most
  double max_acceleration_mps2 = 3.0;     ///< commanded velocity changes at most this fast (setpoints' message times)
  double min_altitude_m = 2.0;   ///< altitude band: never commanded below (position) or further down (velocity)
  double max_altitude_m = 50.0;  ///< altitude band: never commanded above or further up

  template <class V>
  void visit(V& v) {
    v("link.url", link_url,
      "udp://:PORT (listen, answer the sender), udp://HOST:PORT (send there), or a serial device path");
    v("link.baud", baud, "serial baud rate (serial links only)");
    v("link.reopen_period_s", reopen_period_s, "a lost serial port or socket is reopened this often, s");
    v("link.system_id", system_id, "our MAVLink system id (1..255; companion computers use the vehicle's)");
    v("link.component_id", component_id, "our MAVLink component id (1..255; 191 = MAV_COMP_ID_ONBOARD_COMPUTER)");
    v("autopilot.system_id", autopilot_system_id,
      "the autopilot's system id; 0 = that of the first autopilot HEARTBEAT");
    v("autopilot.component_id", autopilot_component_id, "the autopilot's component id (1 = MAV_COMP_ID_AUTOPILOT1)");
    v("autopilot.kind", autopilot, "auto (from its HEARTBEAT), px4 (OFFBOARD engages) or ardupilot (GUIDED engages)");
    v("autopilot.heartbeat_timeout_s", heartbeat_timeout_s,
      "no autopilot HEARTBEAT for longer than this (monotonic clock, s): link lost, streaming stops");
    v("input.setpoint_channel", setpoint_channel, "setpoint_t channel from wingman-follower-ctrl");
    v("output.own_pose_channel", own_pose_channel, "own_pose_t channel to publish the autopilot's pose on");
    v("output.own_pose_frame", own_pose_frame, "frame of the published own pose: enu (FLU body) or ned (FRD body)");
    v("pose.source", pose_source,
      "auto (ODOMETRY once seen, else ATTITUDE_QUATERNION + LOCAL_POSITION_NED), odometry, or attitude_position");
    v("pose.max_attitude_age_s", max_attitude_age_s,
      "attitude_position: the attitude may be this far from the position's time at most (autopilot time, s)");
    v("rates.attitude_quaternion_hz", attitude_rate_hz, "ATTITUDE_QUATERNION rate asked for (0: not asked)");
    v("rates.local_position_ned_hz", local_position_rate_hz, "LOCAL_POSITION_NED rate asked for (0: not asked)");
    v("rates.odometry_hz", odometry_rate_hz, "ODOMETRY rate asked for (0: not asked)");
    v("time.timesync_period_s", timesync_period_s, "TIMESYNC requests this often, s");
    v("time.timesync_max_rtt_s", timesync_max_rtt_s, "TIMESYNC samples with a longer round trip are not used, s");
    v("time.timesync_window", timesync_window, "the offset is the median of this many recent samples (2..256)");
    v("stream.rate_hz", stream_rate_hz,
      "SET_POSITION_TARGET_LOCAL_NED rate while streaming (>= 2: autopilots drop below)");
    v("stream.setpoint_timeout_s", setpoint_timeout_s,
      "no setpoint for longer than this (monotonic clock, s): the stream stopped -> hover, then stop");
    v("stream.max_setpoint_age_s", max_setpoint_age_s,
      "a setpoint older than the newest own pose by more than this (message time, s) is refused");
    v("stream.hover_s", hover_s, "on hold, target loss or stream stop: command a hover this long, then stop streaming");
    v("safety.px4_ready_stream", px4_ready_stream,
      "PX4: send zero-velocity setpoints while not in OFFBOARD so the pilot can engage it (PX4 needs a stream first)");
    v("safety.resume_after_stop", resume_after_stop,
      "after a stop, stream again without the pilot leaving and re-engaging OFFBOARD/GUIDED");
    v("safety.allow_mode_switch", allow_mode_switch, "may request OFFBOARD/GUIDED itself (never unless true)");
    v("safety.allow_arm", allow_arm, "may arm the vehicle itself (never unless true)");
    v("limits.max_horizontal_speed_mps", max_horizontal_speed_mps, "commanded horizontal speed at most, m/s");
    v("limits.max_vertical_speed_mps", max_vertical_speed_mps, "commanded vertical speed at most, m/s");
    v("limits.max_acceleration_mps2", max_acceleration_mps2,
      "commanded velocity changes at most this fast over the setpoints' message times, m/s^2");
    v("limits.min_altitude_m", min_altitude_m, "lowest altitude commanded (metres up from the local origin)");
    v("limits.max_altitude_m", max_altitude_m, "highest altitude commanded (metres up from the local origin)");
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
  /// The autopilot kind. Precondition: validate() is empty.
  AutopilotKind autopilot_kind() const;
};

}  // namespace wingman::mavlink_bridge
