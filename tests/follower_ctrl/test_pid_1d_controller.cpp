// SPDX-License-Identifier: MIT
// The 1-D follower: eq. 34 on the box centre, the sign convention, its axis of motion and the height hold.
#include "wingman/follower_ctrl/pid_1d_controller.hpp"

#include "follower_test_helpers.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>

namespace {

using Eigen::Vector3d;
using wingman::follower_ctrl::box_centre_error;
using wingman::follower_ctrl::LimitsOptions;
using wingman::follower_ctrl::most_confident_box;
using wingman::follower_ctrl::OwnState;
using wingman::follower_ctrl::Pid1dCommand;
using wingman::follower_ctrl::Pid1dController;
using wingman::follower_ctrl::Pid1dOptions;
using namespace wingman::follower_ctrl::test;

OwnState own_at(double yaw_rad, double z = 5.0) {
  OwnState s;
  s.utime = kT0 - 1000000;  // measured 1 s before: the acceleration limit from it is wide
  s.p_body_in_world = Vector3d(0, 0, z);
  s.R_body_to_world = Eigen::AngleAxisd(yaw_rad, Vector3d::UnitZ()).toRotationMatrix();
  return s;
}

TEST(Pid1dController, Eq34IsTheNormalisedBoxCentreMinusOneHalf) {
  EXPECT_NEAR(box_centre_error(box(700.0f), 1000), 0.2, kTol);
  EXPECT_NEAR(box_centre_error(box(160.0f), 640), -0.25, kTol);
  EXPECT_NEAR(box_centre_error(box(320.0f), 640), 0.0, kTol);
}

TEST(Pid1dController, MostConfidentBoxInsideTheImageIsUsed) {
  const auto d = detections(kT0, {box(100, 0.5f), box(1200, 0.99f), box(800, 0.7f), box(300, 0.7f)});
  const auto b = most_confident_box(d);
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->cx, 800.0f) << "1200 is outside the 1000 px image; ties go to the first";
  EXPECT_FALSE(most_confident_box(detections(kT0, {})).has_value());
}

TEST(Pid1dController, BoxesOfOtherClassesThanDroneAreNeverFollowed) {
  // A multi-class model: a bird (class 2) more confident than the drone, and an airplane alone.
  auto bird = box(300, 0.95f);
  bird.class_id = 2;
  bird.drone_score = 0.05f;
  const auto b = most_confident_box(detections(kT0, {bird, box(600, 0.6f)}));
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->cx, 600.0f) << "the drone, not the more confident bird";
  auto airplane = box(500, 0.9f);
  airplane.class_id = 1;
  EXPECT_FALSE(most_confident_box(detections(kT0, {airplane})).has_value());
}

TEST(Pid1dController, ThesisSetUpTargetRightOfCentreMovesTheFollowerTowardsWorldPlusX) {
  // The thesis's 1-D experiment: the camera looks along world +Y (body yawed 90 degrees); the image's
  // right-hand side is world +X, along which the leader moves.
  Pid1dController c(Pid1dOptions{}, wide_limits(), default_mount());
  const OwnState own = own_at(M_PI / 2);
  const auto axis = c.axis_in_world(own);
  ASSERT_TRUE(axis.has_value());
  EXPECT_VEC_NEAR(*axis, Vector3d(1, 0, 0), kTol);
  const Pid1dCommand right = c.update(0.2, *axis, own, kT0, 5.0);
  EXPECT_VEC_NEAR(right.command.v_body_in_world, Vector3d(26.0 * 0.2, 0, 0), kTol);
  ASSERT_TRUE(right.terms.has_value());
  EXPECT_NEAR(right.terms->p, 5.2, kTol);
  EXPECT_EQ(right.command.yaw_rate_radps, 0.0) << "the 1-D follower holds its heading";

  c.reset();
  const Pid1dCommand left = c.update(-0.3, *axis, own, kT0, 5.0);
  EXPECT_VEC_NEAR(left.command.v_body_in_world, Vector3d(26.0 * -0.3, 0, 0), kTol);
}

