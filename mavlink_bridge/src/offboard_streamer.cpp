// SPDX-License-Identifier: MIT
// The setpoint stream's states, conversion to NED and clamps.
#include "wingman/mavlink_bridge/offboard_streamer.hpp"

#include <wingman/geometry/message_eigen.hpp>
#include <wingman/geometry/ned_enu.hpp>
#include <wingman/mavlink/enums.hpp>
#include <wingman/own_pose_t.hpp>

#include <algorithm>
#include <cmath>

namespace wingman::mavlink_bridge {

using mavlink::SetPositionTargetLocalNed;

std::string AutopilotState::mode_name() const {
  if (kind == AutopilotKind::kPx4) {
    switch (mavlink::px4_main_mode(custom_mode)) {
      case 1:
        return "MANUAL";
      case 2:
        return "ALTCTL";
      case mavlink::kPx4MainModePosctl:
        return "POSCTL";
      case mavlink::kPx4MainModeAuto:
        return "AUTO";
      case 5:
        return "ACRO";
      case mavlink::kPx4MainModeOffboard:
        return "OFFBOARD";
      case 7:
        return "STABILIZED";
      default:
        return "main mode " + std::to_string(mavlink::px4_main_mode(custom_mode));
    }
  }
  if (kind == AutopilotKind::kArdupilot) {
    switch (custom_mode) {
      case 0:
        return "STABILIZE";
      case 2:
        return "ALT_HOLD";
      case 3:
        return "AUTO";
      case mavlink::kCopterModeGuided:
        return "GUIDED";
      case mavlink::kCopterModeLoiter:
        return "LOITER";
      case 6:
        return "RTL";
      case 9:
        return "LAND";
      case mavlink::kCopterModeBrake:
        return "BRAKE";
      default:
        return "mode " + std::to_string(custom_mode);
    }
  }
  return "mode " + std::to_string(custom_mode);
}

const char* to_string(StreamState s) {
  switch (s) {
    case StreamState::kIdle:
      return "idle";
    case StreamState::kReady:
      return "ready (zero velocity until OFFBOARD)";
    case StreamState::kStreaming:
      return "streaming";
    case StreamState::kHover:
      return "hover";
    case StreamState::kStopped:
      return "stopped";
  }
  return "?";
}

OffboardStreamer::OffboardStreamer(const BridgeOptions& options, Log log)
    : o_(options), log_(std::move(log)), period_us_(static_cast<int64_t>(std::llround(1e6 / options.stream_rate_hz))) {}

void OffboardStreamer::refuse(const std::string& reason, const std::string& message) {
  if (refusals_.count(reason) && log_) log_(reason, message);
}

void OffboardStreamer::on_setpoint(const wingman::setpoint_t& sp, int64_t mono_us, int64_t newest_pose_utime) {
  if (sp.frame != wingman::own_pose_t::FRAME_ENU && sp.frame != wingman::own_pose_t::FRAME_NED) {
    refuse("setpoint_bad_frame", "setpoint_t.frame = " + std::to_string(sp.frame) + ": must be FRAME_ENU or FRAME_NED");
    return;
  }
  const int64_t max_age_us = static_cast<int64_t>(std::llround(o_.max_setpoint_age_s * 1e6));
  if (newest_pose_utime > 0 && newest_pose_utime - sp.utime > max_age_us) {
    refuse("setpoint_too_old", "setpoint_t.utime is " + std::to_string((newest_pose_utime - sp.utime) / 1000) +
                                   " ms older than the newest own pose (stream.max_setpoint_age_s)");
    return;
  }
  if (sp.mode != wingman::setpoint_t::MODE_HOLD && !autopilot_.engaged)
    refuse("setpoint_not_engaged", "setpoints arrive but the autopilot is not in OFFBOARD/GUIDED: not sent");
  setpoint_ = sp;
  setpoint_mono_us_ = mono_us;
}

void OffboardStreamer::on_autopilot(const AutopilotState& state) {
  if (!state.engaged && (state_ == StreamState::kStopped)) left_mode_since_stop_ = true;
  autopilot_ = state;
}

bool OffboardStreamer::wants_control(int64_t mono_us) const {
  const int64_t timeout_us = static_cast<int64_t>(std::llround(o_.setpoint_timeout_s * 1e6));
  return setpoint_ && mono_us - setpoint_mono_us_ <= timeout_us && setpoint_->mode != wingman::setpoint_t::MODE_HOLD;
}

void OffboardStreamer::update_state(int64_t mono_us) {
  const int64_t timeout_us = static_cast<int64_t>(std::llround(o_.setpoint_timeout_s * 1e6));
  const bool live = setpoint_ && mono_us - setpoint_mono_us_ <= timeout_us;
  const bool active = wants_control(mono_us);
  const bool engaged = autopilot_.known && autopilot_.engaged;
  const bool may_start = state_ != StreamState::kStopped || o_.resume_after_stop || left_mode_since_stop_;
  switch (state_) {
    case StreamState::kIdle:
    case StreamState::kReady:
    case StreamState::kStopped:
      if (engaged && active && may_start) {
        state_ = StreamState::kStreaming;
        left_mode_since_stop_ = false;
      } else if (o_.px4_ready_stream && autopilot_.known && autopilot_.kind == AutopilotKind::kPx4 && !engaged &&
                 active) {
        state_ = StreamState::kReady;
      } else if (state_ == StreamState::kReady) {
        state_ = StreamState::kIdle;
      }
      break;
    case StreamState::kStreaming:
      if (!engaged) {
        refuse("mode_left", autopilot_.known ? "the autopilot left OFFBOARD/GUIDED (" + autopilot_.mode_name() +
                                                   "): stream stopped at once"
                                             : "autopilot HEARTBEAT lost: stream stopped at once");
        state_ = StreamState::kIdle;
      } else if (!active) {
        refuse(live ? "follower_hold" : "setpoint_stream_stopped",
               live ? "the follower holds: hover, then stop streaming"
                    : "no setpoint for stream.setpoint_timeout_s: hover, then stop streaming");
        state_ = StreamState::kHover;
        hover_until_us_ = mono_us + static_cast<int64_t>(std::llround(o_.hover_s * 1e6));
      }
      break;
    case StreamState::kHover:
      if (!engaged) {
        state_ = StreamState::kIdle;
      } else if (active) {
        state_ = StreamState::kStreaming;
      } else if (mono_us >= hover_until_us_) {
        state_ = StreamState::kStopped;
        left_mode_since_stop_ = false;
      }
      break;
  }
}

std::optional<SetPositionTargetLocalNed> OffboardStreamer::tick(int64_t mono_us, bool force) {
  const StreamState before = state_;
  update_state(mono_us);
  const bool sending =
      state_ == StreamState::kStreaming || state_ == StreamState::kHover || state_ == StreamState::kReady;
  if (!sending) {
    last_v_ned_.setZero();
    last_follower_utime_ = -1;
    return std::nullopt;
  }
  const bool due = last_sent_us_ < 0 || mono_us - last_sent_us_ >= period_us_ || state_ != before;
  if (!due && !(force && state_ == StreamState::kStreaming)) return std::nullopt;
  SetPositionTargetLocalNed t = state_ == StreamState::kStreaming ? follower_target(mono_us) : hover_target();
  last_sent_us_ = mono_us;
  ++sent_;
  return t;
}

SetPositionTargetLocalNed OffboardStreamer::hover_target() {
  SetPositionTargetLocalNed t;
  t.coordinate_frame = mavlink::kMavFrameLocalNed;
  t.type_mask = mavlink::kTypemaskPositionIgnore | mavlink::kTypemaskAccelerationIgnore | mavlink::kTypemaskYawIgnore;
  last_v_ned_.setZero();
  last_follower_utime_ = -1;
  return t;  // zero velocity, zero yaw rate
}

SetPositionTargetLocalNed OffboardStreamer::follower_target(int64_t mono_us) {
  const wingman::setpoint_t& sp = *setpoint_;
  const bool enu = sp.frame == wingman::own_pose_t::FRAME_ENU;
  SetPositionTargetLocalNed t;
  t.coordinate_frame = mavlink::kMavFrameLocalNed;
  if (sp.mode == wingman::setpoint_t::MODE_POSITION) {
    Eigen::Vector3d p = geometry::to_vector3(sp.position);
    if (enu) p = geometry::swap_ned_enu(p);
    const double up = std::clamp(-p.z(), o_.min_altitude_m, o_.max_altitude_m);
    if (up != -p.z())
      refuse("altitude_clamped", "a position setpoint outside limits.min_altitude_m..max_altitude_m was clamped");
    p.z() = -up;
    t.x = static_cast<float>(p.x());
    t.y = static_cast<float>(p.y());
    t.z = static_cast<float>(p.z());
    t.yaw = static_cast<float>(enu ? geometry::swap_ned_enu_yaw(sp.yaw) : sp.yaw);
    t.type_mask =
        mavlink::kTypemaskVelocityIgnore | mavlink::kTypemaskAccelerationIgnore | mavlink::kTypemaskYawRateIgnore;
    last_v_ned_.setZero();
    last_follower_utime_ = -1;
    return t;
  }
  Eigen::Vector3d v = geometry::to_vector3(sp.velocity);
  if (enu) v = geometry::swap_ned_enu(v);
  // Speeds.
  const double h = std::hypot(v.x(), v.y());
  if (h > o_.max_horizontal_speed_mps) {
    v.x() *= o_.max_horizontal_speed_mps / h;
    v.y() *= o_.max_horizontal_speed_mps / h;
    refuse("speed_clamped", "a horizontal speed above limits.max_horizontal_speed_mps was clamped");
  }
  if (std::abs(v.z()) > o_.max_vertical_speed_mps) {
    v.z() = std::copysign(o_.max_vertical_speed_mps, v.z());
    refuse("speed_clamped", "a vertical speed above limits.max_vertical_speed_mps was clamped");
  }
  // Acceleration: the commanded velocity moves towards v by at most max_acceleration * dt per sent setpoint, dt on the
  // setpoints' message times (the follower's clock, not the arrival: a burst of late setpoints is not an acceleration,
  // and a simulation runs the same at any speed); a resend of the same setpoint moves it no further. After a send that
  // was not the follower's (hover, ready), one stream period.
  const int64_t dt_us =
      last_follower_utime_ < 0 ? period_us_ : std::clamp<int64_t>(sp.utime - last_follower_utime_, 0, 2 * period_us_);
  const double dt_s = dt_us * 1e-6;
  const Eigen::Vector3d dv = v - last_v_ned_;
  const double max_dv = o_.max_acceleration_mps2 * dt_s;
  if (dv.norm() > max_dv + 1e-9) {
    v = last_v_ned_ + dv * (max_dv / dv.norm());
    refuse("acceleration_clamped", "a velocity change faster than limits.max_acceleration_mps2 was limited");
  }
  // Altitude band, after the acceleration limit (it stops at once): no further down below the band, no further up
  // above it (NED: z down).
  if (std::isfinite(altitude_m_) &&
      ((altitude_m_ <= o_.min_altitude_m && v.z() > 0) || (altitude_m_ >= o_.max_altitude_m && v.z() < 0))) {
    v.z() = 0;
    refuse("altitude_clamped", "a vertical speed out of limits.min_altitude_m..max_altitude_m was set to 0");
  }
  last_v_ned_ = v;
  last_follower_utime_ = std::max(last_follower_utime_, sp.utime);
  t.vx = static_cast<float>(v.x());
  t.vy = static_cast<float>(v.y());
  t.vz = static_cast<float>(v.z());
  t.yaw_rate = static_cast<float>(enu ? -sp.yaw_rate : sp.yaw_rate);
  t.type_mask = mavlink::kTypemaskPositionIgnore | mavlink::kTypemaskAccelerationIgnore | mavlink::kTypemaskYawIgnore;
  return t;
}

}  // namespace wingman::mavlink_bridge
