// SPDX-License-Identifier: MIT
// Speed and acceleration limits, the no-approach rule and the floor, and their order of priority.
#include "wingman/follower_ctrl/velocity_limits.hpp"

#include "follower_test_helpers.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace {

using Eigen::Vector3d;
using wingman::follower_ctrl::LimitsOptions;
using wingman::follower_ctrl::OwnState;
using wingman::follower_ctrl::remove_approach;
using wingman::follower_ctrl::VelocityLimiter;

using namespace wingman::follower_ctrl::test;

constexpr double kLimitTol = 1e-12;

LimitsOptions limits(double max_h, double max_v, double acc_h, double acc_v, double floor = -100.0) {
  LimitsOptions l;
  l.max_horizontal_speed_mps = max_h;
  l.max_vertical_speed_mps = max_v;
  l.max_horizontal_accel_mps2 = acc_h;
  l.max_vertical_accel_mps2 = acc_v;
  l.floor_height_m = floor;
  return l;
}

OwnState own_at(int64_t utime, const Vector3d& p, const Vector3d& v = Vector3d::Zero()) {
  OwnState s;
  s.utime = utime;
  s.p_body_in_world = p;
  s.v_body_in_world = v;
  return s;
}

TEST(VelocityLimits, SpeedLimitScalesTheHorizontalPartAndClampsTheVertical) {
  const LimitsOptions l = limits(2.5, 1.0, 1, 1);
  EXPECT_VEC_NEAR(limit_speed(Vector3d(3, 4, 2), l), Vector3d(1.5, 2.0, 1.0), kLimitTol);    // |(3,4)| = 5 -> 2.5
  EXPECT_VEC_NEAR(limit_speed(Vector3d(-1, 1, -3), l), Vector3d(-1, 1, -1), kLimitTol);      // horizontal within
  EXPECT_VEC_NEAR(limit_speed(Vector3d(0.5, 0, 0.2), l), Vector3d(0.5, 0, 0.2), kLimitTol);  // untouched
}

TEST(VelocityLimits, AccelerationLimitScalesTheChangeVectorAndClampsTheVerticalChange) {
  const LimitsOptions l = limits(10, 10, 2.0, 1.0);
  // dt = 0.5 s: horizontal change at most 1 m/s along (3, 4)/5; vertical at most 0.5 m/s.
  EXPECT_VEC_NEAR(limit_acceleration(Vector3d(3, 4, -2), Vector3d::Zero(), 0.5, l), Vector3d(0.6, 0.8, -0.5),
                  kLimitTol);
  EXPECT_VEC_NEAR(limit_acceleration(Vector3d(1.2, 1, 0.1), Vector3d(1, 1, 0), 0.5, l), Vector3d(1.2, 1, 0.1),
                  kLimitTol);
  EXPECT_VEC_NEAR(limit_acceleration(Vector3d(5, 5, 5), Vector3d(1, 2, 3), 0.0, l), Vector3d(1, 2, 3), kLimitTol);
}

TEST(VelocityLimits, LimiterRampsFromTheMeasuredVelocityAfterAResetThenFromItsPreviousCommand) {
  VelocityLimiter limiter(limits(3.0, 1.0, 2.0, 1.0));
  const OwnState own = own_at(kT0, Vector3d(0, 0, 10), Vector3d(1, 0, 0));
  // First command 0.1 s after the measurement: 1 + 2 * 0.1.
  EXPECT_VEC_NEAR(limiter.apply(Vector3d(3, 0, 0), kT0 + 100000, own), Vector3d(1.2, 0, 0), kLimitTol);
  EXPECT_VEC_NEAR(limiter.apply(Vector3d(3, 0, 0), kT0 + 200000, own), Vector3d(1.4, 0, 0), kLimitTol);
  EXPECT_VEC_NEAR(limiter.apply(Vector3d(-3, 0, 0), kT0 + 300000, own), Vector3d(1.2, 0, 0), kLimitTol);
  // A command at the same time cannot change.
  EXPECT_VEC_NEAR(limiter.apply(Vector3d(0, 0, 0), kT0 + 300000, own), Vector3d(1.2, 0, 0), kLimitTol);
  limiter.reset();
  // At the measurement's own time after a reset: exactly the measured velocity, no jump.
  EXPECT_VEC_NEAR(limiter.apply(Vector3d(-3, 0, 0), kT0, own), Vector3d(1, 0, 0), kLimitTol);
  EXPECT_THROW(limiter.apply(Vector3d::Zero(), kT0 - 1, own), std::invalid_argument);
}

TEST(VelocityLimits, SpeedLimitWinsOverTheAccelerationLimitWhenTheMeasuredVelocityIsTooFast) {
  VelocityLimiter limiter(limits(3.0, 1.0, 2.0, 1.0));
  const OwnState own = own_at(kT0, Vector3d(0, 0, 10), Vector3d(5, 0, -2));
  EXPECT_VEC_NEAR(limiter.apply(Vector3d(5, 0, -2), kT0 + 10000, own), Vector3d(3, 0, -1), kLimitTol);
}

