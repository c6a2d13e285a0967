// SPDX-License-Identifier: MIT
// Own poses from ATTITUDE_QUATERNION + LOCAL_POSITION_NED and from ODOMETRY, and their ENU conversion.
#include <wingman/geometry/ned_enu.hpp>
#include <wingman/mavlink/enums.hpp>
#include <wingman/mavlink_bridge/own_pose_assembler.hpp>

#include <gtest/gtest.h>

#include <cmath>

using namespace wingman::mavlink_bridge;
namespace mav = wingman::mavlink;

namespace {

/// FRD body -> NED for a heading `yaw` (from north, clockwise), level.
Eigen::Quaterniond heading(double yaw) { return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())); }

mav::AttitudeQuaternion attitude(uint32_t ms, const Eigen::Quaterniond& q) {
  mav::AttitudeQuaternion a;
  a.time_boot_ms = ms;
  a.q1 = static_cast<float>(q.w());
  a.q2 = static_cast<float>(q.x());
  a.q3 = static_cast<float>(q.y());
  a.q4 = static_cast<float>(q.z());
  return a;
}

/// An ODOMETRY at boot time 5 s, level and facing north (pose in LOCAL_NED, velocity in the FRD body), no covariance.
mav::Odometry odometry() {
  mav::Odometry o;
  o.time_usec = 5000000;
  o.frame_id = mav::kMavFrameLocalNed;
  o.child_frame_id = mav::kMavFrameBodyFrd;
  o.q = {1, 0, 0, 0};
  o.pose_covariance.fill(0);
  return o;
}

mav::LocalPositionNed position(uint32_t ms) {
  mav::LocalPositionNed p;
  p.time_boot_ms = ms;
  p.x = 10;  // north
  p.y = 20;  // east
  p.z = -5;  // 5 m up
  p.vx = 1;  // north
  p.vy = 0;
  p.vz = -0.5f;  // climbing
  return p;
}

}  // namespace

TEST(OwnPoseAssembler, APositionWithARecentAttitudeMakesAPoseAtThePositionsTime) {
  OwnPoseAssembler a(PoseSource::kAttitudePosition, 100000);
  std::string why;
  EXPECT_FALSE(a.on_local_position(position(1000), &why));
  EXPECT_NE(why.find("no ATTITUDE_QUATERNION"), std::string::npos);
  EXPECT_FALSE(a.on_attitude(attitude(990, heading(M_PI / 2)), &why));
  const auto pose = a.on_local_position(position(1000), &why);
  ASSERT_TRUE(pose) << why;
  EXPECT_EQ(pose->time_us, 1000000);
  EXPECT_FALSE(a.on_local_position(position(1200), &why)) << "attitude 210 ms away";
  EXPECT_NE(why.find("210 ms"), std::string::npos) << why;
}

TEST(OwnPoseAssembler, TheOwnPoseInEnuIsTheSameVehicleAsInNed) {
  OwnPoseAssembler a(PoseSource::kAttitudePosition, 100000);
  std::string why;
  a.on_attitude(attitude(1000, heading(M_PI / 2)), &why);  // facing east
  const auto pose = a.on_local_position(position(1000), &why);
  ASSERT_TRUE(pose);
  const auto enu = own_pose_message(*pose, 42, true);
  EXPECT_EQ(enu.utime, 42);
  EXPECT_EQ(enu.frame, int8_t{wingman::own_pose_t::FRAME_ENU});
  EXPECT_NEAR(enu.p_body_in_world[0], 20, 1e-6);  // east
  EXPECT_NEAR(enu.p_body_in_world[1], 10, 1e-6);  // north
  EXPECT_NEAR(enu.p_body_in_world[2], 5, 1e-6);   // up
  EXPECT_NEAR(enu.v_body_in_world[2], 0.5, 1e-6);
  // Facing east: the FLU body's x axis is ENU east, its y axis (left) north, its z up.
  const Eigen::Quaterniond q(enu.q_body_to_world[0], enu.q_body_to_world[1], enu.q_body_to_world[2],
                             enu.q_body_to_world[3]);
  EXPECT_TRUE((q * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitX(), 1e-6));
  EXPECT_TRUE((q * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d::UnitY(), 1e-6));
  EXPECT_TRUE((q * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitZ(), 1e-6));
  const auto ned = own_pose_message(*pose, 42, false);
  EXPECT_EQ(ned.frame, int8_t{wingman::own_pose_t::FRAME_NED});
  EXPECT_NEAR(ned.p_body_in_world[2], -5, 1e-6);
}

