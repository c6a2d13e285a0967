// SPDX-License-Identifier: MIT
// The autopilot's pose from ATTITUDE_QUATERNION + LOCAL_POSITION_NED or from ODOMETRY, and as an own_pose_t.
#pragma once

#include <wingman/mavlink/messages.hpp>
#include <wingman/own_pose_t.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <optional>
#include <string>

namespace wingman::mavlink_bridge {

/// One pose as the autopilot measured it, in its local NED frame with an FRD body.
struct NedPose {
  int64_t time_us = 0;      ///< measurement time: autopilot boot time, microseconds (epoch_time: Unix epoch)
  bool epoch_time = false;  ///< true when the autopilot stamped it with Unix time (ODOMETRY time_usec that large)
  Eigen::Vector3d p_body_in_ned = Eigen::Vector3d::Zero();           ///< metres north, east, down
  Eigen::Vector3d v_body_in_ned = Eigen::Vector3d::Zero();           ///< m/s north, east, down
  Eigen::Quaterniond q_frd_to_ned = Eigen::Quaterniond::Identity();  ///< FRD body -> NED
  double position_std_m = -1;   ///< ODOMETRY: sqrt of the mean of its x, y, z variances; -1 unknown
  bool has_covariance = false;  ///< ODOMETRY with a valid pose_covariance: the two below are set
  Eigen::Matrix3d cov_p_in_ned = Eigen::Matrix3d::Zero();  ///< covariance of p_body_in_ned, m^2
  Eigen::Vector3d var_rpy_frd = Eigen::Vector3d::Zero();   ///< variances of roll, pitch, yaw (FRD body axes), rad^2
};

/// Where poses come from (BridgeOptions::pose_source).
enum class PoseSource { kAuto, kOdometry, kAttitudePosition };

/// Builds NedPose from the autopilot's messages. attitude_position: a pose per LOCAL_POSITION_NED, with the newest
/// ATTITUDE_QUATERNION if it is within max_attitude_age of it; odometry: a pose per ODOMETRY (pose in
/// MAV_FRAME_LOCAL_NED, velocity in MAV_FRAME_BODY_FRD or MAV_FRAME_LOCAL_NED); auto: odometry once one was used, until
/// then the pair. A message that gives no pose says why in `*why` (empty when it is simply waiting for its partner).
/// An ODOMETRY whose pose_covariance is given but not a covariance (not finite, a negative variance, a covariance
/// beyond +-sqrt(var var)) gives its pose without one and says why.
class OwnPoseAssembler {
 public:
  OwnPoseAssembler(PoseSource source, int64_t max_attitude_age_us)
      : source_(source), max_age_us_(max_attitude_age_us) {}

  std::optional<NedPose> on_attitude(const mavlink::AttitudeQuaternion& m, std::string* why);
  std::optional<NedPose> on_local_position(const mavlink::LocalPositionNed& m, std::string* why);
  std::optional<NedPose> on_odometry(const mavlink::Odometry& m, std::string* why);

 private:
  bool pair_wanted() const;
  PoseSource source_;
  int64_t max_age_us_;
  bool odometry_seen_ = false;
  std::optional<mavlink::AttitudeQuaternion> attitude_;
};

/// Unix time above which an ODOMETRY time_usec is taken as epoch time, not boot time (2001-09-09).
constexpr int64_t kEpochTimeThresholdUs = 1000000000000000;

/// `pose` as an own_pose_t stamped `utime` (epoch us): in NED with the FRD body as the autopilot gave it, or converted
/// to ENU with an FLU body (geometry/ned_enu.hpp).
wingman::own_pose_t own_pose_message(const NedPose& pose, int64_t utime, bool enu);

}  // namespace wingman::mavlink_bridge
