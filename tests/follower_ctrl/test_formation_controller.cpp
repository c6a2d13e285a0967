// SPDX-License-Identifier: MIT
// The formation controller: offset, feed-forward, height modes and floor, avoidance, yaw towards the target.
#include "wingman/follower_ctrl/formation_controller.hpp"

#include "follower_test_helpers.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>

namespace {

using Eigen::Vector3d;
using wingman::follower_ctrl::FormationController;
using wingman::follower_ctrl::FormationOptions;
using wingman::follower_ctrl::LimitsOptions;
using wingman::follower_ctrl::OwnState;
using wingman::follower_ctrl::TargetState;
using wingman::follower_ctrl::VelocityCommand;

using namespace wingman::follower_ctrl::test;

FormationOptions fixed_height(double height_m) {
  FormationOptions o;
  o.height_mode = "fixed";
  o.height_m = height_m;
  return o;
}

/// Own state at kT0, measured 1 s earlier (so the acceleration limit from the measured velocity is wide).
OwnState own_at(const Vector3d& p, double yaw_rad = 0.0) {
  OwnState s;
  s.utime = kT0 - 1000000;
  s.p_body_in_world = p;
  s.R_body_to_world = Eigen::AngleAxisd(yaw_rad, Vector3d::UnitZ()).toRotationMatrix();
  return s;
}

TargetState target_at(const Vector3d& p, const Vector3d& v = Vector3d::Zero()) {
  TargetState t;
  t.track_id = 1;
  t.p_target_in_world = p;
  t.v_target_in_world = v;
  t.state_utime = kT0;
  t.source_utime = kT0;
  return t;
}

TEST(FormationController, OnStationTheCommandIsTheFeedForwardOfTheTargetVelocity) {
  FormationController c(fixed_height(10.0), wide_limits(), default_mount());
  // Default offset: 6 m south of the target.
  const VelocityCommand cmd = c.update(target_at({0, 0, 10}, {1.0, 0.5, 0.3}), own_at({0, -6, 10}), kT0, 0.0);
  EXPECT_VEC_NEAR(cmd.v_body_in_world, Vector3d(1.0, 0.5, 0.0), kTol) << "fixed height: the target's climb is ignored";
  EXPECT_FALSE(cmd.avoiding);

  FormationOptions half = fixed_height(10.0);
  half.feedforward_gain = 0.5;
  FormationController h(half, wide_limits(), default_mount());
  EXPECT_VEC_NEAR(h.update(target_at({0, 0, 10}, {1.0, 0.5, 0.3}), own_at({0, -6, 10}), kT0, 0.0).v_body_in_world,
                  Vector3d(0.5, 0.25, 0.0), kTol);

  FormationOptions follow_z;
  follow_z.height_mode = "target";
  follow_z.offset_m = {0.0, -6.0, 1.0};
  FormationController z(follow_z, wide_limits(), default_mount());
  EXPECT_VEC_NEAR(z.update(target_at({0, 0, 10}, {1.0, 0.5, 0.3}), own_at({0, -6, 11}), kT0, 0.0).v_body_in_world,
                  Vector3d(1.0, 0.5, 0.3), kTol);
}

TEST(FormationController, PositionErrorAddsKpTimesTheErrorToTheFeedForward) {
  FormationOptions o = fixed_height(10.0);
  o.kp = 0.8;
  FormationController c(o, wide_limits(), default_mount());
  // Own 1 m east of and 0.5 m below the formation point (0, -6, 10).
  const VelocityCommand cmd = c.update(target_at({0, 0, 10}, {1.0, 0.5, 0.0}), own_at({1, -6, 9.5}), kT0, 0.0);
  EXPECT_VEC_NEAR(cmd.v_body_in_world, Vector3d(1.0 - 0.8, 0.5, 0.8 * 0.5), kTol);
}

TEST(FormationController, HeightReferenceFollowsTheModeAndIsRaisedToTheFloor) {
  const TargetState t = target_at({10, 20, 7});
  FormationOptions start;  // default: height at start
  EXPECT_VEC_NEAR(FormationController(start, wide_limits(), default_mount()).desired_position(t, 4.5),
                  Vector3d(10, 14, 4.5), kTol);
  EXPECT_VEC_NEAR(FormationController(fixed_height(3.0), wide_limits(), default_mount()).desired_position(t, 4.5),
                  Vector3d(10, 14, 3.0), kTol);
  FormationOptions follow_z;
  follow_z.height_mode = "target";
  follow_z.offset_m = {2.0, -6.0, -1.5};
  EXPECT_VEC_NEAR(FormationController(follow_z, wide_limits(), default_mount()).desired_position(t, 4.5),
                  Vector3d(12, 14, 5.5), kTol);
  EXPECT_VEC_NEAR(FormationController(fixed_height(0.2), wide_limits(), default_mount()).desired_position(t, 4.5),
                  Vector3d(10, 14, 1.0), kTol)
      << "floor_height_m = 1";
}

TEST(FormationController, InsideTheAvoidanceRadiusItClimbsAndNeverApproaches) {
  FormationOptions o = fixed_height(10.0);
  o.offset_m = {0.0, 6.0, 0.0};  // formation point north of the target: getting there means passing it
  o.avoid_climb_mps = 0.7;
  FormationController c(o, wide_limits(), default_mount());
  const TargetState t = target_at({0, 0, 10});
  const Vector3d own(0.5, -2.0, 10.0);  // 2.06 m south of the target
  const VelocityCommand cmd = c.update(t, own_at(own), kT0, 0.0);
  EXPECT_TRUE(cmd.avoiding);
  EXPECT_NEAR(cmd.v_body_in_world.z(), 0.7, kTol);
  EXPECT_LE(cmd.v_body_in_world.dot(t.p_target_in_world - own), kTol) << cmd.v_body_in_world.transpose();
  // What is left of the wanted (-0.5, 8, 0) is its part across the line to the target.
  const Vector3d u = (t.p_target_in_world - own).normalized();
  const Vector3d wanted(-0.5, 8.0, 0.7);
  EXPECT_VEC_NEAR(cmd.v_body_in_world, Vector3d(wanted - wanted.dot(u) * u), kTol);

  // Outside the radius the same geometry flies straight at the formation point, at constant height.
  FormationController far(o, wide_limits(), default_mount());
  const VelocityCommand ok = far.update(t, own_at({0.5, -3.5, 10.0}), kT0, 0.0);
  EXPECT_FALSE(ok.avoiding);
  EXPECT_VEC_NEAR(ok.v_body_in_world, Vector3d(-0.5, 9.5, 0.0), kTol);
}

TEST(FormationController, YawTurnsTheOpticalAxisTowardsTheTargetAtALimitedRate) {
  struct Case {
    double own_yaw;
    Vector3d target;
    double yaw_rate;  // yaw_kp = 1, limit 1 rad/s
  };
  const Case cases[] = {
      {0.0, {5, 5, 10}, M_PI / 4},    // north-east of a camera looking east: turn left
      {0.0, {5, -5, 10}, -M_PI / 4},  // south-east: turn right
      {0.0, {-5, 5, 10}, 1.0},        // 135 deg: limited
      {0.0, {5, 0, 10}, 0.0},         // straight ahead
      {170 * M_PI / 180, {-5, -5 * std::tan(10 * M_PI / 180), 10}, 20 * M_PI / 180},  // across +-180: short way
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(testing::Message() << "own yaw " << k.own_yaw << ", target " << k.target.transpose());
    FormationOptions o = fixed_height(10.0);
    o.avoid_radius_m = 0.0;
    FormationController c(o, wide_limits(), default_mount());
    const VelocityCommand cmd = c.update(target_at(k.target), own_at({0, 0, 10}, k.own_yaw), kT0, 0.0);
    EXPECT_NEAR(cmd.yaw_rate_radps, k.yaw_rate, 1e-9);
  }
  // A camera looking out of the left side (body +y): a target to the left is already in view.
  const Eigen::Matrix3d left_mount =
      Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitZ()).toRotationMatrix() * default_mount();
  FormationOptions o = fixed_height(10.0);
  FormationController side(o, wide_limits(), left_mount);
  const VelocityCommand cmd = side.update(target_at({0, 8, 10}), own_at({0, 0, 10}, 0.0), kT0, 0.0);
  EXPECT_NEAR(cmd.yaw_rate_radps, 0.0, 1e-9);
  EXPECT_NEAR(cmd.yaw_rad, 0.0, 1e-9) << "the body keeps its heading: the camera already points north";
}

