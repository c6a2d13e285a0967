// SPDX-License-Identifier: MIT
// The bridge: autopilot state, own poses, time sync, the setpoint stream and requests.
#include "wingman/mavlink_bridge/bridge.hpp"

#include <wingman/mavlink/enums.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace wingman::mavlink_bridge {

using namespace wingman::mavlink;

namespace {

constexpr int64_t kHeartbeatPeriodUs = 1000000;
constexpr int64_t kRequestRetryUs = 1000000;
constexpr int kRequestTries = 3;

PoseSource pose_source(const std::string& s) {
  if (s == "odometry") return PoseSource::kOdometry;
  if (s == "attitude_position") return PoseSource::kAttitudePosition;
  return PoseSource::kAuto;
}

}  // namespace

Bridge::Bridge(const BridgeOptions& options, OffboardStreamer::Log log)
    : o_(options),
      log_(log),
      streamer_(options, log),
      assembler_(pose_source(options.pose_source),
                 static_cast<int64_t>(std::llround(options.max_attitude_age_s * 1e6))),
      time_sync_(options.timesync_window, static_cast<int64_t>(std::llround(options.timesync_max_rtt_s * 1e6))),
      autopilot_sysid_(options.autopilot_system_id) {
  for (auto [id, hz] : {std::pair<uint32_t, double>{AttitudeQuaternion::kId, options.attitude_rate_hz},
                        {LocalPositionNed::kId, options.local_position_rate_hz},
                        {Odometry::kId, options.odometry_rate_hz}})
    if (hz > 0) interval_requests_.emplace_back(id, static_cast<float>(1e6 / hz));
}

void Bridge::refuse(const std::string& reason, const std::string& message) {
  if (refusals_.count(reason) && log_) log_(reason, message);
}

template <class Msg>
void Bridge::send(const Msg& msg, BridgeOutput& out) {
  out.frames.push_back(
      encode(msg, Sender{static_cast<uint8_t>(o_.system_id), static_cast<uint8_t>(o_.component_id), seq_++}));
}

void Bridge::send_command(uint16_t command, float p1, float p2, float p3, uint8_t confirmation, BridgeOutput& out) {
  CommandLong c;
  c.target_system = static_cast<uint8_t>(autopilot_sysid_);
  c.target_component = static_cast<uint8_t>(o_.autopilot_component_id);
  c.command = command;
  c.confirmation = confirmation;
  c.param1 = p1;
  c.param2 = p2;
  c.param3 = p3;
  send(c, out);
}

void Bridge::on_heartbeat(const Frame& f, int64_t mono_us) {
  Heartbeat hb;
  decode(f, hb);
  if (hb.autopilot == kMavAutopilotInvalid) return;  // a ground station or another companion computer
  if (autopilot_sysid_ == 0) autopilot_sysid_ = f.sysid;
  AutopilotState s;
  s.known = true;
  switch (o_.autopilot_kind()) {
    case AutopilotKind::kPx4:
      s.kind = AutopilotKind::kPx4;
      break;
    case AutopilotKind::kArdupilot:
      s.kind = AutopilotKind::kArdupilot;
      break;
    case AutopilotKind::kAuto:
      s.kind = hb.autopilot == kMavAutopilotPx4             ? AutopilotKind::kPx4
               : hb.autopilot == kMavAutopilotArdupilotmega ? AutopilotKind::kArdupilot
                                                            : AutopilotKind::kAuto;
      break;
  }
  if (s.kind == AutopilotKind::kAuto)
    refuse("autopilot_unknown", "HEARTBEAT.autopilot = " + std::to_string(hb.autopilot) +
                                    ": neither PX4 (12) nor ArduPilot (3); set autopilot.kind; never streaming");
  s.custom_mode = hb.custom_mode;
  s.armed = (hb.base_mode & kMavModeFlagSafetyArmed) != 0;
  s.engaged = (hb.base_mode & kMavModeFlagCustomModeEnabled) != 0 &&
              ((s.kind == AutopilotKind::kPx4 && px4_main_mode(hb.custom_mode) == kPx4MainModeOffboard) ||
               (s.kind == AutopilotKind::kArdupilot && hb.custom_mode == kCopterModeGuided));
  autopilot_ = s;
  last_heartbeat_rx_us_ = mono_us;
  streamer_.on_autopilot(autopilot_);
}

