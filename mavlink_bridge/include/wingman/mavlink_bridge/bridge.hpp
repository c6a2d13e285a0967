// SPDX-License-Identifier: MIT
// wingman-mavlink's logic without I/O: MAVLink frames and setpoints in; frames to write and own poses out.
#pragma once

#include "wingman/mavlink_bridge/bridge_options.hpp"
#include "wingman/mavlink_bridge/offboard_streamer.hpp"
#include "wingman/mavlink_bridge/own_pose_assembler.hpp"
#include "wingman/mavlink_bridge/refusals.hpp"
#include "wingman/mavlink_bridge/time_sync.hpp"

#include <wingman/mavlink/frame.hpp>
#include <wingman/own_pose_t.hpp>
#include <wingman/setpoint_t.hpp>

#include <cmath>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace wingman::mavlink_bridge {

/// What one call produced: frames to write to the autopilot, in order, and own poses to publish.
struct BridgeOutput {
  std::vector<std::vector<uint8_t>> frames;
  std::vector<wingman::own_pose_t> poses;
};

/// The bridge. Clocks passed in: `mono_us` (monotonic, microseconds: rates and liveness) and `wall_ns` (the
/// pipeline's epoch clock, nanoseconds: TIMESYNC only). Own poses are stamped with the autopilot's measurement time
/// mapped through TIMESYNC, never with the arrival time. Single-threaded.
class Bridge {
 public:
  /// TIMESYNC requests while no sample has been used yet: this often at most (time.timesync_period_s once synced).
  static constexpr int64_t kTimesyncAcquirePeriodUs = 100000;

  /// `log(reason, message)` is called once per refusal reason (the process logs it as a warning).
  Bridge(const BridgeOptions& options, OffboardStreamer::Log log);

  /// A frame from the autopilot's link.
  void on_frame(const mavlink::Frame& frame, int64_t mono_us, int64_t wall_ns, BridgeOutput& out);
  /// A setpoint from the follower: sent at once when streaming (then at the stream rate).
  void on_setpoint(const wingman::setpoint_t& sp, int64_t mono_us, BridgeOutput& out);
  /// Periodic work, called at least at the stream rate: our HEARTBEAT (1 Hz), TIMESYNC requests, message-rate
  /// requests until acknowledged, the setpoint stream, mode and arm requests (only where allowed), link liveness.
  void tick(int64_t mono_us, int64_t wall_ns, BridgeOutput& out);

  const AutopilotState& autopilot() const { return autopilot_; }
  const TimeSync& time_sync() const { return time_sync_; }
  const OffboardStreamer& streamer() const { return streamer_; }
  /// Refusals outside the stream (poses that could not be made or stamped, commands the autopilot refused).
  const Refusals& refusals() const { return refusals_; }
  int64_t poses_published() const { return poses_; }
  /// The newest ODOMETRY's position standard deviation (sqrt of the mean variance), metres; -1 unknown.
  double position_std_m() const { return position_std_m_; }
  /// SYSTEM_TIME: the autopilot's Unix clock minus ours at its arrival, seconds (monitoring only: own poses are
  /// stamped through TIMESYNC); NaN before one with a Unix time arrived.
  double autopilot_unix_minus_ours_s() const { return unix_diff_s_; }
  /// True when the autopilot is heard and its clock is synchronised (the process reports OK).
  bool healthy() const { return autopilot_.known && time_sync_.synced(); }
  /// One line: autopilot, mode, armed, stream state, time offset and jitter, refusals.
  std::string detail() const;

 private:
  template <class Msg>
  void send(const Msg& msg, BridgeOutput& out);
  void refuse(const std::string& reason, const std::string& message);
  void on_heartbeat(const mavlink::Frame& f, int64_t mono_us);
  void publish_pose(const NedPose& pose, BridgeOutput& out);
  void send_command(uint16_t command, float p1, float p2, float p3, uint8_t confirmation, BridgeOutput& out);

  BridgeOptions o_;
  OffboardStreamer::Log log_;
  OffboardStreamer streamer_;
  OwnPoseAssembler assembler_;
  TimeSync time_sync_;
  Refusals refusals_;
  AutopilotState autopilot_;
  int autopilot_sysid_ = 0;
  int64_t last_heartbeat_rx_us_ = -1;
  int64_t last_heartbeat_tx_us_ = -1;
  int64_t last_timesync_tx_us_ = -1;
  int64_t last_mode_request_us_ = -1;
  int64_t last_arm_request_us_ = -1;
  int64_t refusal_counted_for_us_ = -1;  ///< setpoint (its arrival) whose mode/arm refusals were counted
  /// The newest own pose that came before the autopilot's clock was known (published when the first sample is used).
  std::optional<NedPose> pose_awaiting_clock_;
  int64_t newest_pose_utime_ = 0;
  int64_t poses_ = 0;
  double position_std_m_ = -1;
  double unix_diff_s_ = NAN;
  uint8_t seq_ = 0;
  int64_t start_mono_us_ = -1;
  /// Message-rate requests still to be acknowledged: (message id, interval us); the front one is outstanding.
  std::deque<std::pair<uint32_t, float>> interval_requests_;
  int64_t last_interval_tx_us_ = -1;
  int interval_tries_ = 0;
};

}  // namespace wingman::mavlink_bridge
