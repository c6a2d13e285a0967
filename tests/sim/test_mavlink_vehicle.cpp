// SPDX-License-Identifier: MIT
// The simulated autopilot's MAVLink rules: PX4 OFFBOARD gating and stream loss, ArduPilot GUIDED and its velocity
// timeout, TIMESYNC, message intervals, commands, telemetry in NED.
#include <gtest/gtest.h>
#include <wingman/geometry/ned_enu.hpp>
#include <wingman/mavlink/enums.hpp>
#include <wingman/mavlink/parser.hpp>
#include <wingman/own_pose_t.hpp>
#include <wingman/sim/mavlink_vehicle.hpp>
#include <wingman/sim/sim_options.hpp>

#include <cmath>
#include <vector>

namespace {

using namespace wingman;
using namespace wingman::mavlink;
using sim::MavlinkVehicle;
using sim::MavlinkVehicleOptions;
using sim::VehicleOutput;

constexpr int64_t kStart = 1767225600000000;  // the scenarios' start_utime
constexpr int64_t kFrameUs = 33333;

/// `msg` as the companion (system 1, component 191) sends it, parsed back into a frame.
template <class Msg>
Frame frame_of(const Msg& msg) {
  const std::vector<uint8_t> bytes = encode(msg, Sender{1, 191, 0});
  std::vector<Frame> frames;
  Parser parser;
  parser.feed(bytes.data(), bytes.size(), [&](const Frame& f) { frames.push_back(f); });
  EXPECT_EQ(frames.size(), 1u);
  return frames.at(0);
}

/// The frames of `out` decoded: every message of type Msg.
template <class Msg>
std::vector<Msg> sent(const VehicleOutput& out) {
  std::vector<Msg> msgs;
  Parser parser;
  for (const auto& bytes : out.frames) {
    parser.feed(bytes.data(), bytes.size(), [&](const Frame& f) {
      Msg m;
      if (decode(f, m)) msgs.push_back(m);
    });
  }
  return msgs;
}

SetPositionTargetLocalNed velocity_target(float vn, float ve, float vd) {
  SetPositionTargetLocalNed t;
  t.target_system = 1;
  t.target_component = 1;
  t.coordinate_frame = kMavFrameLocalNed;
  t.type_mask = kTypemaskPositionIgnore | kTypemaskAccelerationIgnore | kTypemaskYawIgnore;
  t.vx = vn;
  t.vy = ve;
  t.vz = vd;
  t.yaw_rate = 0.1f;
  return t;
}

CommandLong set_mode(uint32_t mode) {
  CommandLong c;
  c.target_system = 1;
  c.target_component = 1;
  c.command = kMavCmdDoSetMode;
  c.param1 = kMavModeFlagCustomModeEnabled;
  c.param2 = static_cast<float>(mode);
  return c;
}

MavlinkVehicleOptions options(const std::string& firmware, double pilot_engage_s = -1) {
  MavlinkVehicleOptions o;
  o.firmware = firmware;
  o.pilot_engage_s = pilot_engage_s;
  return o;
}

sim::MultirotorState hovering() {
  sim::MultirotorState s;
  s.p_body_in_world = Eigen::Vector3d(1, 2, 11);  // east, north, up
  s.v_body_in_world = Eigen::Vector3d(0.5, -0.25, 0.1);
  return s;
}

TEST(MavlinkVehicleOptions, DefaultsAreValidAndBadValuesNameTheKey) {
  EXPECT_TRUE(MavlinkVehicleOptions{}.validate().empty());
  MavlinkVehicleOptions o;
  o.firmware = "inav";
  o.streams = {"odometry", "gps_raw_int"};
  o.url = "/dev/ttyACM0";
  o.px4_offboard_loss_timeout_s = 0;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 4u);
  EXPECT_NE(p[0].find("mavlink.url"), std::string::npos) << p[0];
  EXPECT_NE(p[1].find("mavlink.firmware"), std::string::npos) << p[1];
  EXPECT_NE(p[2].find("mavlink.px4_offboard_loss_timeout_s"), std::string::npos) << p[2];
  EXPECT_NE(p[3].find("mavlink.streams = 'gps_raw_int'"), std::string::npos) << p[3];
  EXPECT_THROW(MavlinkVehicle(o, kStart), std::invalid_argument);
}