void Bridge::publish_pose(const NedPose& pose, BridgeOutput& out) {
  int64_t utime = pose.time_us;
  if (!pose.epoch_time) {
    if (!time_sync_.synced()) {
      // Held, not lost: the newest one is published (with its own measurement time) once the clock is known.
      refuse("pose_before_timesync",
             "own pose held: no TIMESYNC answer from the autopilot yet (the newest is published once one is used)");
      pose_awaiting_clock_ = pose;
      return;
    }
    utime = time_sync_.to_epoch_us(pose.time_us);
  }
  out.poses.push_back(own_pose_message(pose, utime, o_.own_pose_frame == "enu"));
  newest_pose_utime_ = utime;
  streamer_.on_altitude(-pose.p_body_in_ned.z());
  ++poses_;
}

void Bridge::on_frame(const Frame& f, int64_t mono_us, int64_t wall_ns, BridgeOutput& out) {
  if (f.msgid == Heartbeat::kId) {
    on_heartbeat(f, mono_us);
    return;
  }
  const bool from_autopilot =
      autopilot_sysid_ != 0 && f.sysid == autopilot_sysid_ && f.compid == o_.autopilot_component_id;
  if (f.msgid == Timesync::kId) {
    Timesync t;
    decode(f, t);
    if (t.tc1 == 0) {  // a request (PX4 and ArduPilot sync to companions too): answer with our clock
      Timesync reply;
      reply.tc1 = wall_ns;
      reply.ts1 = t.ts1;
      reply.target_system = f.sysid;
      reply.target_component = f.compid;
      send(reply, out);
    } else if (from_autopilot) {
      if (!time_sync_.on_response(t.tc1, t.ts1, wall_ns)) {
        refuse("timesync_sample_rejected",
               "a TIMESYNC answer came too late (time.timesync_max_rtt_s) and was not used");
      } else if (pose_awaiting_clock_) {
        const NedPose held = *pose_awaiting_clock_;
        pose_awaiting_clock_.reset();
        publish_pose(held, out);
      }
    }
    return;
  }
  if (!from_autopilot) return;
  if (f.msgid == SystemTime::kId) {
    SystemTime st;
    decode(f, st);
    if (st.time_unix_usec != 0)
      unix_diff_s_ = (static_cast<double>(st.time_unix_usec) - static_cast<double>(wall_ns / 1000)) * 1e-6;
    return;
  }
  std::string why;
  std::optional<NedPose> pose;
  switch (f.msgid) {
    case AttitudeQuaternion::kId: {
      AttitudeQuaternion m;
      decode(f, m);
      pose = assembler_.on_attitude(m, &why);
      break;
    }
    case LocalPositionNed::kId: {
      LocalPositionNed m;
      decode(f, m);
      pose = assembler_.on_local_position(m, &why);
      break;
    }
    case Odometry::kId: {
      Odometry m;
      decode(f, m);
      pose = assembler_.on_odometry(m, &why);
      break;
    }
    case CommandAck::kId: {
      CommandAck ack;
      decode(f, ack);
      if (ack.command == kMavCmdSetMessageInterval && !interval_requests_.empty()) {
        if (ack.result != kMavResultAccepted)
          refuse("message_interval_refused", "the autopilot refused MAV_CMD_SET_MESSAGE_INTERVAL for message " +
                                                 std::to_string(interval_requests_.front().first) + " (MAV_RESULT " +
                                                 std::to_string(ack.result) + ")");
        interval_requests_.pop_front();
        interval_tries_ = 0;
        last_interval_tx_us_ = -1;
      } else if ((ack.command == kMavCmdDoSetMode || ack.command == kMavCmdComponentArmDisarm) &&
                 ack.result != kMavResultAccepted) {
        refuse(ack.command == kMavCmdDoSetMode ? "mode_request_refused" : "arm_request_refused",
               "the autopilot refused command " + std::to_string(ack.command) + " (MAV_RESULT " +
                   std::to_string(ack.result) + ")");
      }
      return;
    }
    default:
      return;
  }
  if (!why.empty()) refuse(pose ? "bad_pose_covariance" : "bad_pose_message", why);
  if (pose && pose->position_std_m >= 0) position_std_m_ = pose->position_std_m;
  if (pose) publish_pose(*pose, out);
}

