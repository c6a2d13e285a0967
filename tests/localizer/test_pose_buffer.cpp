// SPDX-License-Identifier: MIT
// PoseBuffer: exact at samples, linear + slerp between, refusals (order, gap, age) with reasons.
#include <gtest/gtest.h>
#include <wingman/localizer/pose_buffer.hpp>

#include "test_rotations.hpp"

#include <cmath>

namespace {

using wingman::localizer::PoseBuffer;
using wingman::localizer::PoseBufferOptions;
using wingman::localizer::PoseSample;

using wingman::testing::kPi;
using wingman::testing::kT0;
using wingman::testing::yaw;

double yaw_deg(const Eigen::Quaterniond& q) {
  const Eigen::Vector3d x = q * Eigen::Vector3d::UnitX();
  return std::atan2(x.y(), x.x()) * 180 / kPi;
}

PoseSample sample(int64_t utime, Eigen::Vector3d p, double yaw_degrees, Eigen::Vector3d v = Eigen::Vector3d::Zero()) {
  PoseSample s;
  s.utime = utime;
  s.p_body_in_world = p;
  s.q_body_to_world = yaw(yaw_degrees);
  s.v_body_in_world = v;
  return s;
}

TEST(PoseBufferOptions, DefaultsAreValidAndBadValuesAreNamed) {
  EXPECT_TRUE(PoseBufferOptions{}.validate().empty());
  PoseBufferOptions o;
  o.max_gap_s = 0;
  o.history_s = -1;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 2u);
  EXPECT_NE(p[0].find("pose.max_gap_s"), std::string::npos);
  EXPECT_NE(p[1].find("pose.history_s"), std::string::npos);
  EXPECT_THROW(PoseBuffer{o}, std::invalid_argument);
}

