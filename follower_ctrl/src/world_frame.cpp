// SPDX-License-Identifier: MIT
// Own state in ENU/FLU, NED <-> ENU conversions and angle helpers.
#include "wingman/follower_ctrl/world_frame.hpp"

#include <wingman/geometry/message_eigen.hpp>

#include <Eigen/Geometry>

#include <cmath>

namespace wingman::follower_ctrl {

OwnState OwnState::predicted_to(int64_t to_utime) const {
  OwnState out = *this;
  out.utime = to_utime;
  out.p_body_in_world = p_body_in_world + v_body_in_world * (static_cast<double>(to_utime - utime) * 1e-6);
  return out;
}

double OwnState::yaw() const { return std::atan2(R_body_to_world(1, 0), R_body_to_world(0, 0)); }

OwnState own_state_from_message(const wingman::own_pose_t& m) {
  OwnState s;
  s.utime = m.utime;
  s.frame = m.frame;
  const Eigen::Vector3d p = geometry::to_vector3(m.p_body_in_world);
  const Eigen::Vector3d v = geometry::to_vector3(m.v_body_in_world);
  const Eigen::Matrix3d R = geometry::to_quaternion(m.q_body_to_world).normalized().toRotationMatrix();
  if (m.frame == wingman::own_pose_t::FRAME_NED) {
    s.p_body_in_world = swap_ned_enu(p);
    s.v_body_in_world = swap_ned_enu(v);
    s.R_body_to_world = geometry::swap_ned_frd_enu_flu(R);
  } else {
    s.p_body_in_world = p;
    s.v_body_in_world = v;
    s.R_body_to_world = R;
  }
  return s;
}

bool horizontal_azimuth(const Eigen::Vector3d& v, double min_horizontal, double* azimuth_rad) {
  if (std::hypot(v.x(), v.y()) < min_horizontal) return false;
  *azimuth_rad = std::atan2(v.y(), v.x());
  return true;
}

}  // namespace wingman::follower_ctrl
