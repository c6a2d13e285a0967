// SPDX-License-Identifier: MIT
// The MAVLink messages Wingman speaks, from message_definitions/v1.0/minimal.xml and common.xml.
//
// Each struct lists its fields in wire order through visit(): the fields before extensions() sorted by type size,
// largest first (stable), as MAVLink's generators order them; extension fields after, in definition order. The
// message table (frame.hpp: find_message) computes each message's CRC_EXTRA and lengths from these lists, and a
// test checks them against the published values.
#pragma once

#include <array>
#include <cstdint>

namespace wingman::mavlink {

/// HEARTBEAT (#0): who a component is and what state it is in; sent by every component at 1 Hz.
struct Heartbeat {
  static constexpr uint32_t kId = 0;
  static constexpr const char* kName = "HEARTBEAT";
  uint32_t custom_mode = 0;     ///< autopilot-specific mode (PX4: main mode << 16 | sub mode << 24; ArduCopter: mode)
  uint8_t type = 0;             ///< MAV_TYPE
  uint8_t autopilot = 0;        ///< MAV_AUTOPILOT
  uint8_t base_mode = 0;        ///< MAV_MODE_FLAG bits (128: armed)
  uint8_t system_status = 0;    ///< MAV_STATE
  uint8_t mavlink_version = 3;  ///< MAVLink version (always 3 on the wire; XML type uint8_t_mavlink_version)
  template <class V>
  void visit(V& v) {
    v.field("custom_mode", custom_mode);
    v.field("type", type);
    v.field("autopilot", autopilot);
    v.field("base_mode", base_mode);
    v.field("system_status", system_status);
    v.field("mavlink_version", mavlink_version);
  }
};

/// SYSTEM_TIME (#2): the sender's Unix time and boot time.
struct SystemTime {
  static constexpr uint32_t kId = 2;
  static constexpr const char* kName = "SYSTEM_TIME";
  uint64_t time_unix_usec = 0;  ///< Unix epoch time, microseconds (0: unknown)
  uint32_t time_boot_ms = 0;    ///< time since the sender's boot, milliseconds
  template <class V>
  void visit(V& v) {
    v.field("time_unix_usec", time_unix_usec);
    v.field("time_boot_ms", time_boot_ms);
  }
};

/// ATTITUDE_QUATERNION (#31): the vehicle's attitude, FRD body to NED world.
struct AttitudeQuaternion {
  static constexpr uint32_t kId = 31;
  static constexpr const char* kName = "ATTITUDE_QUATERNION";
  uint32_t time_boot_ms = 0;             ///< measurement time since the autopilot's boot, milliseconds
  float q1 = 1, q2 = 0, q3 = 0, q4 = 0;  ///< quaternion w, x, y, z rotating FRD body vectors into NED
  float rollspeed = 0;                   ///< rad/s about body x
  float pitchspeed = 0;                  ///< rad/s about body y
  float yawspeed = 0;                    ///< rad/s about body z
  std::array<float, 4> repr_offset_q{};  ///< extension: rotation offset of the representation (0s: none)
  template <class V>
  void visit(V& v) {
    v.field("time_boot_ms", time_boot_ms);
    v.field("q1", q1);
    v.field("q2", q2);
    v.field("q3", q3);
    v.field("q4", q4);
    v.field("rollspeed", rollspeed);
    v.field("pitchspeed", pitchspeed);
    v.field("yawspeed", yawspeed);
    v.extensions();
    v.field("repr_offset_q", repr_offset_q);
  }
};

/// LOCAL_POSITION_NED (#32): position and velocity in the autopilot's local NED frame.
struct LocalPositionNed {
  static constexpr uint32_t kId = 32;
  static constexpr const char* kName = "LOCAL_POSITION_NED";
  uint32_t time_boot_ms = 0;     ///< measurement time since the autopilot's boot, milliseconds
  float x = 0, y = 0, z = 0;     ///< position north, east, down, metres
  float vx = 0, vy = 0, vz = 0;  ///< velocity north, east, down, m/s
  template <class V>
  void visit(V& v) {
    v.field("time_boot_ms", time_boot_ms);
    v.field("x", x);
    v.field("y", y);
    v.field("z", z);
    v.field("vx", vx);
    v.field("vy", vy);
    v.field("vz", vz);
  }
};

/// COMMAND_LONG (#76): a command with seven float parameters.
struct CommandLong {
  static constexpr uint32_t kId = 76;
  static constexpr const char* kName = "COMMAND_LONG";
  float param1 = 0, param2 = 0, param3 = 0, param4 = 0, param5 = 0, param6 = 0, param7 = 0;  ///< by command
  uint16_t command = 0;                                                                      ///< MAV_CMD
  uint8_t target_system = 0;     ///< system that executes it
  uint8_t target_component = 0;  ///< component that executes it (0: all)
  uint8_t confirmation = 0;      ///< 0 first transmission, then incremented for each retry
  template <class V>
  void visit(V& v) {
    v.field("param1", param1);
    v.field("param2", param2);
    v.field("param3", param3);
    v.field("param4", param4);
    v.field("param5", param5);
    v.field("param6", param6);
    v.field("param7", param7);
    v.field("command", command);
    v.field("target_system", target_system);
    v.field("target_component", target_component);
    v.field("confirmation", confirmation);
  }
};

/// COMMAND_ACK (#77): the answer to a command.
struct CommandAck {
  static constexpr uint32_t kId = 77;
  static constexpr const char* kName = "COMMAND_ACK";
  uint16_t command = 0;          ///< MAV_CMD acknowledged
  uint8_t result = 0;            ///< MAV_RESULT
  uint8_t progress = 0;          ///< extension: percent done (MAV_RESULT_IN_PROGRESS)
  int32_t result_param2 = 0;     ///< extension: command-specific detail
  uint8_t target_system = 0;     ///< extension: system that sent the command
  uint8_t target_component = 0;  ///< extension: component that sent the command
  template <class V>
  void visit(V& v) {
    v.field("command", command);
    v.field("result", result);
    v.extensions();
    v.field("progress", progress);
    v.field("result_param2", result_param2);
    v.field("target_system", target_system);
    v.field("target_component", target_component);
  }
};

/// The fields of SET_POSITION_TARGET_LOCAL_NED and POSITION_TARGET_LOCAL_NED after time_boot_ms, in wire order.
struct PositionTargetFields {
  float x = 0, y = 0, z = 0;        ///< position north, east, down, metres
  float vx = 0, vy = 0, vz = 0;     ///< velocity north, east, down, m/s
  float afx = 0, afy = 0, afz = 0;  ///< acceleration (or force) north, east, down, m/s^2
  float yaw = 0;                    ///< heading, radians from north, clockwise
  float yaw_rate = 0;               ///< heading rate, rad/s
  uint16_t type_mask = 0;           ///< POSITION_TARGET_TYPEMASK: set bits name the fields to ignore
  /// These fields, in wire order (between time_boot_ms and the 1-byte fields).
  template <class V>
  void visit_target(V& v) {
    v.field("x", x);
    v.field("y", y);
    v.field("z", z);
    v.field("vx", vx);
    v.field("vy", vy);
    v.field("vz", vz);
    v.field("afx", afx);
    v.field("afy", afy);
    v.field("afz", afz);
    v.field("yaw", yaw);
    v.field("yaw_rate", yaw_rate);
    v.field("type_mask", type_mask);
  }
};

/// SET_POSITION_TARGET_LOCAL_NED (#84): an offboard setpoint in the local NED frame.
struct SetPositionTargetLocalNed : PositionTargetFields {
  static constexpr uint32_t kId = 84;
  static constexpr const char* kName = "SET_POSITION_TARGET_LOCAL_NED";
  uint32_t time_boot_ms = 0;     ///< sender's time since boot, milliseconds
  uint8_t target_system = 0;     ///< the autopilot's system id
  uint8_t target_component = 0;  ///< the autopilot's component id
  uint8_t coordinate_frame = 1;  ///< MAV_FRAME (1: MAV_FRAME_LOCAL_NED)
  template <class V>
  void visit(V& v) {
    v.field("time_boot_ms", time_boot_ms);
    visit_target(v);
    v.field("target_system", target_system);
    v.field("target_component", target_component);
    v.field("coordinate_frame", coordinate_frame);
  }
};

/// POSITION_TARGET_LOCAL_NED (#85): the setpoint the autopilot is flying to (its echo of #84).
struct PositionTargetLocalNed : PositionTargetFields {
  static constexpr uint32_t kId = 85;
  static constexpr const char* kName = "POSITION_TARGET_LOCAL_NED";
  uint32_t time_boot_ms = 0;     ///< autopilot's time since boot, milliseconds
  uint8_t coordinate_frame = 1;  ///< MAV_FRAME
  template <class V>
  void visit(V& v) {
    v.field("time_boot_ms", time_boot_ms);
    visit_target(v);
    v.field("coordinate_frame", coordinate_frame);
  }
};

/// TIMESYNC (#111): a time-synchronisation request (tc1 = 0) or response (tc1 = responder's time).
struct Timesync {
  static constexpr uint32_t kId = 111;
  static constexpr const char* kName = "TIMESYNC";
  int64_t tc1 = 0;               ///< responder's time, nanoseconds (0 in a request)
  int64_t ts1 = 0;               ///< requester's time, nanoseconds (mirrored unchanged in the response)
  uint8_t target_system = 0;     ///< extension: the request's sender (responses), 0 broadcast
  uint8_t target_component = 0;  ///< extension: the request's sender (responses), 0 broadcast
  template <class V>
  void visit(V& v) {
    v.field("tc1", tc1);
    v.field("ts1", ts1);
    v.extensions();
    v.field("target_system", target_system);
    v.field("target_component", target_component);
  }
};

/// ODOMETRY (#331): pose, velocity and their covariances.
struct Odometry {
  static constexpr uint32_t kId = 331;
  static constexpr const char* kName = "ODOMETRY";
  uint64_t time_usec = 0;     ///< measurement time: since the autopilot's boot, or Unix time when large, microseconds
  float x = 0, y = 0, z = 0;  ///< position in frame_id, metres
  std::array<float, 4> q{1, 0, 0, 0};  ///< w, x, y, z: child_frame_id (body) to frame_id
  float vx = 0, vy = 0, vz = 0;        ///< velocity in child_frame_id (PX4: MAV_FRAME_BODY_FRD or LOCAL_NED), m/s
  float rollspeed = 0, pitchspeed = 0, yawspeed = 0;  ///< body rates, rad/s
  std::array<float, 21> pose_covariance{};      ///< upper triangle of the 6x6 pose covariance (NaN first: unknown)
  std::array<float, 21> velocity_covariance{};  ///< upper triangle of the 6x6 velocity covariance (NaN first: unknown)
  uint8_t frame_id = 0;                         ///< MAV_FRAME of the pose (MAV_FRAME_LOCAL_NED, MAV_FRAME_LOCAL_FRD)
  uint8_t child_frame_id = 0;                   ///< MAV_FRAME of the velocity (MAV_FRAME_BODY_FRD, MAV_FRAME_LOCAL_NED)
  uint8_t reset_counter = 0;                    ///< extension: incremented at every estimator reset
  uint8_t estimator_type = 0;                   ///< extension: MAV_ESTIMATOR_TYPE
  int8_t quality = 0;                           ///< extension: percent, 0 unknown, -1 failed
  template <class V>
  void visit(V& v) {
    v.field("time_usec", time_usec);
    v.field("x", x);
    v.field("y", y);
    v.field("z", z);
    v.field("q", q);
    v.field("vx", vx);
    v.field("vy", vy);
    v.field("vz", vz);
    v.field("rollspeed", rollspeed);
    v.field("pitchspeed", pitchspeed);
    v.field("yawspeed", yawspeed);
    v.field("pose_covariance", pose_covariance);
    v.field("velocity_covariance", velocity_covariance);
    v.field("frame_id", frame_id);
    v.field("child_frame_id", child_frame_id);
    v.extensions();
    v.field("reset_counter", reset_counter);
    v.field("estimator_type", estimator_type);
    v.field("quality", quality);
  }
};

/// Calls f(Msg{}) for every message type above (the message table, tests).
template <class F>
void for_each_message_type(F&& f) {
  f(Heartbeat{});
  f(SystemTime{});
  f(AttitudeQuaternion{});
  f(LocalPositionNed{});
  f(CommandLong{});
  f(CommandAck{});
  f(SetPositionTargetLocalNed{});
  f(PositionTargetLocalNed{});
  f(Timesync{});
  f(Odometry{});
}

}  // namespace wingman::mavlink