TEST(FormationController, ResetPidRemovesTheDerivativeKickAfterATrackSwitch) {
  FormationOptions o = fixed_height(10.0);
  o.kp = 1.0;
  o.kd = 1.0;
  o.avoid_radius_m = 0.0;
  FormationController c(o, wide_limits(), default_mount());
  c.update(target_at({0, 0, 10}), own_at({0, -6, 10}), kT0, 0.0);  // error 0
  TargetState other = target_at({4, 0, 10});
  other.track_id = 2;
  c.reset_pid();
  // The new error of 4 m east appears at once: without the reset, D would add 1 * 4 / 0.1 = 40 m/s.
  const VelocityCommand cmd = c.update(other, own_at({0, -6, 10}), kT0 + 100000, 0.0);
  EXPECT_VEC_NEAR(cmd.v_body_in_world, Vector3d(4, 0, 0), kTol);
}

TEST(FormationController, ValidateNamesEveryBadKey) {
  EXPECT_TRUE(FormationOptions{}.validate().empty());
  FormationOptions o;
  o.offset_m = {1.0, 2.0};
  o.height_mode = "sky";
  o.select = "random";
  o.kp = -1;
  o.avoid_radius_m = std::nan("");
  o.reselect_after_s = -1;
  const auto p = o.validate();
  const std::string all = testing::PrintToString(p);
  for (const char* key : {"formation.offset_m = '[1, 2]': must be 3 finite numbers",
                          "formation.height_mode = 'sky': must be start, fixed or target",
                          "formation.select = 'random'", "formation.kp = -1", "formation.avoid_radius_m = nan",
                          "formation.reselect_after_s = -1: must be a finite number >= 0"})
    EXPECT_NE(all.find(key), std::string::npos) << key << " not in " << all;
  EXPECT_EQ(p.size(), 6u) << all;

  FormationOptions inside;
  inside.offset_m = {0.0, -2.0, 5.0};  // 2 m horizontally, within the 3 m avoidance radius
  const auto q = inside.validate();
  ASSERT_EQ(q.size(), 1u);
  EXPECT_NE(q[0].find("must place the follower farther from the target (2 m horizontally) than "
                      "formation.avoid_radius_m = 3"),
            std::string::npos)
      << q[0];
  inside.height_mode = "target";  // then the 3-D offset counts: sqrt(29) > 3
  EXPECT_TRUE(inside.validate().empty());
}

}  // namespace

