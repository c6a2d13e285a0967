// SPDX-License-Identifier: MIT
// Multirotor dynamics: first-order velocity response, speed/acceleration/yaw-rate limits, tilt under acceleration,
// setpoint frames ENU and NED, and MODE_HOLD.
#include <gtest/gtest.h>
#include <wingman/own_pose_t.hpp>
#include <wingman/setpoint_t.hpp>
#include <wingman/sim/multirotor.hpp>
#include <wingman/sim/vehicle_command.hpp>

#include "test_constants.hpp"

#include <cmath>

namespace {

using wingman::setpoint_t;
using wingman::sim::attitude_from_acceleration;
using wingman::sim::kGravity;
using wingman::sim::Multirotor;
using wingman::sim::MultirotorLimits;
using wingman::sim::VehicleCommand;
using wingman::testing::kDeg;

VehicleCommand velocity(const Eigen::Vector3d& v, double yaw_rate = 0.0) {
  VehicleCommand c;
  c.mode = VehicleCommand::Mode::kVelocity;
  c.v_ref_in_world = v;
  c.yaw_rate_ref = yaw_rate;
  return c;
}

VehicleCommand position(const Eigen::Vector3d& p, double yaw = 0.0) {
  VehicleCommand c;
  c.mode = VehicleCommand::Mode::kPosition;
  c.p_ref_in_world = p;
  c.yaw_ref_rad = yaw;
  return c;
}

double horizontal(const Eigen::Vector3d& v) { return std::hypot(v.x(), v.y()); }

TEST(MultirotorLimits, DefaultsAreValidAndBadValuesNameTheKey) {
  EXPECT_TRUE(MultirotorLimits{}.validate().empty());
  MultirotorLimits l;
  l.max_speed_xy = -1;
  l.step_s = 0.5;
  const auto p = l.validate("vehicles[1].dynamics.");
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[0], "vehicles[1].dynamics.max_speed_xy = -1: must be > 0");
  EXPECT_EQ(p[1], "vehicles[1].dynamics.step_s = 0.5: must be in (0, 0.1] seconds");
  EXPECT_THROW(Multirotor(l, Eigen::Vector3d::Zero(), 0.0), std::invalid_argument);
}

