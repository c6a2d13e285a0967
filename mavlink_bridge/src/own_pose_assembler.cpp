// SPDX-License-Identifier: MIT
// Poses from the autopilot's attitude, position and odometry messages.
#include "wingman/mavlink_bridge/own_pose_assembler.hpp"

#include <wingman/geometry/message_eigen.hpp>
#include <wingman/geometry/ned_enu.hpp>
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
  // pose_covariance: upper triangle of the 6x6 (x, y, z, roll, pitch, yaw) covariance, row by row: row x at 0..5,
  // row y at 6..10, row z at 11..14, then roll-roll 15, pitch-pitch 18, yaw-yaw 20. NaN first: unknown.
  if (!std::isnan(m.pose_covariance[0])) {
    const auto& c = m.pose_covariance;
    Eigen::Matrix3d P;
    P << c[0], c[1], c[2],  //
        c[1], c[6], c[7],   //
        c[2], c[7], c[11];
    const Eigen::Vector3d var_rpy(c[15], c[18], c[20]);
    std::string problem;
    if (!P.allFinite() || !var_rpy.allFinite())
      problem = "not finite";
    else if ((P.diagonal().array() < 0).any() || (var_rpy.array() < 0).any())
      problem = "a negative variance";
    for (int i = 0; i < 3 && problem.empty(); ++i)
      for (int j = i + 1; j < 3 && problem.empty(); ++j)
        if (std::abs(P(i, j)) > std::sqrt(P(i, i) * P(j, j)) * (1 + 1e-6) + 1e-300)
          problem = "a covariance beyond +-sqrt(var var)";
    if (problem.empty()) {
      pose.has_covariance = true;
      pose.cov_p_in_ned = P;
      pose.var_rpy_frd = var_rpy;
      pose.position_std_m = std::sqrt(P.trace() / 3.0);
    } else {
      *why = "ODOMETRY.pose_covariance: " + problem + "; the pose is published without a covariance";
    }
  }
  odometry_seen_ = true;
  return pose;
}

wingman::own_pose_t own_pose_message(const NedPose& pose, int64_t utime, bool enu) {
  wingman::own_pose_t m{};
  m.utime = utime;
  m.frame = enu ? wingman::own_pose_t::FRAME_ENU : wingman::own_pose_t::FRAME_NED;
  const Eigen::Vector3d p = enu ? geometry::swap_ned_enu(pose.p_body_in_ned) : pose.p_body_in_ned;
  const Eigen::Vector3d v = enu ? geometry::swap_ned_enu(pose.v_body_in_ned) : pose.v_body_in_ned;
  const Eigen::Quaterniond q = enu ? geometry::swap_ned_frd_enu_flu(pose.q_frd_to_ned) : pose.q_frd_to_ned.normalized();
  geometry::to_array(p, m.p_body_in_world);
  geometry::to_array(v, m.v_body_in_world);
  geometry::to_array(q, m.q_body_to_world);
  if (pose.has_covariance) {
    // Roll, pitch, yaw variances are the same for an FRD and an FLU body (the axes differ by sign only).
    const Eigen::Matrix3d C = enu ? geometry::swap_ned_enu_covariance(pose.cov_p_in_ned) : pose.cov_p_in_ned;
    m.has_covariance = true;
    geometry::to_upper_triangle(C, m.cov_p_body_in_world);
    geometry::to_array(pose.var_rpy_frd, m.var_rpy_body);
  }
  return m;
}

}  // namespace wingman::mavlink_bridge
