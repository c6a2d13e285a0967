// SPDX-License-Identifier: MIT
// setpoint_t (ENU or NED) to VehicleCommand (ENU).
#include "wingman/sim/vehicle_command.hpp"

#include <wingman/geometry/message_eigen.hpp>
#include <wingman/geometry/ned_enu.hpp>
#include <wingman/own_pose_t.hpp>

#include <cmath>
#include <stdexcept>
#include <string>

namespace wingman::sim {
namespace {

Eigen::Vector3d to_enu(const double (&v)[3], bool ned) {
  const Eigen::Vector3d p = geometry::to_vector3(v);
  return ned ? geometry::swap_ned_enu(p) : p;
}

}  // namespace

VehicleCommand command_from_setpoint(const wingman::setpoint_t& sp) {
  if (sp.frame != wingman::own_pose_t::FRAME_ENU && sp.frame != wingman::own_pose_t::FRAME_NED) {
    throw std::invalid_argument("setpoint_t.frame = " + std::to_string(sp.frame) + ": must be FRAME_ENU or FRAME_NED");
  }
  const bool ned = sp.frame == wingman::own_pose_t::FRAME_NED;
  VehicleCommand c;
  switch (sp.mode) {
    case wingman::setpoint_t::MODE_HOLD:
      c.mode = VehicleCommand::Mode::kHold;
      break;
    case wingman::setpoint_t::MODE_POSITION:
      c.mode = VehicleCommand::Mode::kPosition;
      c.p_ref_in_world = to_enu(sp.position, ned);
      c.yaw_ref_rad = ned ? geometry::swap_ned_enu_yaw(sp.yaw) : sp.yaw;
      break;
    case wingman::setpoint_t::MODE_VELOCITY:
      c.mode = VehicleCommand::Mode::kVelocity;
      c.v_ref_in_world = to_enu(sp.velocity, ned);
      c.yaw_rate_ref = ned ? -sp.yaw_rate : sp.yaw_rate;
      break;
    default:
      throw std::invalid_argument("setpoint_t.mode = " + std::to_string(sp.mode) +
                                  ": must be MODE_HOLD, MODE_POSITION or MODE_VELOCITY");
  }
  if (!c.p_ref_in_world.allFinite() || !c.v_ref_in_world.allFinite() || !std::isfinite(c.yaw_ref_rad) ||
      !std::isfinite(c.yaw_rate_ref)) {
    throw std::invalid_argument("setpoint_t: position, velocity, yaw and yaw_rate must be finite");
  }
  return c;
}

}  // namespace wingman::sim
