// SPDX-License-Identifier: MIT
// Own poses from ATTITUDE_QUATERNION + LOCAL_POSITION_NED and from ODOMETRY, and their ENU conversion.
#include <wingman/common/ned_enu.hpp>
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
