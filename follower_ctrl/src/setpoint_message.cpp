// SPDX-License-Identifier: MIT
// Internal: setpoint_t messages from ENU commands.
#include "setpoint_message.hpp"

#include <wingman/geometry/message_eigen.hpp>

namespace wingman::follower_ctrl::detail {

wingman::setpoint_t velocity_setpoint(int64_t utime, int8_t frame, const VelocityCommand& command, int32_t track_id,
                                      int8_t detection_source) {
  const bool ned = frame == wingman::own_pose_t::FRAME_NED;
  wingman::setpoint_t s{};
  s.utime = utime;
  s.mode = wingman::setpoint_t::MODE_VELOCITY;
  s.frame = frame;
  geometry::to_array(ned ? swap_ned_enu(command.v_body_in_world) : command.v_body_in_world, s.velocity);
  s.yaw = ned ? swap_ned_enu_yaw(command.yaw_rad) : command.yaw_rad;
  s.yaw_rate = ned ? -command.yaw_rate_radps : command.yaw_rate_radps;
  s.target_track_id = track_id;
  s.detection_source = detection_source;
  return s;
}

wingman::setpoint_t hold_setpoint(int64_t utime, const OwnState* own, int8_t detection_source) {
  wingman::setpoint_t s{};
  s.utime = utime;
  s.mode = wingman::setpoint_t::MODE_HOLD;
  s.frame = own ? own->frame : wingman::own_pose_t::FRAME_ENU;
  if (own) {
    const bool ned = own->frame == wingman::own_pose_t::FRAME_NED;
    geometry::to_array(ned ? swap_ned_enu(own->p_body_in_world) : own->p_body_in_world, s.position);
    s.yaw = ned ? swap_ned_enu_yaw(own->yaw()) : own->yaw();
  }
  s.detection_source = detection_source;
  return s;
}

}  // namespace wingman::follower_ctrl::detail