void Bridge::on_setpoint(const wingman::setpoint_t& sp, int64_t mono_us, BridgeOutput& out) {
  streamer_.on_setpoint(sp, mono_us, newest_pose_utime_);
  if (auto t = streamer_.tick(mono_us, /*force=*/true)) {
    t->time_boot_ms = static_cast<uint32_t>((mono_us - start_mono_us_) / 1000);
    t->target_system = static_cast<uint8_t>(autopilot_sysid_);
    t->target_component = static_cast<uint8_t>(o_.autopilot_component_id);
    send(*t, out);
  }
}

void Bridge::tick(int64_t mono_us, int64_t wall_ns, BridgeOutput& out) {
  if (start_mono_us_ < 0) start_mono_us_ = mono_us;
  // Link liveness.
  const int64_t hb_timeout_us = static_cast<int64_t>(std::llround(o_.heartbeat_timeout_s * 1e6));
  if (autopilot_.known && mono_us - last_heartbeat_rx_us_ > hb_timeout_us) {
    refuse("autopilot_heartbeat_lost", "no autopilot HEARTBEAT for autopilot.heartbeat_timeout_s: streaming stops");
    autopilot_.known = false;
    autopilot_.engaged = false;
    streamer_.on_autopilot(autopilot_);
  }
  // Our HEARTBEAT, as an onboard controller.
  if (last_heartbeat_tx_us_ < 0 || mono_us - last_heartbeat_tx_us_ >= kHeartbeatPeriodUs) {
    Heartbeat hb;
    hb.type = kMavTypeOnboardController;
    hb.autopilot = kMavAutopilotInvalid;
    hb.system_status = kMavStateActive;
    send(hb, out);
    last_heartbeat_tx_us_ = mono_us;
  }
  if (autopilot_sysid_ != 0) {
    // TIMESYNC requests.
    // Until a sample is used (none yet, or each came too late), every kTimesyncAcquirePeriodUs at most: own poses
    // wait for the clock.
    int64_t ts_period_us = static_cast<int64_t>(std::llround(o_.timesync_period_s * 1e6));
    if (!time_sync_.synced()) ts_period_us = std::min(ts_period_us, kTimesyncAcquirePeriodUs);
    if (last_timesync_tx_us_ < 0 || mono_us - last_timesync_tx_us_ >= ts_period_us) {
      Timesync t;
      t.ts1 = wall_ns;
      t.target_system = static_cast<uint8_t>(autopilot_sysid_);
      t.target_component = static_cast<uint8_t>(o_.autopilot_component_id);
      send(t, out);
      last_timesync_tx_us_ = mono_us;
    }
    // Message rates, one request outstanding at a time (COMMAND_ACK does not say which message it answers).
    if (!interval_requests_.empty() &&
        (last_interval_tx_us_ < 0 || mono_us - last_interval_tx_us_ >= kRequestRetryUs)) {
      if (interval_tries_ >= kRequestTries) {
        refuse("message_interval_unanswered", "no COMMAND_ACK for MAV_CMD_SET_MESSAGE_INTERVAL of message " +
                                                  std::to_string(interval_requests_.front().first) + ": given up");
        interval_requests_.pop_front();
        interval_tries_ = 0;
      }
      if (!interval_requests_.empty()) {
        const auto [id, interval_us] = interval_requests_.front();
        send_command(kMavCmdSetMessageInterval, static_cast<float>(id), interval_us, 0,
                     static_cast<uint8_t>(interval_tries_), out);
        ++interval_tries_;
        last_interval_tx_us_ = mono_us;
      }
    }
  }
  // The setpoint stream.
  if (auto t = streamer_.tick(mono_us)) {
    t->time_boot_ms = static_cast<uint32_t>((mono_us - start_mono_us_) / 1000);
    t->target_system = static_cast<uint8_t>(autopilot_sysid_);
    t->target_component = static_cast<uint8_t>(o_.autopilot_component_id);
    send(*t, out);
  }
  // Mode and arm requests: only where a config key allows them, and only while the follower has live setpoints. A
  // refusal is counted once per setpoint received, not per tick.
  const bool count_refusal = streamer_.setpoint_mono_us() != refusal_counted_for_us_;
  const bool wants = streamer_.state() == StreamState::kReady ||
                     (autopilot_.kind == AutopilotKind::kArdupilot && streamer_.wants_control(mono_us));
  if (autopilot_.known && !autopilot_.engaged && wants) {
    if (!o_.allow_mode_switch) {
      if (count_refusal)
        refuse("mode_switch_not_allowed",
               "setpoints are live but the autopilot is not in OFFBOARD/GUIDED; the pilot "
               "must engage it (safety.allow_mode_switch is false)");
    } else if (last_mode_request_us_ < 0 || mono_us - last_mode_request_us_ >= kRequestRetryUs) {
      const bool px4 = autopilot_.kind == AutopilotKind::kPx4;
      send_command(kMavCmdDoSetMode, kMavModeFlagCustomModeEnabled,
                   px4 ? static_cast<float>(kPx4MainModeOffboard) : static_cast<float>(kCopterModeGuided), 0, 0, out);
      last_mode_request_us_ = mono_us;
    }
  }
  if (autopilot_.known && !autopilot_.armed && streamer_.wants_control(mono_us)) {
    if (!o_.allow_arm) {
      if (count_refusal)
        refuse("arm_not_allowed",
               "setpoints are live but the vehicle is disarmed; the pilot must arm it "
               "(safety.allow_arm is false)");
    } else if (last_arm_request_us_ < 0 || mono_us - last_arm_request_us_ >= kRequestRetryUs) {
      send_command(kMavCmdComponentArmDisarm, 1, 0, 0, 0, out);
      last_arm_request_us_ = mono_us;
    }
  }
  refusal_counted_for_us_ = streamer_.setpoint_mono_us();
}

