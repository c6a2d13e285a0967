// SPDX-License-Identifier: MIT
// The simulated camera vehicle's autopilot as MAVLink sees it: PX4's OFFBOARD or ArduPilot's GUIDED rules, telemetry,
// TIMESYNC, commands. Frames in, frames and vehicle commands out; no I/O, driven by simulated time.
#pragma once

#include "wingman/sim/multirotor.hpp"

#include <wingman/mavlink/frame.hpp>
#include <wingman/setpoint_t.hpp>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace wingman::sim {

/// The uncertainty a vehicle reports with its pose (ODOMETRY.pose_covariance): the same variance on each position
/// axis and on each rotation (roll, pitch, yaw). Unknown by default (ODOMETRY.pose_covariance[0] = NaN).
struct ReportedPoseUncertainty {
  bool known = false;
  double position_var_m2 = 0.0;    ///< variance of each position axis, m^2
  double attitude_var_rad2 = 0.0;  ///< variance of each rotation, rad^2
};

/// Options of the simulated autopilot's MAVLink side (config keys `mavlink.*` of config/sim.yaml; used with
/// `autopilot: mavlink`). Times are simulated seconds unless they say wall clock.
struct MavlinkVehicleOptions {
  /// The link to the companion (wingman-mavlink): udp://HOST:PORT sends there (PX4 SITL's offboard link sends to the
  /// companion's port 14540) and takes the answers on its own port.
  std::string url = "udp://127.0.0.1:14540";
  int system_id = 1;     ///< our MAVLink system id (the vehicle's), 1..255
  int component_id = 1;  ///< our component id (MAV_COMP_ID_AUTOPILOT1), 1..255
  /// px4: OFFBOARD needs a setpoint stream before it is accepted and is left when the stream stops; ardupilot: GUIDED
  /// is accepted at any time, a velocity setpoint stops the vehicle when no new one came for guided_timeout_s.
  std::string firmware = "px4";
  /// The autopilot booted this long before the scenario starts: its boot clock (time_boot_ms, ODOMETRY.time_usec)
  /// reads simulated time minus (start_utime - boot_before_start_s), seconds >= 0.
  double boot_before_start_s = 60.0;
  /// PX4's COM_OF_LOSS_T: no setpoint for longer (simulated time) = offboard lost: PX4 leaves OFFBOARD for POSCTL and
  /// holds; also how recent a setpoint must be for OFFBOARD to be accepted. Seconds > 0.
  double px4_offboard_loss_timeout_s = 1.0;
  /// ArduPilot's GUID_TIMEOUT: a velocity setpoint older than this (simulated time) stops the vehicle (it holds, still
  /// in GUIDED). Seconds > 0.
  double ardupilot_guided_timeout_s = 3.0;
  /// The simulated pilot switches to OFFBOARD/GUIDED from this many simulated seconds after the start, at the first
  /// frame the autopilot accepts it, once; < 0: never (the companion must ask with MAV_CMD_DO_SET_MODE).
  double pilot_engage_s = 0.0;
  /// Messages sent at every frame until the companion sets an interval (MAV_CMD_SET_MESSAGE_INTERVAL):
  /// attitude_quaternion, local_position_ned, odometry.
  std::vector<std::string> streams = {"attitude_quaternion", "local_position_ned"};
  double heartbeat_period_s =
      1.0;  ///< our HEARTBEAT this often on the wall clock (link liveness), and at every mode change