TEST(Pid1dController, CameraRightAxisTurnsWithTheBodyAndTheMount) {
  Pid1dController c(Pid1dOptions{}, wide_limits(), default_mount());
  EXPECT_VEC_NEAR(*c.axis_in_world(own_at(0.0)), Vector3d(0, -1, 0), kTol) << "facing east: right is south";
  EXPECT_VEC_NEAR(*c.axis_in_world(own_at(M_PI)), Vector3d(0, 1, 0), kTol) << "facing west: right is north";
  // A camera rolled 90 degrees about its optical axis has its x axis vertical: no horizontal axis.
  const Eigen::Matrix3d rolled = default_mount() * Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitZ()).toRotationMatrix();
  Pid1dController r(Pid1dOptions{}, wide_limits(), rolled);
  EXPECT_FALSE(r.axis_in_world(own_at(0.0)).has_value());
}

TEST(Pid1dController, WorldAxisIsNormalisedAndIndependentOfTheAttitude) {
  Pid1dOptions o;
  o.axis = "world";
  o.world_axis = {0.0, 2.0};
  Pid1dController c(o, wide_limits(), default_mount());
  EXPECT_VEC_NEAR(*c.axis_in_world(own_at(0.3)), Vector3d(0, 1, 0), kTol);
}

TEST(Pid1dController, HeightIsHeldWithAPTermOnTheStartOrFixedHeightRaisedToTheFloor) {
  Pid1dOptions o;
  o.height_kp = 0.5;
  Pid1dController start(o, wide_limits(), default_mount());
  EXPECT_NEAR(start.update(0.0, Vector3d::UnitX(), own_at(0.0, 4.0), kT0, 5.0).command.v_body_in_world.z(), 0.5, kTol);
  o.height_mode = "fixed";
  o.height_m = 0.0;  // below the 1 m floor
  Pid1dController fixed(o, wide_limits(), default_mount());
  EXPECT_NEAR(fixed.update(0.0, Vector3d::UnitX(), own_at(0.0, 4.0), kT0, 5.0).command.v_body_in_world.z(), -1.5, kTol);
}

TEST(Pid1dController, WithoutABoxTheAxisCommandIsZeroAndThePidMemoryIsKept) {
  Pid1dController c(Pid1dOptions{}, wide_limits(), default_mount());
  const OwnState own = own_at(M_PI / 2);
  c.update(0.1, Vector3d::UnitX(), own, kT0, 5.0);
  const Pid1dCommand none = c.update(std::nullopt, Vector3d::UnitX(), own, kT0 + 100000, 5.0);
  EXPECT_FALSE(none.terms.has_value());
  EXPECT_NEAR(none.command.v_body_in_world.x(), 0.0, kTol);
  // The next box continues the loop from the last box, 0.2 s before: I = 2 (0.3 * 0.2),
  // D = 2 (0.3 - 0.1) / 0.2.
  const Pid1dCommand next = c.update(0.3, Vector3d::UnitX(), own, kT0 + 200000, 5.0);
  ASSERT_TRUE(next.terms.has_value());
  EXPECT_NEAR(next.terms->dt_s, 0.2, kTol);
  EXPECT_NEAR(next.terms->i, 2.0 * 0.06, kTol);
  EXPECT_NEAR(next.terms->d, 2.0, kTol);
  EXPECT_NEAR(next.command.v_body_in_world.x(), 7.8 + 0.12 + 2.0, kTol);
}

TEST(Pid1dController, ValidateNamesEveryBadKey) {
  EXPECT_TRUE(Pid1dOptions{}.validate().empty());
  Pid1dOptions o;
  o.kd = std::nan("");
  o.integral_max = -0.1;
  o.axis = "up";
  o.world_axis = {0.0, 0.0};
  o.height_mode = "target";
  const auto p = o.validate();
  const std::string all = testing::PrintToString(p);
  for (const char* key : {"pid_1d.kd = nan: must be finite", "pid_1d.integral_max = -0.1",
                          "pid_1d.axis = 'up': must be camera_right or world", "pid_1d.world_axis = '[0, 0]'",
                          "pid_1d.height_mode = 'target': must be start or fixed"})
    EXPECT_NE(all.find(key), std::string::npos) << key << " not in " << all;
  EXPECT_EQ(p.size(), 5u) << all;
}

}  // namespace