std::string Bridge::detail() const {
  const char* kind = autopilot_.kind == AutopilotKind::kPx4         ? "px4"
                     : autopilot_.kind == AutopilotKind::kArdupilot ? "ardupilot"
                                                                    : "autopilot";
  std::string s = autopilot_.known
                      ? std::string(kind) + " " + autopilot_.mode_name() + (autopilot_.armed ? " armed" : " disarmed")
                      : "no autopilot heartbeat";
  s += "; stream " + std::string(to_string(streamer_.state())) + " (" + std::to_string(streamer_.sent()) + " sent)";
  if (time_sync_.synced()) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "; time offset %lld us, jitter %.0f us, rtt %lld us",
                  static_cast<long long>(time_sync_.offset_us()), time_sync_.jitter_us(),
                  static_cast<long long>(time_sync_.last_rtt_us()));
    s += buf;
  } else {
    s += "; no time sync yet";
  }
  s += "; own poses " + std::to_string(poses_);
  if (position_std_m_ >= 0) {
    char buf[64];
    std::snprintf(buf, sizeof buf, " (position std %.3f m)", position_std_m_);
    s += buf;
  }
  if (std::isfinite(unix_diff_s_)) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "; autopilot Unix clock %+.3f s from ours", unix_diff_s_);
    s += buf;
  }
  s += "; refusals: " + streamer_.refusals().summary() + "; " + refusals_.summary();
  return s;
}

}  // namespace wingman::mavlink_bridge