TEST(MavlinkVehicleOptions, TheSimulatorsAutopilotKeyIsLcmOrMavlinkAndItsMavlinkKeysAreChecked) {
  wingman::sim::SimOptions o;
  EXPECT_EQ(o.autopilot, "lcm") << "the default stays LCM";
  EXPECT_TRUE(o.validate().empty());
  o.autopilot = "px4";
  o.mavlink.system_id = 0;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 2u);
  EXPECT_NE(p[0].find("autopilot = 'px4'"), std::string::npos) << p[0];
  EXPECT_NE(p[1].find("mavlink.system_id"), std::string::npos) << p[1];
}

TEST(MavlinkVehiclePx4, OffboardIsRefusedWithoutASetpointStreamAndAcceptedWithOne) {
  MavlinkVehicle v(options("px4"), kStart);
  VehicleOutput out;
  v.on_frame(frame_of(set_mode(kPx4MainModeOffboard)), kStart, out);
  auto acks = sent<CommandAck>(out);
  ASSERT_EQ(acks.size(), 1u);
  EXPECT_EQ(acks[0].command, kMavCmdDoSetMode);
  EXPECT_EQ(acks[0].result, kMavResultTemporarilyRejected);
  EXPECT_FALSE(v.engaged());
  EXPECT_EQ(v.counts().mode_refusals, 1);

  // A setpoint while in POSCTL: not flown, but it is the stream PX4 wants before OFFBOARD.
  out = {};
  v.on_frame(frame_of(velocity_target(1, 2, -0.5f)), kStart + kFrameUs, out);
  EXPECT_TRUE(out.commands.empty());
  EXPECT_EQ(v.counts().setpoints_ignored, 1);
  v.on_frame(frame_of(set_mode(kPx4MainModeOffboard)), kStart + 2 * kFrameUs, out);
  acks = sent<CommandAck>(out);
  ASSERT_EQ(acks.size(), 1u);
  EXPECT_EQ(acks[0].result, kMavResultAccepted);
  EXPECT_TRUE(v.engaged());
  EXPECT_EQ(v.mode_name(), "OFFBOARD");
  // The newest setpoint is flown from the engagement on, in NED, stamped with the simulated time.
  ASSERT_EQ(out.commands.size(), 1u);
  EXPECT_EQ(+out.commands[0].mode, +setpoint_t::MODE_VELOCITY);
  EXPECT_EQ(+out.commands[0].frame, +own_pose_t::FRAME_NED);
  EXPECT_EQ(out.commands[0].utime, kStart + 2 * kFrameUs);
  EXPECT_FLOAT_EQ(out.commands[0].velocity[0], 1.0);
  EXPECT_FLOAT_EQ(out.commands[0].velocity[1], 2.0);
  EXPECT_FLOAT_EQ(out.commands[0].velocity[2], -0.5);
  // The mode change is announced at once.
  const auto hbs = sent<Heartbeat>(out);
  ASSERT_EQ(hbs.size(), 1u);
  EXPECT_EQ(px4_main_mode(hbs[0].custom_mode), kPx4MainModeOffboard);
  EXPECT_EQ(hbs[0].autopilot, kMavAutopilotPx4);
  EXPECT_TRUE(hbs[0].base_mode & kMavModeFlagSafetyArmed);
}