TEST(PoseBuffer, IsExactAtTheSamples) {
  PoseBuffer b;
  ASSERT_TRUE(b.add(sample(kT0, {1, 2, 3}, 10)));
  ASSERT_TRUE(b.add(sample(kT0 + 20'000, {2, 2, 3}, 30)));
  ASSERT_TRUE(b.add(sample(kT0 + 40'000, {3, 2, 3}, 50)));
  for (int k = 0; k < 3; ++k) {
    const auto p = b.at(kT0 + 20'000 * k);
    ASSERT_TRUE(p);
    EXPECT_EQ(p->utime, kT0 + 20'000 * k);
    EXPECT_DOUBLE_EQ(p->p_body_in_world.x(), 1.0 + k);
    EXPECT_NEAR(yaw_deg(p->q_body_to_world), 10.0 + 20 * k, 1e-12);
  }
}

TEST(PoseBuffer, MidpointOfA90DegreeYawChangeIs45Degrees) {
  PoseBuffer b;
  ASSERT_TRUE(b.add(sample(kT0, {0, 0, 0}, 0, {1, 0, 0})));
  ASSERT_TRUE(b.add(sample(kT0 + 100'000, {1, 2, 3}, 90, {3, 0, 0})));
  const auto mid = b.at(kT0 + 50'000);
  ASSERT_TRUE(mid);
  EXPECT_NEAR(yaw_deg(mid->q_body_to_world), 45.0, 1e-12);
  EXPECT_NEAR(mid->q_body_to_world.norm(), 1.0, 1e-15);
  EXPECT_TRUE(mid->p_body_in_world.isApprox(Eigen::Vector3d(0.5, 1, 1.5), 1e-15));
  EXPECT_TRUE(mid->v_body_in_world.isApprox(Eigen::Vector3d(2, 0, 0), 1e-15));
  // A quarter of the way: slerp is uniform in angle (22.5 deg), not in quaternion components.
  EXPECT_NEAR(yaw_deg(b.at(kT0 + 25'000)->q_body_to_world), 22.5, 1e-12);
}

TEST(PoseBuffer, SlerpTakesTheShortArcWhateverTheQuaternionSign) {
  PoseBuffer b;
  PoseSample a = sample(kT0, {0, 0, 0}, 170);
  PoseSample c = sample(kT0 + 100'000, {0, 0, 0}, -170);  // 20 degrees away across +-180
  c.q_body_to_world.coeffs() *= -1;                       // same rotation, other hemisphere
  ASSERT_TRUE(b.add(a));
  ASSERT_TRUE(b.add(c));
  EXPECT_NEAR(std::abs(yaw_deg(b.at(kT0 + 50'000)->q_body_to_world)), 180.0, 1e-9);
}

TEST(PoseBuffer, RefusesDuplicateAndOutOfOrderSamplesWithAReason) {
  PoseBuffer b;
  std::string why;
  ASSERT_TRUE(b.add(sample(kT0 + 10'000, {0, 0, 0}, 0), &why));
  EXPECT_FALSE(b.add(sample(kT0 + 10'000, {9, 9, 9}, 0), &why));
  EXPECT_NE(why.find("duplicate"), std::string::npos) << why;
  EXPECT_FALSE(b.add(sample(kT0, {9, 9, 9}, 0), &why));
  EXPECT_NE(why.find("out of order"), std::string::npos) << why;
  EXPECT_EQ(b.size(), 1u);
  EXPECT_TRUE(b.at(kT0 + 10'000)->p_body_in_world.isZero());  // the refused samples changed nothing
}

TEST(PoseBuffer, RefusesNonFiniteAndNonUnitQuaternions) {
  PoseBuffer b;
  std::string why;
  PoseSample s = sample(kT0, {0, 0, 0}, 0);
  s.q_body_to_world.coeffs() *= 1.1;
  EXPECT_FALSE(b.add(s, &why));
  EXPECT_NE(why.find("norm"), std::string::npos) << why;
  s = sample(kT0, {NAN, 0, 0}, 0);
  EXPECT_FALSE(b.add(s, &why));
  EXPECT_NE(why.find("non-finite"), std::string::npos) << why;
  EXPECT_EQ(b.size(), 0u);
}

TEST(PoseBuffer, RefusesQueriesAcrossAGapWithAReason) {
  PoseBufferOptions o;
  o.max_gap_s = 0.1;
  PoseBuffer b(o);
  ASSERT_TRUE(b.add(sample(kT0, {0, 0, 0}, 0)));
  ASSERT_TRUE(b.add(sample(kT0 + 100'000, {1, 0, 0}, 0)));  // exactly max_gap_s: fine
  ASSERT_TRUE(b.add(sample(kT0 + 600'000, {2, 0, 0}, 0)));  // 0.5 s gap: a dropped stream
  EXPECT_TRUE(b.at(kT0 + 50'000));
  std::string why;
  EXPECT_FALSE(b.at(kT0 + 300'000, &why));
  EXPECT_NE(why.find("0.500 s apart"), std::string::npos) << why;
  EXPECT_NE(why.find("pose.max_gap_s"), std::string::npos) << why;
}

TEST(PoseBuffer, ExtrapolatesALittleAndRefusesStalePosesWithAReason) {
  PoseBufferOptions o;
  o.max_extrapolation_s = 0.05;
  PoseBuffer b(o);
  std::string why;
  EXPECT_FALSE(b.at(kT0, &why));
  EXPECT_NE(why.find("no own pose"), std::string::npos) << why;
  ASSERT_TRUE(b.add(sample(kT0, {0, 0, 0}, 30, {2, -1, 0})));
  ASSERT_TRUE(b.add(sample(kT0 + 20'000, {0.04, -0.02, 0}, 30, {2, -1, 0})));
  const auto ahead = b.at(kT0 + 20'000 + 50'000);  // newest + max_extrapolation_s: held orientation, moved by v
  ASSERT_TRUE(ahead);
  EXPECT_TRUE(ahead->p_body_in_world.isApprox(Eigen::Vector3d(0.14, -0.07, 0), 1e-12));
  EXPECT_NEAR(yaw_deg(ahead->q_body_to_world), 30, 1e-12);
  EXPECT_FALSE(b.at(kT0 + 20'000 + 50'001, &why));
  EXPECT_NE(why.find("older than utime"), std::string::npos) << why;
  EXPECT_NE(why.find("pose.max_extrapolation_s"), std::string::npos) << why;
  const auto before = b.at(kT0 - 10'000);
  ASSERT_TRUE(before);
  EXPECT_TRUE(before->p_body_in_world.isApprox(Eigen::Vector3d(-0.02, 0.01, 0), 1e-12));
  EXPECT_FALSE(b.at(kT0 - 60'000, &why));
  EXPECT_NE(why.find("before the oldest"), std::string::npos) << why;
}

TEST(PoseBuffer, DropsSamplesOlderThanTheHistory) {
  PoseBufferOptions o;
  o.history_s = 1.0;
  PoseBuffer b(o);
  for (int k = 0; k <= 300; ++k) ASSERT_TRUE(b.add(sample(kT0 + 10'000 * k, {0.01 * k, 0, 0}, 0)));
  EXPECT_EQ(b.size(), 101u);  // 2.0 s .. 3.0 s
  std::string why;
  EXPECT_FALSE(b.at(kT0 + 1'000'000, &why));
  EXPECT_NE(why.find("pose.history_s"), std::string::npos) << why;
  EXPECT_TRUE(b.at(kT0 + 2'000'000));
}

TEST(PoseFrames, NedFrdPoseBecomesEnuFlu) {
  // Level vehicle in NED heading east (yaw +90 deg about down), at north 1, east 2, down 3, flying east.
  PoseSample ned;
  ned.utime = kT0;
  ned.p_body_in_world = {1, 2, 3};
  ned.v_body_in_world = {0, 4, 0};
  ned.q_body_to_world = yaw(90);
  const PoseSample enu = wingman::localizer::pose_ned_frd_to_enu_flu(ned);
  EXPECT_TRUE(enu.p_body_in_world.isApprox(Eigen::Vector3d(2, 1, -3)));
  EXPECT_TRUE(enu.v_body_in_world.isApprox(Eigen::Vector3d(4, 0, 0)));
  // FLU forward points east (ENU x), left points north (ENU y), up points up.
  EXPECT_TRUE((enu.q_body_to_world * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitX(), 1e-12));
  EXPECT_TRUE((enu.q_body_to_world * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_TRUE((enu.q_body_to_world * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitZ(), 1e-12));
}

TEST(PoseFrames, NedCovarianceBecomesTheCovarianceOfTheEnuPosition) {
  // The covariance of p_enu = S p_ned is S C S^T: north and east variances exchange, covariances with down change
  // sign. Checked on the definition: for any u, var(u . p_enu) = (S^T u)^T C (S^T u).
  PoseSample ned;
  ned.cov_p_body_in_world << 4, 1, 0.5,  //
      1, 9, -2,                          //
      0.5, -2, 16;
  ned.var_rpy_body = {1e-4, 2e-4, 3e-4};
  const PoseSample enu = wingman::localizer::pose_ned_frd_to_enu_flu(ned);
  EXPECT_DOUBLE_EQ(enu.cov_p_body_in_world(0, 0), 9);   // east
  EXPECT_DOUBLE_EQ(enu.cov_p_body_in_world(1, 1), 4);   // north
  EXPECT_DOUBLE_EQ(enu.cov_p_body_in_world(2, 2), 16);  // up
  EXPECT_DOUBLE_EQ(enu.cov_p_body_in_world(0, 1), 1);
  EXPECT_DOUBLE_EQ(enu.cov_p_body_in_world(0, 2), 2);     // east-up = -(east-down)
  EXPECT_DOUBLE_EQ(enu.cov_p_body_in_world(1, 2), -0.5);  // north-up = -(north-down)
  EXPECT_TRUE(enu.cov_p_body_in_world.isApprox(enu.cov_p_body_in_world.transpose()));
  EXPECT_TRUE(enu.var_rpy_body.isApprox(ned.var_rpy_body));  // FRD and FLU axes differ by sign only
}

TEST(PoseBuffer, InterpolatesTheCovarianceLinearly) {
  PoseBuffer b;
  PoseSample a = sample(kT0, {0, 0, 0}, 0);
  a.cov_p_body_in_world = Eigen::Matrix3d::Identity();
  a.var_rpy_body = {1e-4, 1e-4, 1e-4};
  PoseSample c = sample(kT0 + 40'000, {0, 0, 0}, 0);
  c.cov_p_body_in_world = 3 * Eigen::Matrix3d::Identity();
  c.var_rpy_body = {3e-4, 3e-4, 5e-4};
  ASSERT_TRUE(b.add(a));
  ASSERT_TRUE(b.add(c));
  const auto mid = b.at(kT0 + 10'000);
  ASSERT_TRUE(mid);
  EXPECT_TRUE(mid->cov_p_body_in_world.isApprox(1.5 * Eigen::Matrix3d::Identity()));
  EXPECT_TRUE(mid->var_rpy_body.isApprox(Eigen::Vector3d(1.5e-4, 1.5e-4, 2e-4)));
  PoseSample bad = sample(kT0 + 80'000, {0, 0, 0}, 0);
  bad.cov_p_body_in_world(0, 0) = NAN;
  std::string why;
  EXPECT_FALSE(b.add(bad, &why));
  EXPECT_NE(why.find("non-finite"), std::string::npos) << why;
}

}  // namespace
