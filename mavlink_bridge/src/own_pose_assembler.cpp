// SPDX-License-Identifier: MIT
// Poses from the autopilot's attitude, position and odometry messages.
#include "wingman/mavlink_bridge/own_pose_assembler.hpp"

#include <wingman/common/ned_enu.hpp>
#include <wingman/mavlink/enums.hpp>

#include <cmath>
#include <cstdlib>

namespace wingman::mavlink_bridge {

namespace {

/// The unit quaternion (w, x, y, z), or nullopt when it is not finite or far from unit length.
std::optional<Eigen::Quaterniond> unit_quaternion(double w, double x, double y, double z) {
  Eigen::Quaterniond q(w, x, y, z);
  const double n = q.norm();
  if (!std::isfinite(n) || std::abs(n - 1.0) > 0.01) return std::nullopt;
  return q.normalized();
}

bool finite(const Eigen::Vector3d& v) { return v.allFinite(); }

}  // namespace

bool OwnPoseAssembler::pair_wanted() const {
  return source_ == PoseSource::kAttitudePosition || (source_ == PoseSource::kAuto && !odometry_seen_);
}

std::optional<NedPose> OwnPoseAssembler::on_attitude(const mavlink::AttitudeQuaternion& m, std::string* why) {
  why->clear();
  if (!unit_quaternion(m.q1, m.q2, m.q3, m.q4)) {
    *why = "ATTITUDE_QUATERNION.q1..q4: not a unit quaternion";
    return std::nullopt;
  }
  attitude_ = m;
  return std::nullopt;  // a pose is made when the position comes
}

std::optional<NedPose> OwnPoseAssembler::on_local_position(const mavlink::LocalPositionNed& m, std::string* why) {
  why->clear();
  if (!pair_wanted()) return std::nullopt;
  NedPose pose;
  pose.time_us = static_cast<int64_t>(m.time_boot_ms) * 1000;
  pose.p_body_in_ned = Eigen::Vector3d(m.x, m.y, m.z);
  pose.v_body_in_ned = Eigen::Vector3d(m.vx, m.vy, m.vz);
  if (!finite(pose.p_body_in_ned) || !finite(pose.v_body_in_ned)) {
    *why = "LOCAL_POSITION_NED.x..vz: not finite";
    return std::nullopt;
  }
  if (!attitude_) {
    *why = "LOCAL_POSITION_NED: no ATTITUDE_QUATERNION yet";
    return std::nullopt;
  }
  const int64_t age_us = std::llabs(pose.time_us - static_cast<int64_t>(attitude_->time_boot_ms) * 1000);
  if (age_us > max_age_us_) {
    *why = "LOCAL_POSITION_NED.time_boot_ms: the newest ATTITUDE_QUATERNION is " + std::to_string(age_us / 1000) +
           " ms away";
    return std::nullopt;
  }
  pose.q_frd_to_ned = *unit_quaternion(attitude_->q1, attitude_->q2, attitude_->q3, attitude_->q4);
  return pose;
}

std::optional<NedPose> OwnPoseAssembler::on_odometry(const mavlink::Odometry& m, std::string* why) {
  why->clear();
  if (source_ == PoseSource::kAttitudePosition) return std::nullopt;
  if (m.frame_id != mavlink::kMavFrameLocalNed) {
    *why = "ODOMETRY.frame_id = " + std::to_string(m.frame_id) + ": only MAV_FRAME_LOCAL_NED (1) is used";
    return std::nullopt;
  }
  if (m.child_frame_id != mavlink::kMavFrameBodyFrd && m.child_frame_id != mavlink::kMavFrameLocalNed) {
    *why = "ODOMETRY.child_frame_id = " + std::to_string(m.child_frame_id) +
           ": velocity must be in MAV_FRAME_BODY_FRD (12) or MAV_FRAME_LOCAL_NED (1)";
    return std::nullopt;
  }
  const auto q = unit_quaternion(m.q[0], m.q[1], m.q[2], m.q[3]);
  if (!q) {
    *why = "ODOMETRY.q: not a unit quaternion";
    return std::nullopt;
  }
  NedPose pose;
  pose.time_us = static_cast<int64_t>(m.time_usec);
  pose.epoch_time = pose.time_us > kEpochTimeThresholdUs;
  pose.q_frd_to_ned = *q;
  pose.p_body_in_ned = Eigen::Vector3d(m.x, m.y, m.z);
  const Eigen::Vector3d v(m.vx, m.vy, m.vz);
  pose.v_body_in_ned = m.child_frame_id == mavlink::kMavFrameBodyFrd ? Eigen::Vector3d(*q * v) : v;
  if (!finite(pose.p_body_in_ned) || !finite(pose.v_body_in_ned)) {
    *why = "ODOMETRY.x..vz: not finite";
    return std::nullopt;
  }
  // pose_covariance: upper triangle of the 6x6 (x, y, z, roll, pitch, yaw) covariance, row-major: x, y and z
  // variances at 0, 6 and 11. NaN in the first element: unknown.
  if (std::isfinite(m.pose_covariance[0])) {
    const double mean_var = (m.pose_covariance[0] + m.pose_covariance[6] + m.pose_covariance[11]) / 3.0;
    if (std::isfinite(mean_var) && mean_var >= 0) pose.position_std_m = std::sqrt(mean_var);
  }
  odometry_seen_ = true;
  return pose;
}

wingman::own_pose_t own_pose_message(const NedPose& pose, int64_t utime, bool enu) {
  wingman::own_pose_t m{};
  m.utime = utime;
  m.frame = enu ? wingman::own_pose_t::FRAME_ENU : wingman::own_pose_t::FRAME_NED;
  const Eigen::Vector3d p = enu ? common::swap_ned_enu(pose.p_body_in_ned) : pose.p_body_in_ned;
  const Eigen::Vector3d v = enu ? common::swap_ned_enu(pose.v_body_in_ned) : pose.v_body_in_ned;
  const Eigen::Quaterniond q = enu ? common::swap_ned_frd_enu_flu(pose.q_frd_to_ned) : pose.q_frd_to_ned.normalized();
  for (int i = 0; i < 3; ++i) {
    m.p_body_in_world[i] = p[i];
    m.v_body_in_world[i] = v[i];
  }
  m.q_body_to_world[0] = q.w();
  m.q_body_to_world[1] = q.x();
  m.q_body_to_world[2] = q.y();
  m.q_body_to_world[3] = q.z();
  return m;
}

}  // namespace wingman::mavlink_bridge