TEST(FormationController, WhileTheTargetsSizeIsInDoubtItWeavesAcrossTheLineOfSightThenStops) {
  // Target 6 m north: the line of sight is along north, so the weave is along east-west (x), to the left of the line
  // of sight (west) at a quarter period (sin = 1).
  FormationOptions o = fixed_height(10.0);
  o.weave_m = 1.0;
  o.weave_period_s = 4.0;
  FormationController c(o, wide_limits(), default_mount());
  TargetState doubtful = target_at({0, 0, 10});
  doubtful.size_sigma_rel = 0.3;
  const int64_t quarter = 1'000'000;  // 1 s of a 4-s period
  const int64_t t = kT0 - kT0 % 4'000'000 + quarter;
  // On station at the formation point: the weave's offset (1 m west at sin = 1) is the whole position error, and its
  // velocity (cos = 0) none.
  const VelocityCommand weaving = c.update(doubtful, own_at({0, -6, 10}), t, 0.0);
  EXPECT_VEC_NEAR(weaving.v_body_in_world, Vector3d(-o.kp * 1.0, 0.0, 0.0), 1e-6);
  // Size known (sigma 2 %): no weave, on station.
  FormationController d(o, wide_limits(), default_mount());
  TargetState known = doubtful;
  known.size_sigma_rel = 0.02;
  EXPECT_VEC_NEAR(d.update(known, own_at({0, -6, 10}), t, 0.0).v_body_in_world, Vector3d::Zero(), 1e-9);
  // Off: no weave either.
  o.weave_m = 0.0;
  FormationController off(o, wide_limits(), default_mount());
  EXPECT_VEC_NEAR(off.update(doubtful, own_at({0, -6, 10}), t, 0.0).v_body_in_world, Vector3d::Zero(), 1e-9);
}
