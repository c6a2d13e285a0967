// SPDX-License-Identifier: MIT
// The simulated autopilot's MAVLink side: modes, setpoints, telemetry, TIMESYNC, commands.
#include "wingman/sim/mavlink_vehicle.hpp"

#include <wingman/common/config.hpp>
#include <wingman/geometry/ned_enu.hpp>
#include <wingman/mavlink/enums.hpp>
#include <wingman/own_pose_t.hpp>

#include <fmt/format.h>

#include <cmath>
#include <set>
#include <stdexcept>

namespace wingman::sim {

using namespace wingman::mavlink;
using common::problem;

namespace {

constexpr uint16_t kVelocityYawRateMask = kTypemaskPositionIgnore | kTypemaskAccelerationIgnore | kTypemaskYawIgnore;
constexpr uint16_t kPositionYawMask = kTypemaskVelocityIgnore | kTypemaskAccelerationIgnore | kTypemaskYawRateIgnore;
constexpr uint32_t kPx4OffboardMode = px4_custom_mode(kPx4MainModeOffboard);
constexpr uint32_t kPx4PosctlMode = px4_custom_mode(kPx4MainModePosctl);

uint32_t stream_id(const std::string& name) {
  if (name == "attitude_quaternion") return AttitudeQuaternion::kId;
  if (name == "local_position_ned") return LocalPositionNed::kId;
  if (name == "odometry") return Odometry::kId;
  return 0;
}

int64_t us(double s) { return static_cast<int64_t>(std::llround(s * 1e6)); }

}  // namespace

std::vector<std::string> MavlinkVehicleOptions::validate() const {
  std::vector<std::string> p;
  if (url.rfind("udp://", 0) != 0 || url.find(':', 6) == std::string::npos || url.size() <= 7)
    p.push_back(problem("mavlink.url", url, "must be udp://HOST:PORT"));
  if (system_id < 1 || system_id > 255) p.push_back(problem("mavlink.system_id", system_id, "must be in 1..255"));
  if (component_id < 1 || component_id > 255)
    p.push_back(problem("mavlink.component_id", component_id, "must be in 1..255"));
  if (firmware != "px4" && firmware != "ardupilot")
    p.push_back(problem("mavlink.firmware", firmware, "must be px4 or ardupilot"));
  if (!(boot_before_start_s >= 0 && boot_before_start_s <= 1e6))
    p.push_back(problem("mavlink.boot_before_start_s", boot_before_start_s, "must be in [0, 1e6]"));
  if (!(px4_offboard_loss_timeout_s > 0 && px4_offboard_loss_timeout_s <= 60))
    p.push_back(problem("mavlink.px4_offboard_loss_timeout_s", px4_offboard_loss_timeout_s, "must be in (0, 60]"));
  if (!(ardupilot_guided_timeout_s > 0 && ardupilot_guided_timeout_s <= 60))
    p.push_back(problem("mavlink.ardupilot_guided_timeout_s", ardupilot_guided_timeout_s, "must be in (0, 60]"));
  if (!std::isfinite(pilot_engage_s) || pilot_engage_s > 1e6)
    p.push_back(problem("mavlink.pilot_engage_s", pilot_engage_s, "must be a number of seconds (< 0: never)"));
  std::set<std::string> seen;
  for (const auto& s : streams) {
    if (stream_id(s) == 0)
      p.push_back(problem("mavlink.streams", s, "must be attitude_quaternion, local_position_ned or odometry"));
    else if (!seen.insert(s).second)
      p.push_back(problem("mavlink.streams", s, "listed twice"));
  }
  if (!(heartbeat_period_s > 0 && heartbeat_period_s <= 10))
    p.push_back(problem("mavlink.heartbeat_period_s", heartbeat_period_s, "must be in (0, 10]"));
  return p;
}

MavlinkVehicle::MavlinkVehicle(const MavlinkVehicleOptions& options, int64_t start_utime)
    : o_(options), boot_epoch_utime_(start_utime - us(options.boot_before_start_s)), start_utime_(start_utime) {
  if (const auto problems = o_.validate(); !problems.empty())
    throw std::invalid_argument(fmt::format("{}", fmt::join(problems, "; ")));
  for (const auto& s : o_.streams) intervals_us_[stream_id(s)] = 0;
}

template <class Msg>
void MavlinkVehicle::send(const Msg& msg, VehicleOutput& out) {
  out.frames.push_back(
      encode(msg, Sender{static_cast<uint8_t>(o_.system_id), static_cast<uint8_t>(o_.component_id), seq_++}));
}

std::string MavlinkVehicle::mode_name() const {
  if (o_.px4()) return engaged_ ? "OFFBOARD" : "POSCTL";
  return engaged_ ? "GUIDED" : "LOITER";
}

void MavlinkVehicle::heartbeat(VehicleOutput& out) {
  Heartbeat hb;
  hb.type = kMavTypeQuadrotor;
  hb.autopilot = o_.px4() ? kMavAutopilotPx4 : kMavAutopilotArdupilotmega;
  hb.base_mode = static_cast<uint8_t>(kMavModeFlagCustomModeEnabled | kMavModeFlagSafetyArmed);
  hb.custom_mode =
      o_.px4() ? (engaged_ ? kPx4OffboardMode : kPx4PosctlMode) : (engaged_ ? kCopterModeGuided : kCopterModeLoiter);
  hb.system_status = kMavStateActive;
  send(hb, out);
}

int64_t MavlinkVehicle::ping(int64_t now_utime, VehicleOutput& out) {
  Timesync t;
  // Our boot time in ns, made unique per request (a TIMESYNC request carries the requester's clock).
  t.ts1 = (now_utime - boot_epoch_utime_) * 1000 + (++pings_ % 1000);
  send(t, out);
  return t.ts1;
}

void MavlinkVehicle::hold(int64_t now_utime, VehicleOutput& out) {
  wingman::setpoint_t sp{};
  sp.utime = now_utime;
  sp.mode = wingman::setpoint_t::MODE_HOLD;
  sp.frame = wingman::own_pose_t::FRAME_NED;
  out.commands.push_back(sp);
  velocity_since_utime_.reset();
}

bool MavlinkVehicle::request_engage(int64_t now_utime, VehicleOutput& out) {
  if (engaged_) return true;
  if (o_.px4()) {
    // PX4 refuses OFFBOARD without a current setpoint stream.
    if (!last_setpoint_utime_ || now_utime - *last_setpoint_utime_ > us(o_.px4_offboard_loss_timeout_s) ||
        !last_setpoint_) {
      ++counts_.mode_refusals;
      return false;
    }
    engaged_ = true;
    out.commands.push_back(*last_setpoint_);  // the newest setpoint is flown from now on
    out.commands.back().utime = now_utime;
    if (last_setpoint_->mode == wingman::setpoint_t::MODE_VELOCITY) velocity_since_utime_ = now_utime;
  } else {
    engaged_ = true;  // GUIDED holds until a setpoint comes
    hold(now_utime, out);
  }
  heartbeat(out);
  return true;
}

void MavlinkVehicle::disengage(int64_t now_utime, VehicleOutput& out) {
  if (!engaged_) return;
  engaged_ = false;
  hold(now_utime, out);
  heartbeat(out);
}

void MavlinkVehicle::on_setpoint(const Frame& f, int64_t now_utime, VehicleOutput& out) {
  SetPositionTargetLocalNed t;
  decode(f, t);
  if (t.target_system != 0 && t.target_system != o_.system_id) return;  // for another vehicle
  wingman::setpoint_t sp{};
  sp.utime = now_utime;
  sp.frame = wingman::own_pose_t::FRAME_NED;
  if (t.coordinate_frame != kMavFrameLocalNed) {
    ++counts_.setpoints_refused;
    return;
  }
  if (t.type_mask == kVelocityYawRateMask) {
    sp.mode = wingman::setpoint_t::MODE_VELOCITY;
    sp.velocity[0] = t.vx;
    sp.velocity[1] = t.vy;
    sp.velocity[2] = t.vz;
    sp.yaw_rate = t.yaw_rate;
  } else if (t.type_mask == kPositionYawMask) {
    sp.mode = wingman::setpoint_t::MODE_POSITION;
    sp.position[0] = t.x;
    sp.position[1] = t.y;
    sp.position[2] = t.z;
    sp.yaw = t.yaw;
  } else {
    ++counts_.setpoints_refused;  // other combinations are not simulated
    return;
  }
  for (double v : {sp.velocity[0], sp.velocity[1], sp.velocity[2], sp.position[0], sp.position[1], sp.position[2],
                   sp.yaw, sp.yaw_rate}) {
    if (!std::isfinite(v)) {
      ++counts_.setpoints_refused;
      return;
    }
  }
  last_setpoint_utime_ = now_utime;
  last_setpoint_ = sp;
  if (!engaged_) {
    ++counts_.setpoints_ignored;
    return;
  }
  ++counts_.setpoints_applied;
  out.commands.push_back(sp);
  if (sp.mode == wingman::setpoint_t::MODE_VELOCITY)
    velocity_since_utime_ = now_utime;
  else
    velocity_since_utime_.reset();
}

void MavlinkVehicle::on_command(const Frame& f, int64_t now_utime, VehicleOutput& out) {
  CommandLong c;
  decode(f, c);
  if (c.target_system != 0 && c.target_system != o_.system_id) return;
  if (c.target_component != 0 && c.target_component != o_.component_id) return;
  CommandAck ack;
  ack.command = c.command;
  ack.target_system = f.sysid;
  ack.target_component = f.compid;
  ack.result = kMavResultUnsupported;
  switch (c.command) {
    case kMavCmdSetMessageInterval: {
      const uint32_t id = std::isfinite(c.param1) ? static_cast<uint32_t>(c.param1) : 0;
      if (id == AttitudeQuaternion::kId || id == LocalPositionNed::kId || id == Odometry::kId) {
        if (c.param2 < 0)
          intervals_us_.erase(id);  // -1: off
        else
          intervals_us_[id] = static_cast<int64_t>(c.param2);  // 0: the default (every frame), else the interval
        ack.result = kMavResultAccepted;
      } else {
        ack.result = kMavResultUnsupported;
      }
      break;
    }
    case kMavCmdDoSetMode: {
      const uint32_t mode = std::isfinite(c.param2) ? static_cast<uint32_t>(c.param2) : 0;
      const uint32_t engage = o_.px4() ? kPx4MainModeOffboard : kCopterModeGuided;
      const uint32_t hold_mode = o_.px4() ? kPx4MainModePosctl : kCopterModeLoiter;
      if (mode == engage) {
        ack.result = request_engage(now_utime, out) ? kMavResultAccepted : kMavResultTemporarilyRejected;
      } else if (mode == hold_mode) {
        disengage(now_utime, out);
        ack.result = kMavResultAccepted;
      } else {
        ack.result = kMavResultUnsupported;
      }
      break;
    }
    case kMavCmdComponentArmDisarm:
      ack.result = c.param1 >= 0.5f ? kMavResultAccepted : kMavResultDenied;  // in the air: no disarm
      break;
    default:
      break;
  }
  ++counts_.commands_answered;
  send(ack, out);
}

void MavlinkVehicle::on_frame(const Frame& f, int64_t now_utime, VehicleOutput& out) {
  switch (f.msgid) {
    case SetPositionTargetLocalNed::kId:
      on_setpoint(f, now_utime, out);
      return;
    case CommandLong::kId:
      on_command(f, now_utime, out);
      return;
    case Timesync::kId: {
      Timesync t;
      decode(f, t);
      if (t.tc1 == 0) {  // a request: the companion's clock is the simulation's epoch clock
        Timesync reply;
        reply.tc1 = t.ts1 - boot_epoch_utime_ * 1000;
        reply.ts1 = t.ts1;
        reply.target_system = f.sysid;
        reply.target_component = f.compid;
        send(reply, out);
        ++counts_.timesync_answered;
      } else if (t.target_system == 0 || t.target_system == o_.system_id) {
        out.pong_ts1 = t.ts1;
      }
      return;
    }
    default:
      return;  // HEARTBEAT of the companion and anything else: nothing to do
  }
}

bool MavlinkVehicle::due(uint32_t msgid, int64_t now_utime) {
  const auto it = intervals_us_.find(msgid);
  if (it == intervals_us_.end()) return false;
  const auto last = last_sent_utime_.find(msgid);
  if (last != last_sent_utime_.end() && now_utime - last->second < it->second) return false;
  last_sent_utime_[msgid] = now_utime;
  return true;
}

void MavlinkVehicle::on_frame_time(int64_t now_utime, const MultirotorState& state, VehicleOutput& out,
                                   const ReportedPoseUncertainty& uncertainty) {
  // Timeouts, judged on simulated time.
  if (engaged_ && o_.px4() &&
      (!last_setpoint_utime_ || now_utime - *last_setpoint_utime_ > us(o_.px4_offboard_loss_timeout_s))) {
    ++counts_.offboard_lost;
    disengage(now_utime, out);
  }
  if (engaged_ && !o_.px4() && velocity_since_utime_ &&
      now_utime - *velocity_since_utime_ > us(o_.ardupilot_guided_timeout_s)) {
    ++counts_.guided_timeouts;
    hold(now_utime, out);
  }
  // The pilot.
  if (!pilot_done_ && o_.pilot_engage_s >= 0 && now_utime >= start_utime_ + us(o_.pilot_engage_s)) {
    if (request_engage(now_utime, out)) pilot_done_ = true;
  }
  // Telemetry: NED world, FRD body, boot time.
  const int64_t boot_us = now_utime - boot_epoch_utime_;
  const Eigen::Vector3d p_ned = geometry::swap_ned_enu(state.p_body_in_world);
  const Eigen::Vector3d v_ned = geometry::swap_ned_enu(state.v_body_in_world);
  const Eigen::Quaterniond q_frd_to_ned = geometry::swap_ned_frd_enu_flu(state.q_body_to_world);
  // FLU -> FRD body rates: (x, -y, -z).
  const Eigen::Vector3d w_frd(state.w_body_in_body.x(), -state.w_body_in_body.y(), -state.w_body_in_body.z());
  if (due(Odometry::kId, now_utime)) {  // first: the companion takes it over the pair once seen
    Odometry m;
    m.time_usec = static_cast<uint64_t>(boot_us);
    m.frame_id = kMavFrameLocalNed;
    m.child_frame_id = kMavFrameBodyFrd;
    m.x = static_cast<float>(p_ned.x());
    m.y = static_cast<float>(p_ned.y());
    m.z = static_cast<float>(p_ned.z());
    m.q = {static_cast<float>(q_frd_to_ned.w()), static_cast<float>(q_frd_to_ned.x()),
           static_cast<float>(q_frd_to_ned.y()), static_cast<float>(q_frd_to_ned.z())};
    const Eigen::Vector3d v_frd = q_frd_to_ned.conjugate() * v_ned;
    m.vx = static_cast<float>(v_frd.x());
    m.vy = static_cast<float>(v_frd.y());
    m.vz = static_cast<float>(v_frd.z());
    m.rollspeed = static_cast<float>(w_frd.x());
    m.pitchspeed = static_cast<float>(w_frd.y());
    m.yawspeed = static_cast<float>(w_frd.z());
    m.pose_covariance.fill(0.0f);
    if (uncertainty.known) {  // upper triangle of the 6x6, row by row: x, y, z at 0, 6, 11; roll, pitch, yaw 15, 18, 20
      m.pose_covariance[0] = m.pose_covariance[6] = m.pose_covariance[11] =
          static_cast<float>(uncertainty.position_var_m2);
      m.pose_covariance[15] = m.pose_covariance[18] = m.pose_covariance[20] =
          static_cast<float>(uncertainty.attitude_var_rad2);
    } else {
      m.pose_covariance[0] = NAN;  // unknown
    }
    m.velocity_covariance.fill(0.0f);
    m.velocity_covariance[0] = NAN;
    send(m, out);
  }
  if (due(AttitudeQuaternion::kId, now_utime)) {
    AttitudeQuaternion m;
    m.time_boot_ms = static_cast<uint32_t>(boot_us / 1000);
    m.q1 = static_cast<float>(q_frd_to_ned.w());
    m.q2 = static_cast<float>(q_frd_to_ned.x());
    m.q3 = static_cast<float>(q_frd_to_ned.y());
    m.q4 = static_cast<float>(q_frd_to_ned.z());
    m.rollspeed = static_cast<float>(w_frd.x());
    m.pitchspeed = static_cast<float>(w_frd.y());
    m.yawspeed = static_cast<float>(w_frd.z());
    send(m, out);
  }
  if (due(LocalPositionNed::kId, now_utime)) {
    LocalPositionNed m;
    m.time_boot_ms = static_cast<uint32_t>(boot_us / 1000);
    m.x = static_cast<float>(p_ned.x());
    m.y = static_cast<float>(p_ned.y());
    m.z = static_cast<float>(p_ned.z());
    m.vx = static_cast<float>(v_ned.x());
    m.vy = static_cast<float>(v_ned.y());
    m.vz = static_cast<float>(v_ned.z());
    send(m, out);
  }
}

}  // namespace wingman::sim