TEST(VelocityLimits, RandomWantedVelocitiesNeverBreakTheSpeedOrAccelerationLimits) {
  const LimitsOptions l = limits(3.0, 1.0, 2.0, 1.5);
  VelocityLimiter limiter(l);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> v(-10, 10);
  std::uniform_int_distribution<int> dt_ms(0, 200);
  const OwnState own = own_at(kT0, Vector3d(0, 0, 10));
  Vector3d previous = Vector3d::Zero();
  int64_t t = kT0;
  for (int k = 0; k < 2000; ++k) {
    const int64_t dt = dt_ms(rng) * 1000;
    t += dt;
    const Vector3d out = limiter.apply(Vector3d(v(rng), v(rng), v(rng)), t, own);
    EXPECT_LE(out.head<2>().norm(), 3.0 + 1e-9);
    EXPECT_LE(std::abs(out.z()), 1.0 + 1e-9);
    EXPECT_LE((out - previous).head<2>().norm(), 2.0 * dt * 1e-6 + 1e-9) << "step " << k;
    EXPECT_LE(std::abs(out.z() - previous.z()), 1.5 * dt * 1e-6 + 1e-9) << "step " << k;
    previous = out;
  }
}

TEST(VelocityLimits, NoApproachRemovesOnlyTheClosingComponent) {
  const Vector3d d(2, 0, 0);  // obstacle east
  EXPECT_VEC_NEAR(remove_approach(Vector3d(2, 1, 0.5), d), Vector3d(0, 1, 0.5), kLimitTol);
  EXPECT_VEC_NEAR(remove_approach(Vector3d(-2, 1, 0), d), Vector3d(-2, 1, 0), kLimitTol);  // moving away: kept
  const Vector3d diag(1, 1, 0);
  const Vector3d out = remove_approach(Vector3d(1, 0, 0), diag);
  EXPECT_VEC_NEAR(out, Vector3d(0.5, -0.5, 0), kLimitTol);
  EXPECT_NEAR(out.dot(diag), 0.0, kLimitTol);
}

TEST(VelocityLimits, FloorStopsDescentsAtAndBelowItOnlyAndKeepsTheNoApproachRule) {
  VelocityLimiter limiter(limits(10, 10, 1e4, 1e4, 1.0));
  EXPECT_VEC_NEAR(limiter.apply(Vector3d(0, 0, -1), kT0 + 100000, own_at(kT0, Vector3d(0, 0, 1.0))), Vector3d(0, 0, 0),
                  kLimitTol);
  limiter.reset();
  EXPECT_VEC_NEAR(limiter.apply(Vector3d(0, 0, -1), kT0 + 100000, own_at(kT0, Vector3d(0, 0, 0.5))), Vector3d(0, 0, 0),
                  kLimitTol);
  limiter.reset();
  EXPECT_VEC_NEAR(limiter.apply(Vector3d(0, 0, -1), kT0 + 100000, own_at(kT0, Vector3d(0, 0, 1.5))), Vector3d(0, 0, -1),
                  kLimitTol);
  limiter.reset();
  // At the floor with the obstacle ahead and above: (1, 0, -1) does not close on (1, 0, 1), but once the
  // floor takes the descent away it would; the horizontal part gives way instead.
  const Vector3d out =
      limiter.apply(Vector3d(1, 0, -1), kT0 + 100000, own_at(kT0, Vector3d(0, 0, 1.0)), Vector3d(1, 0, 1));
  EXPECT_GE(out.z(), 0.0);
  EXPECT_LE(out.dot(Vector3d(1, 0, 1)), kLimitTol);
  EXPECT_VEC_NEAR(out, Vector3d(0, 0, 0), kLimitTol);
}

TEST(VelocityLimits, NoApproachWinsOverTheAccelerationLimit) {
  VelocityLimiter limiter(limits(3.0, 1.0, 1.0, 1.0));
  const OwnState own = own_at(kT0, Vector3d(0, 0, 10), Vector3d(2, 0, 0));                      // flying east at 2 m/s
  const Vector3d out = limiter.apply(Vector3d(2, 0, 0), kT0 + 100000, own, Vector3d(2, 0, 0));  // obstacle east
  EXPECT_LE(out.x(), kLimitTol) << "never closes on the obstacle, though braking from 2 m/s takes 2 s at 1 m/s^2";
}

TEST(VelocityLimits, YawRateIsClampedSymmetrically) {
  LimitsOptions l;
  l.max_yaw_rate_radps = 0.5;
  VelocityLimiter limiter(l);
  EXPECT_EQ(limiter.limit_yaw_rate(2.0), 0.5);
  EXPECT_EQ(limiter.limit_yaw_rate(-2.0), -0.5);
  EXPECT_EQ(limiter.limit_yaw_rate(0.25), 0.25);
}

TEST(VelocityLimits, ValidateNamesEveryBadKeyAndTheDefaultsAreValid) {
  EXPECT_TRUE(LimitsOptions{}.validate().empty());
  LimitsOptions l;
  l.max_horizontal_speed_mps = 0;
  l.max_vertical_accel_mps2 = -1;
  l.floor_height_m = std::numeric_limits<double>::infinity();
  const auto p = l.validate();
  ASSERT_EQ(p.size(), 3u);
  EXPECT_NE(p[0].find("limits.max_horizontal_speed_mps = 0: must be a finite number > 0"), std::string::npos) << p[0];
  EXPECT_NE(p[1].find("limits.max_vertical_accel_mps2 = -1"), std::string::npos) << p[1];
  EXPECT_NE(p[2].find("limits.floor_height_m = inf: must be finite"), std::string::npos) << p[2];
  EXPECT_THROW(VelocityLimiter{l}, std::invalid_argument);
}

}  // namespace