  template <class V>
  void visit(V& v) {
    v("mavlink.url", url, "udp://HOST:PORT of the companion (wingman-mavlink listens on udp://:14540)");
    v("mavlink.system_id", system_id, "our MAVLink system id (1..255)");
    v("mavlink.component_id", component_id, "our MAVLink component id (1..255; 1 = MAV_COMP_ID_AUTOPILOT1)");
    v("mavlink.firmware", firmware,
      "px4 (OFFBOARD needs a setpoint stream, left when it stops) or ardupilot (GUIDED, velocity times out)");
    v("mavlink.boot_before_start_s", boot_before_start_s,
      "the autopilot booted this long before the scenario's start_utime (its boot clock), s");
    v("mavlink.px4_offboard_loss_timeout_s", px4_offboard_loss_timeout_s,
      "PX4 COM_OF_LOSS_T: no setpoint for longer (simulated s) leaves OFFBOARD for POSCTL; also gates entering it");
    v("mavlink.ardupilot_guided_timeout_s", ardupilot_guided_timeout_s,
      "ArduPilot GUID_TIMEOUT: a velocity setpoint older than this (simulated s) stops the vehicle");
    v("mavlink.pilot_engage_s", pilot_engage_s,
      "the simulated pilot engages OFFBOARD/GUIDED from this simulated time on, once (< 0: never)");
    v("mavlink.streams", streams,
      "sent every frame until an interval is set: attitude_quaternion, local_position_ned, odometry");
    v("mavlink.heartbeat_period_s", heartbeat_period_s,
      "our HEARTBEAT this often (wall clock), s, and at mode changes");
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
  bool px4() const { return firmware == "px4"; }
};

/// What the vehicle says and does after an input: frames to send to the companion, commands for the simulated
/// vehicle (setpoint_t in NED, stamped with the simulated time they were given at), and the answer to our own
/// TIMESYNC request (a barrier: see MavlinkVehicle::ping).
struct VehicleOutput {
  std::vector<std::vector<uint8_t>> frames;
  std::vector<wingman::setpoint_t> commands;
  std::optional<int64_t> pong_ts1;  ///< ts1 of a TIMESYNC answer to our request
};

/// Counts for the status line.
struct MavlinkVehicleCounts {
  int64_t setpoints_applied = 0;  ///< SET_POSITION_TARGET_LOCAL_NED in OFFBOARD/GUIDED, given to the vehicle
  int64_t setpoints_ignored = 0;  ///< ... while not in OFFBOARD/GUIDED (PX4 still counts them as the stream)
  int64_t setpoints_refused = 0;  ///< ... with a frame, type_mask or value we do not take (dropped)
  int64_t offboard_lost = 0;      ///< PX4 left OFFBOARD because the stream stopped
  int64_t guided_timeouts = 0;    ///< ArduPilot stopped on an old velocity setpoint
  int64_t mode_refusals = 0;      ///< engage requests refused (PX4 without a stream), by pilot or command
  int64_t commands_answered = 0;  ///< COMMAND_LONG answered with COMMAND_ACK
  int64_t timesync_answered = 0;  ///< TIMESYNC requests answered
};

/// The simulated autopilot. Rules (as PX4 and ArduPilot document them):
/// - PX4: OFFBOARD (main mode 6) is accepted only when a SET_POSITION_TARGET_LOCAL_NED came within
///   px4_offboard_loss_timeout_s (COM_OF_LOSS_T); in OFFBOARD, each setpoint is flown; no setpoint for longer leaves
///   OFFBOARD for POSCTL (main mode 3), which holds the position (COM_OBL_RC_ACT position mode).
/// - ArduPilot: GUIDED (copter mode 4) is accepted at any time and holds until a setpoint comes; a velocity setpoint
///   older than ardupilot_guided_timeout_s (GUID_TIMEOUT) stops the vehicle (hold, still GUIDED); LOITER (5) holds.
/// - Outside OFFBOARD/GUIDED setpoints are ignored (counted); leaving the mode holds the position.
/// - Always armed (the scenario starts in the air); a disarm request is denied.
/// Time: everything is judged on simulated time (`now_utime`, microseconds since epoch), never on arrival times. The
/// boot clock reads now_utime - boot_epoch_utime(). TIMESYNC requests are answered with tc1 = ts1 - boot epoch: the
/// companion's clock is taken as the simulation's epoch clock, so the companion maps boot times back to simulated
/// times (give or take half the round trip).
class MavlinkVehicle {
 public:
  /// Throws std::invalid_argument listing options.validate() problems.
  MavlinkVehicle(const MavlinkVehicleOptions& options, int64_t start_utime);

  /// A frame from the companion, at simulated time `now_utime`.
  void on_frame(const mavlink::Frame& frame, int64_t now_utime, VehicleOutput& out);
  /// A new frame time: the stream and guided timeouts, the pilot, then the telemetry of `state` (ENU world, FLU body:
  /// sent in NED with an FRD body; the reported state, with any pose error) and its `uncertainty` in ODOMETRY's
  /// pose_covariance. Call after the vehicle was stepped to `now_utime`.
  void on_frame_time(int64_t now_utime, const MultirotorState& state, VehicleOutput& out,
                     const ReportedPoseUncertainty& uncertainty = {});
  /// Our HEARTBEAT (the caller paces it on the wall clock; mode changes send one at once).
  void heartbeat(VehicleOutput& out);
  /// A TIMESYNC request whose answer (VehicleOutput::pong_ts1 == the returned ts1) marks that the companion has
  /// handled everything it received before it: the simulator's lockstep barrier.
  int64_t ping(int64_t now_utime, VehicleOutput& out);

  /// True in OFFBOARD (PX4) or GUIDED (ArduPilot).
  bool engaged() const { return engaged_; }
  /// "OFFBOARD", "POSCTL", "GUIDED", "LOITER".
  std::string mode_name() const;
  /// Simulated epoch time of the autopilot's boot, microseconds.
  int64_t boot_epoch_utime() const { return boot_epoch_utime_; }
  const MavlinkVehicleCounts& counts() const { return counts_; }
  /// Requests to engage, by the pilot or a command, at simulated `now_utime`: true when accepted.
  bool request_engage(int64_t now_utime, VehicleOutput& out);
  /// Leaves OFFBOARD/GUIDED for POSCTL/LOITER (holds).
  void disengage(int64_t now_utime, VehicleOutput& out);

 private:
  template <class Msg>
  void send(const Msg& msg, VehicleOutput& out);
  void on_setpoint(const mavlink::Frame& f, int64_t now_utime, VehicleOutput& out);
  void on_command(const mavlink::Frame& f, int64_t now_utime, VehicleOutput& out);
  void hold(int64_t now_utime, VehicleOutput& out);
  bool due(uint32_t msgid, int64_t now_utime);

  MavlinkVehicleOptions o_;
  int64_t boot_epoch_utime_;
  int64_t start_utime_;
  bool engaged_ = false;
  bool pilot_done_ = false;
  std::optional<int64_t> last_setpoint_utime_;        ///< simulated time of the newest setpoint received (any mode)
  std::optional<wingman::setpoint_t> last_setpoint_;  ///< the newest usable one (flown when OFFBOARD is engaged)
  std::optional<int64_t> velocity_since_utime_;       ///< ArduPilot: the velocity setpoint in force came then
  /// Message id -> interval, microseconds (0: every frame; absent: not sent).
  std::map<uint32_t, int64_t> intervals_us_;
  std::map<uint32_t, int64_t> last_sent_utime_;
  uint8_t seq_ = 0;
  int64_t pings_ = 0;
  MavlinkVehicleCounts counts_;
};

}  // namespace wingman::sim