TEST(OwnPoseAssembler, OdometryVelocityInTheBodyIsRotatedIntoNedAndItsCovarianceRead) {
  OwnPoseAssembler a(PoseSource::kAuto, 100000);
  mav::Odometry o;
  o.time_usec = 5000000;
  o.frame_id = mav::kMavFrameLocalNed;
  o.child_frame_id = mav::kMavFrameBodyFrd;
  const Eigen::Quaterniond q = heading(M_PI / 2);  // facing east
  o.q = {static_cast<float>(q.w()), static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z())};
  o.vx = 2;  // forward
  o.pose_covariance.fill(0);
  o.pose_covariance[0] = o.pose_covariance[6] = o.pose_covariance[11] = 0.04f;
  std::string why;
  const auto pose = a.on_odometry(o, &why);
  ASSERT_TRUE(pose) << why;
  EXPECT_NEAR(pose->v_body_in_ned.y(), 2, 1e-6);  // east
  EXPECT_NEAR(pose->v_body_in_ned.x(), 0, 1e-6);
  EXPECT_NEAR(pose->position_std_m, 0.2, 1e-6);
  EXPECT_FALSE(pose->epoch_time);
  // Once odometry is used, auto ignores the attitude/position pair.
  a.on_attitude(attitude(5000, q), &why);
  EXPECT_FALSE(a.on_local_position(position(5000), &why));
  EXPECT_TRUE(why.empty());
}

TEST(OwnPoseAssembler, BadMessagesSayWhichField) {
  OwnPoseAssembler a(PoseSource::kAuto, 100000);
  std::string why;
  EXPECT_FALSE(a.on_attitude(attitude(1, Eigen::Quaterniond(2, 0, 0, 0)), &why));
  EXPECT_NE(why.find("ATTITUDE_QUATERNION.q1..q4"), std::string::npos);
  mav::Odometry o;
  o.frame_id = mav::kMavFrameLocalFrd;
  EXPECT_FALSE(a.on_odometry(o, &why));
  EXPECT_NE(why.find("ODOMETRY.frame_id"), std::string::npos);
}

TEST(OwnPoseAssembler, OdometryCovarianceReachesTheOwnPoseInBothFrames) {
  OwnPoseAssembler a(PoseSource::kOdometry, 100000);
  mav::Odometry o = odometry();
  // Upper triangle of the 6x6, row by row: xx xy xz .. (0..5), yy yz .. (6..10), zz .. (11..14), then
  // roll 15, pitch 18, yaw 20.
  o.pose_covariance[0] = 0.25f;   // north
  o.pose_covariance[1] = 0.05f;   // north-east
  o.pose_covariance[2] = -0.1f;   // north-down
  o.pose_covariance[6] = 0.16f;   // east
  o.pose_covariance[7] = 0.02f;   // east-down
  o.pose_covariance[11] = 0.64f;  // down
  o.pose_covariance[15] = 1e-4f;
  o.pose_covariance[18] = 4e-4f;
  o.pose_covariance[20] = 9e-4f;
  o.pose_covariance[3] = 7.0f;  // x-roll: not carried (own_pose_t has no position-attitude cross terms)
  std::string why;
  const auto pose = a.on_odometry(o, &why);
  ASSERT_TRUE(pose) << why;
  EXPECT_TRUE(why.empty()) << why;
  ASSERT_TRUE(pose->has_covariance);
  const auto ned = own_pose_message(*pose, 1, false);
  ASSERT_TRUE(ned.has_covariance);
  const double want_ned[6] = {0.25, 0.05, -0.1, 0.16, 0.02, 0.64};
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(ned.cov_p_body_in_world[i], want_ned[i], 1e-7) << i;
  const auto enu = own_pose_message(*pose, 1, true);
  ASSERT_TRUE(enu.has_covariance);
  // ENU: x east, y north, z up.
  const double want_enu[6] = {0.16, 0.05, -0.02, 0.25, 0.1, 0.64};
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(enu.cov_p_body_in_world[i], want_enu[i], 1e-7) << i;
  const double want_rpy[3] = {1e-4, 4e-4, 9e-4};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(enu.var_rpy_body[i], want_rpy[i], 1e-10) << i;
    EXPECT_NEAR(ned.var_rpy_body[i], want_rpy[i], 1e-10) << i;
  }
}

TEST(OwnPoseAssembler, AnInvalidOdometryCovarianceKeepsThePoseAndSaysWhy) {
  OwnPoseAssembler a(PoseSource::kOdometry, 100000);
  mav::Odometry o = odometry();
  struct Case {
    int index;
    float value;
    const char* says;
  };
  for (const Case c :
       {Case{0, -1.0f, "negative variance"}, Case{18, -1e-4f, "negative variance"},
        Case{1, 0.5f, "beyond +-sqrt(var var)"}, Case{6, INFINITY, "not finite"}, Case{20, NAN, "not finite"}}) {
    o.pose_covariance.fill(0);
    o.pose_covariance[0] = o.pose_covariance[6] = o.pose_covariance[11] = 0.04f;
    o.pose_covariance[c.index] = c.value;
    std::string why;
    const auto pose = a.on_odometry(o, &why);
    ASSERT_TRUE(pose) << c.index;
    EXPECT_FALSE(pose->has_covariance) << c.index;
    EXPECT_FALSE(own_pose_message(*pose, 1, true).has_covariance);
    EXPECT_NE(why.find("ODOMETRY.pose_covariance: "), std::string::npos) << why;
    EXPECT_NE(why.find(c.says), std::string::npos) << c.index << ": " << why;
  }
  o.pose_covariance.fill(0);
  o.pose_covariance[0] = NAN;  // unknown: no covariance and nothing to say
  std::string why;
  const auto pose = a.on_odometry(o, &why);
  ASSERT_TRUE(pose);
  EXPECT_FALSE(pose->has_covariance);
  EXPECT_TRUE(why.empty()) << why;
}