TEST(MavlinkVehiclePx4, TheStreamStoppingLeavesOffboardForPosctlAndHolds) {
  MavlinkVehicleOptions o = options("px4", 0.0);  // the pilot engages as soon as PX4 accepts
  MavlinkVehicle v(o, kStart);
  VehicleOutput out;
  v.on_frame_time(kStart, hovering(), out);
  EXPECT_FALSE(v.engaged()) << "no stream yet";
  v.on_frame(frame_of(velocity_target(0, 1, 0)), kStart, out);
  v.on_frame_time(kStart + kFrameUs, hovering(), out);
  EXPECT_TRUE(v.engaged());
  // Setpoints every frame keep it in OFFBOARD.
  int64_t t = kStart + kFrameUs;
  for (int i = 0; i < 30; ++i, t += kFrameUs) {
    out = {};
    v.on_frame(frame_of(velocity_target(0, 1, 0)), t, out);
    ASSERT_EQ(out.commands.size(), 1u);
    v.on_frame_time(t + kFrameUs, hovering(), out);
    ASSERT_TRUE(v.engaged()) << "frame " << i;
  }
  // Then nothing: OFFBOARD is kept up to the loss timeout (1 s) and left after it.
  const int64_t last = t - kFrameUs;
  out = {};
  v.on_frame_time(last + 1000000, hovering(), out);
  EXPECT_TRUE(v.engaged());
  v.on_frame_time(last + 1000000 + kFrameUs, hovering(), out);
  EXPECT_FALSE(v.engaged());
  EXPECT_EQ(v.mode_name(), "POSCTL");
  EXPECT_EQ(v.counts().offboard_lost, 1);
  ASSERT_EQ(out.commands.size(), 1u);
  EXPECT_EQ(+out.commands[0].mode, +setpoint_t::MODE_HOLD);
  const auto hbs = sent<Heartbeat>(out);
  ASSERT_EQ(hbs.size(), 1u);
  EXPECT_EQ(px4_main_mode(hbs[0].custom_mode), kPx4MainModePosctl);
  // A new setpoint does not bring OFFBOARD back: the pilot engaged once.
  out = {};
  v.on_frame(frame_of(velocity_target(0, 1, 0)), last + 1100000, out);
  v.on_frame_time(last + 1100000, hovering(), out);
  EXPECT_FALSE(v.engaged());
  EXPECT_TRUE(out.commands.empty());
}

TEST(MavlinkVehicleArdupilot, GuidedIsAcceptedAtOnceAndAnOldVelocitySetpointStopsTheVehicle) {
  MavlinkVehicle v(options("ardupilot"), kStart);
  VehicleOutput out;
  v.on_frame(frame_of(set_mode(kCopterModeGuided)), kStart, out);
  ASSERT_EQ(sent<CommandAck>(out).size(), 1u);
  EXPECT_EQ(sent<CommandAck>(out)[0].result, kMavResultAccepted);
  EXPECT_TRUE(v.engaged());
  EXPECT_EQ(v.mode_name(), "GUIDED");
  ASSERT_EQ(out.commands.size(), 1u);
  EXPECT_EQ(+out.commands[0].mode, +setpoint_t::MODE_HOLD) << "GUIDED holds until a setpoint comes";
  EXPECT_EQ(sent<Heartbeat>(out).at(0).custom_mode, kCopterModeGuided);
  EXPECT_EQ(sent<Heartbeat>(out).at(0).autopilot, kMavAutopilotArdupilotmega);

  out = {};
  v.on_frame(frame_of(velocity_target(1, 0, 0)), kStart + kFrameUs, out);
  ASSERT_EQ(out.commands.size(), 1u);
  EXPECT_EQ(+out.commands[0].mode, +setpoint_t::MODE_VELOCITY);
  // GUID_TIMEOUT (3 s): at 3 s it still flies, after it stops, still in GUIDED.
  out = {};
  v.on_frame_time(kStart + kFrameUs + 3000000, hovering(), out);
  EXPECT_TRUE(out.commands.empty());
  v.on_frame_time(kStart + 2 * kFrameUs + 3000000, hovering(), out);
  ASSERT_EQ(out.commands.size(), 1u);
  EXPECT_EQ(+out.commands[0].mode, +setpoint_t::MODE_HOLD);
  EXPECT_TRUE(v.engaged());
  EXPECT_EQ(v.counts().guided_timeouts, 1);

  // A position setpoint does not time out.
  SetPositionTargetLocalNed p;
  p.target_system = 1;
  p.coordinate_frame = kMavFrameLocalNed;
  p.type_mask = kTypemaskVelocityIgnore | kTypemaskAccelerationIgnore | kTypemaskYawRateIgnore;
  p.x = 3;
  p.y = 4;
  p.z = -12;
  p.yaw = 1.0f;
  out = {};
  v.on_frame(frame_of(p), kStart + 10000000, out);
  ASSERT_EQ(out.commands.size(), 1u);
  EXPECT_EQ(+out.commands[0].mode, +setpoint_t::MODE_POSITION);
  EXPECT_FLOAT_EQ(out.commands[0].position[2], -12.0);
  out = {};
  v.on_frame_time(kStart + 20000000, hovering(), out);
  EXPECT_TRUE(out.commands.empty());
  // LOITER leaves GUIDED and holds; setpoints are ignored there.
  v.on_frame(frame_of(set_mode(kCopterModeLoiter)), kStart + 20000000, out);
  EXPECT_FALSE(v.engaged());
  ASSERT_EQ(out.commands.size(), 1u);
  EXPECT_EQ(+out.commands[0].mode, +setpoint_t::MODE_HOLD);
  out = {};
  v.on_frame(frame_of(velocity_target(1, 0, 0)), kStart + 20100000, out);
  EXPECT_TRUE(out.commands.empty());
  EXPECT_EQ(v.counts().setpoints_ignored, 1);
}