TEST(Multirotor, HoversAtItsInitialPoseBeforeAnyCommand) {
  Multirotor m(MultirotorLimits{}, Eigen::Vector3d(1, 2, 3), 0.5);
  m.advance(10.0);
  EXPECT_EQ(m.state().p_body_in_world, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(m.state().v_body_in_world, Eigen::Vector3d::Zero());
  EXPECT_DOUBLE_EQ(m.state().yaw_rad, 0.5);
}

TEST(Multirotor, VelocityStepResponseHasTheConfiguredTimeConstant) {
  MultirotorLimits l;
  l.velocity_time_constant_s = 0.3;
  l.max_accel_xy = 100;  // no acceleration clamp: a pure first-order response
  Multirotor m(l, Eigen::Vector3d::Zero(), 0.0);
  m.set_command(velocity({2.0, 0, 0}));
  m.advance(0.3);  // one time constant: 1 - 1/e of the step
  EXPECT_NEAR(m.state().v_body_in_world.x(), 2.0 * (1.0 - std::exp(-1.0)), 1e-9);
  m.advance(0.3);  // two time constants
  EXPECT_NEAR(m.state().v_body_in_world.x(), 2.0 * (1.0 - std::exp(-2.0)), 1e-9);
  // Position: integral of v = V (t - tau (1 - exp(-t / tau))); the steps are exact for piecewise-constant
  // acceleration, so the error is O(h^2) with h = 2 ms.
  const double t = 0.6, tau = 0.3;
  EXPECT_NEAR(m.state().p_body_in_world.x(), 2.0 * (t - tau * (1.0 - std::exp(-t / tau))), 1e-5);
  EXPECT_EQ(m.state().v_body_in_world.y(), 0.0);
}

TEST(Multirotor, SpeedAndAccelerationLimitsHoldForLargeCommands) {
  MultirotorLimits l;  // 5 m/s, 2 m/s vertical, 4 and 3 m/s^2
  Multirotor m(l, Eigen::Vector3d::Zero(), 0.0);
  m.set_command(velocity({30.0, -40.0, 20.0}));
  double max_speed_xy = 0, max_speed_z = 0;
  for (int i = 0; i < 2000; ++i) {
    m.step(0.005);
    const auto& s = m.state();
    max_speed_xy = std::max(max_speed_xy, horizontal(s.v_body_in_world));
    max_speed_z = std::max(max_speed_z, std::abs(s.v_body_in_world.z()));
    ASSERT_LE(horizontal(s.a_body_in_world), l.max_accel_xy + 1e-9) << "step " << i;
    ASSERT_LE(std::abs(s.a_body_in_world.z()), l.max_accel_z + 1e-9) << "step " << i;
  }
  EXPECT_LE(max_speed_xy, l.max_speed_xy + 1e-12);
  EXPECT_LE(max_speed_z, l.max_speed_z + 1e-12);
  EXPECT_NEAR(max_speed_xy, l.max_speed_xy, 1e-6);  // it does reach the limit
  EXPECT_NEAR(max_speed_z, l.max_speed_z, 1e-6);
  // The direction of the horizontal command is kept when the speed is clamped: (3, -4) / 5.
  EXPECT_NEAR(m.state().v_body_in_world.x(), 3.0, 1e-6);
  EXPECT_NEAR(m.state().v_body_in_world.y(), -4.0, 1e-6);
  // From rest to 5 m/s at 4 m/s^2 takes at least 1.25 s: the acceleration limit shapes the start.
  Multirotor m2(l, Eigen::Vector3d::Zero(), 0.0);
  m2.set_command(velocity({5.0, 0, 0}));
  m2.advance(0.5);
  EXPECT_NEAR(m2.state().v_body_in_world.x(), 2.0, 1e-9);  // 4 m/s^2 * 0.5 s, clamped all along
}

TEST(Multirotor, TiltsTowardsItsAccelerationByAtanOfAOverG) {
  // While the acceleration is clamped at max_accel_xy the tilt is atan(4 / 9.80665) = 22.19 degrees.
  for (double yaw_deg : {0.0, 90.0, -135.0}) {
    for (const Eigen::Vector3d& dir :
         {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(-0.6, 0.8, 0)}) {
      SCOPED_TRACE(testing::Message() << "yaw " << yaw_deg << " deg, direction " << dir.transpose());
      MultirotorLimits l;
      Multirotor m(l, Eigen::Vector3d::Zero(), yaw_deg * kDeg);
      m.set_command(velocity(5.0 * dir, 0.0));
      m.advance(0.2);
      const auto& s = m.state();
      ASSERT_NEAR(horizontal(s.a_body_in_world), l.max_accel_xy, 1e-9);
      const Eigen::Matrix3d R = s.q_body_to_world.toRotationMatrix();
      const Eigen::Vector3d z_body = R.col(2);
      const double tilt = std::acos(z_body.z());
      EXPECT_NEAR(tilt, std::atan(l.max_accel_xy / kGravity), 1e-9);
      EXPECT_NEAR(tilt / kDeg, 22.19, 0.01);
      // The thrust (body z) leans towards the acceleration: its horizontal part is along dir.
      EXPECT_NEAR(z_body.head<2>().normalized().dot(dir.head<2>()), 1.0, 1e-9);
      // The heading is kept while tilting: body y stays perpendicular to the heading direction, so body x lies in
      // the plane of the heading and the thrust (Mellinger and Kumar 2011).
      const Eigen::Vector3d heading(std::cos(yaw_deg * kDeg), std::sin(yaw_deg * kDeg), 0.0);
      EXPECT_NEAR(R.col(1).dot(heading), 0.0, 1e-12);
      EXPECT_GT(R.col(0).dot(heading), 0.9);
    }
  }
}

TEST(Multirotor, AForwardAccelerationPitchesTheNoseAndTheCameraDown) {
  // Heading north (yaw 90 deg), accelerating north: body x (and a forward camera's optical axis) dips below the
  // horizon by the tilt; a backward acceleration raises it.
  const Eigen::Quaterniond q_fwd = attitude_from_acceleration({0, 2.0, 0}, 90 * kDeg);
  const Eigen::Vector3d x_fwd = q_fwd * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(std::asin(-x_fwd.z()), std::atan(2.0 / kGravity), 1e-12);
  EXPECT_NEAR(x_fwd.x(), 0.0, 1e-12);
  const Eigen::Vector3d x_back = attitude_from_acceleration({0, -2.0, 0}, 90 * kDeg) * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(std::asin(x_back.z()), std::atan(2.0 / kGravity), 1e-12);
  // Accelerating to the left (west, heading north) rolls the left side down: body y dips.
  const Eigen::Vector3d y_left = attitude_from_acceleration({-2.0, 0, 0}, 90 * kDeg) * Eigen::Vector3d::UnitY();
  EXPECT_NEAR(std::asin(-y_left.z()), std::atan(2.0 / kGravity), 1e-12);
  // Level at rest, heading kept.
  const Eigen::Quaterniond q0 = attitude_from_acceleration(Eigen::Vector3d::Zero(), 30 * kDeg);
  EXPECT_TRUE(q0.isApprox(Eigen::Quaterniond(Eigen::AngleAxisd(30 * kDeg, Eigen::Vector3d::UnitZ())), 1e-12));
}

TEST(Multirotor, PositionCommandConvergesWithoutOvershoot) {
  Multirotor m(MultirotorLimits{}, Eigen::Vector3d::Zero(), 0.0);
  m.set_command(position({1.0, 0, 0}));  // small enough that no limit is reached: the linear loop, damping 1.02
  double max_x = 0;
  for (int i = 0; i < 5000; ++i) {
    m.step(0.002);
    max_x = std::max(max_x, m.state().p_body_in_world.x());
  }
  EXPECT_LE(max_x, 1.0 + 1e-9);
  EXPECT_NEAR(m.state().p_body_in_world.x(), 1.0, 1e-4);
}

TEST(Multirotor, YawTurnsTheShortWayWithinTheRateLimit) {
  MultirotorLimits l;
  Multirotor m(l, Eigen::Vector3d::Zero(), -179 * kDeg);
  m.set_command(position(Eigen::Vector3d::Zero(), 179 * kDeg));  // 2 degrees clockwise across +-180
  m.advance(5.0);
  EXPECT_NEAR(std::abs(m.state().yaw_rad), 179 * kDeg, 1e-5);  // 2 deg * exp(-gain 2 * 5 s)
  EXPECT_GT(m.state().yaw_rad, 0);
  // A quarter turn is limited to 90 deg/s: after 0.5 s at most 45 degrees.
  Multirotor m2(l, Eigen::Vector3d::Zero(), 0.0);
  m2.set_command(position(Eigen::Vector3d::Zero(), 90 * kDeg));
  m2.advance(0.5);
  EXPECT_NEAR(m2.state().yaw_rad, 45 * kDeg, 1e-9);
  EXPECT_NEAR(m2.state().w_body_in_body.z(), 90 * kDeg, 1e-6);
  // Velocity mode: the commanded rate, clamped.
  Multirotor m3(l, Eigen::Vector3d::Zero(), 0.0);
  m3.set_command(velocity(Eigen::Vector3d::Zero(), -10.0));
  m3.advance(0.25);
  EXPECT_NEAR(m3.state().yaw_rad, -22.5 * kDeg, 1e-9);
}

setpoint_t make_setpoint(int8_t mode, int8_t frame) {
  setpoint_t sp{};
  sp.utime = 1;
  sp.mode = mode;
  sp.frame = frame;
  return sp;
}

TEST(VehicleCommand, NedSetpointsMapToTheSameEnuCommands) {
  setpoint_t enu = make_setpoint(setpoint_t::MODE_POSITION, wingman::own_pose_t::FRAME_ENU);
  enu.position[0] = 1;  // east
  enu.position[1] = 2;  // north
  enu.position[2] = 3;  // up
  enu.yaw = 0.3;        // from east towards north
  setpoint_t ned = make_setpoint(setpoint_t::MODE_POSITION, wingman::own_pose_t::FRAME_NED);
  ned.position[0] = 2;       // north
  ned.position[1] = 1;       // east
  ned.position[2] = -3;      // down
  ned.yaw = M_PI / 2 - 0.3;  // from north towards east
  const VehicleCommand a = wingman::sim::command_from_setpoint(enu), b = wingman::sim::command_from_setpoint(ned);
  EXPECT_EQ(a.mode, VehicleCommand::Mode::kPosition);
  EXPECT_EQ(a.p_ref_in_world, b.p_ref_in_world);
  EXPECT_NEAR(a.yaw_ref_rad, b.yaw_ref_rad, 1e-15);

  setpoint_t venu = make_setpoint(setpoint_t::MODE_VELOCITY, wingman::own_pose_t::FRAME_ENU);
  venu.velocity[0] = 0.5;
  venu.velocity[1] = -1.0;
  venu.velocity[2] = 0.2;
  venu.yaw_rate = 0.4;  // counter-clockwise from above
  setpoint_t vned = make_setpoint(setpoint_t::MODE_VELOCITY, wingman::own_pose_t::FRAME_NED);
  vned.velocity[0] = -1.0;
  vned.velocity[1] = 0.5;
  vned.velocity[2] = -0.2;
  vned.yaw_rate = -0.4;  // NED yaw rate is clockwise from above
  const VehicleCommand c = wingman::sim::command_from_setpoint(venu), d = wingman::sim::command_from_setpoint(vned);
  EXPECT_EQ(c.mode, VehicleCommand::Mode::kVelocity);
  EXPECT_EQ(c.v_ref_in_world, d.v_ref_in_world);
  EXPECT_EQ(c.yaw_rate_ref, d.yaw_rate_ref);

  // Flown, the two give the same trajectory.
  Multirotor m1(MultirotorLimits{}, Eigen::Vector3d::Zero(), 0.0), m2(MultirotorLimits{}, Eigen::Vector3d::Zero(), 0.0);
  m1.set_command(c);
  m2.set_command(d);
  m1.advance(3.0);
  m2.advance(3.0);
  EXPECT_EQ(m1.state().p_body_in_world, m2.state().p_body_in_world);
  EXPECT_EQ(m1.state().yaw_rad, m2.state().yaw_rad);
  EXPECT_NEAR(m1.state().p_body_in_world.y(), -1.0 * (3.0 - 0.3 * (1 - std::exp(-10.0))), 0.02);

  setpoint_t bad = make_setpoint(7, wingman::own_pose_t::FRAME_ENU);
  EXPECT_THROW(wingman::sim::command_from_setpoint(bad), std::invalid_argument);
}

TEST(Multirotor, HoldKeepsThePositionWhereTheHoldBegan) {
  Multirotor m(MultirotorLimits{}, Eigen::Vector3d(0, 0, 5), 0.0);
  m.set_command(velocity({1.0, 0, 0}));
  m.advance(3.0);
  const Eigen::Vector3d p_hold = m.state().p_body_in_world;
  const double yaw_hold = m.state().yaw_rad;
  VehicleCommand hold;
  hold.mode = VehicleCommand::Mode::kHold;
  m.set_command(hold);
  m.advance(1.0);
  EXPECT_GT(m.state().p_body_in_world.x(), p_hold.x());  // it was still moving: it overshoots, then comes back
  m.set_command(hold);                                   // a hold after a hold keeps the first hold point
  m.advance(20.0);
  EXPECT_LT((m.state().p_body_in_world - p_hold).norm(), 1e-4);
  EXPECT_DOUBLE_EQ(m.state().yaw_rad, yaw_hold);
  // After another command, a new hold takes the new position.
  m.set_command(velocity({0, 1.0, 0}));
  m.advance(2.0);
  m.set_command(hold);
  EXPECT_EQ(m.command().p_ref_in_world, m.state().p_body_in_world);
}

}  // namespace