TEST(MavlinkVehicle, SetpointsItCannotFlyAreRefusedAndCounted) {
  MavlinkVehicle v(options("ardupilot", 0.0), kStart);
  VehicleOutput out;
  v.on_frame_time(kStart, hovering(), out);
  ASSERT_TRUE(v.engaged());
  out = {};
  SetPositionTargetLocalNed bad_frame = velocity_target(1, 0, 0);
  bad_frame.coordinate_frame = kMavFrameBodyFrd;
  SetPositionTargetLocalNed bad_mask = velocity_target(1, 0, 0);
  bad_mask.type_mask = 0;  // everything at once: not simulated
  SetPositionTargetLocalNed not_finite = velocity_target(NAN, 0, 0);
  SetPositionTargetLocalNed other_vehicle = velocity_target(1, 0, 0);
  other_vehicle.target_system = 7;
  for (const auto& t : {bad_frame, bad_mask, not_finite, other_vehicle}) v.on_frame(frame_of(t), kStart, out);
  EXPECT_TRUE(out.commands.empty());
  EXPECT_EQ(v.counts().setpoints_refused, 3);  // the one for system 7 is not ours: not counted
  EXPECT_EQ(v.counts().setpoints_applied, 0);
}

TEST(MavlinkVehicle, TheBootClockTimesyncAndTheTelemetryAreInSimulatedTimeAndNed) {
  MavlinkVehicleOptions o = options("px4");
  o.boot_before_start_s = 60;
  MavlinkVehicle v(o, kStart);
  EXPECT_EQ(v.boot_epoch_utime(), kStart - 60000000);
  VehicleOutput out;
  // A request: answered with the companion's clock taken as the simulation's epoch clock.
  Timesync req;
  req.ts1 = (kStart + 5000000) * 1000;
  v.on_frame(frame_of(req), kStart, out);
  auto ts = sent<Timesync>(out);
  ASSERT_EQ(ts.size(), 1u);
  EXPECT_EQ(ts[0].ts1, req.ts1);
  EXPECT_EQ(ts[0].tc1, 65000000000LL) << "65 s after the boot";
  EXPECT_EQ(ts[0].target_system, 1);
  EXPECT_EQ(ts[0].target_component, 191);
  // Our own request and its answer: the barrier.
  out = {};
  const int64_t ts1 = v.ping(kStart + kFrameUs, out);
  ASSERT_EQ(sent<Timesync>(out).size(), 1u);
  EXPECT_EQ(sent<Timesync>(out)[0].tc1, 0);
  Timesync answer;
  answer.tc1 = 123;
  answer.ts1 = ts1;
  answer.target_system = 1;
  out = {};
  v.on_frame(frame_of(answer), kStart + kFrameUs, out);
  ASSERT_TRUE(out.pong_ts1.has_value());
  EXPECT_EQ(*out.pong_ts1, ts1);

  // The default streams: attitude and local position, every frame; odometry once asked for; attitude switched off.
  out = {};
  const int64_t t = kStart + 2000000 + 500;
  v.on_frame_time(t, hovering(), out);
  ASSERT_EQ(sent<LocalPositionNed>(out).size(), 1u);
  ASSERT_EQ(sent<AttitudeQuaternion>(out).size(), 1u);
  EXPECT_TRUE(sent<Odometry>(out).empty());
  const LocalPositionNed lp = sent<LocalPositionNed>(out)[0];
  EXPECT_EQ(lp.time_boot_ms, 62000u);
  EXPECT_FLOAT_EQ(lp.x, 2.0f);    // north
  EXPECT_FLOAT_EQ(lp.y, 1.0f);    // east
  EXPECT_FLOAT_EQ(lp.z, -11.0f);  // down
  EXPECT_FLOAT_EQ(lp.vx, -0.25f);
  EXPECT_FLOAT_EQ(lp.vy, 0.5f);
  EXPECT_FLOAT_EQ(lp.vz, -0.1f);
  // A level vehicle heading east (ENU yaw 0) is at NED yaw pi/2.
  const auto att = sent<AttitudeQuaternion>(out)[0];
  const Eigen::Quaterniond q(att.q1, att.q2, att.q3, att.q4);
  const Eigen::Vector3d fwd = q * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(fwd.y(), 1.0, 1e-6) << "body forward points east";

  CommandLong odo;
  odo.target_system = 1;
  odo.target_component = 1;
  odo.command = kMavCmdSetMessageInterval;
  odo.param1 = static_cast<float>(Odometry::kId);
  odo.param2 = 20000;
  CommandLong att_off = odo;
  att_off.param1 = static_cast<float>(AttitudeQuaternion::kId);
  att_off.param2 = -1;
  CommandLong unknown = odo;
  unknown.param1 = 24;  // GPS_RAW_INT: not simulated
  out = {};
  for (const auto& c : {odo, att_off, unknown}) v.on_frame(frame_of(c), t, out);
  const auto acks = sent<CommandAck>(out);
  ASSERT_EQ(acks.size(), 3u);
  EXPECT_EQ(acks[0].result, kMavResultAccepted);
  EXPECT_EQ(acks[1].result, kMavResultAccepted);
  EXPECT_EQ(acks[2].result, kMavResultUnsupported);
  out = {};
  v.on_frame_time(t + kFrameUs, hovering(), out);
  EXPECT_TRUE(sent<AttitudeQuaternion>(out).empty());
  ASSERT_EQ(sent<Odometry>(out).size(), 1u);
  const Odometry od = sent<Odometry>(out)[0];
  EXPECT_EQ(od.time_usec, static_cast<uint64_t>(62000500 + kFrameUs)) << "microseconds of the boot clock";
  EXPECT_EQ(od.frame_id, kMavFrameLocalNed);
  EXPECT_EQ(od.child_frame_id, kMavFrameBodyFrd);
  EXPECT_TRUE(std::isnan(od.pose_covariance[0]));
  // Body FRD velocity of a vehicle heading east: forward = east (0.5), right = south (0.25), down (-0.1).
  EXPECT_NEAR(od.vx, 0.5, 1e-6);
  EXPECT_NEAR(od.vy, 0.25, 1e-6);
  EXPECT_NEAR(od.vz, -0.1, 1e-6);
  // A disarm in the air is denied.
  CommandLong disarm;
  disarm.target_system = 1;
  disarm.command = kMavCmdComponentArmDisarm;
  disarm.param1 = 0;
  out = {};
  v.on_frame(frame_of(disarm), t, out);
  EXPECT_EQ(sent<CommandAck>(out).at(0).result, kMavResultDenied);
}

TEST(MavlinkVehicle, ThePilotEngagesNotBeforeItsTime) {
  MavlinkVehicle v(options("ardupilot", 1.0), kStart);
  VehicleOutput out;
  v.on_frame_time(kStart + 999999, hovering(), out);
  EXPECT_FALSE(v.engaged());
  v.on_frame_time(kStart + 1000000, hovering(), out);
  EXPECT_TRUE(v.engaged());
}

}  // namespace
