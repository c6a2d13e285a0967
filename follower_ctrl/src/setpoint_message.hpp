// SPDX-License-Identifier: MIT
// Internal: setpoint_t messages from ENU commands, in the autopilot's frame convention.
#pragma once

#include "wingman/follower_ctrl/velocity_command.hpp"
#include "wingman/follower_ctrl/world_frame.hpp"

#include <wingman/setpoint_t.hpp>

#include <cstdint>

namespace wingman::follower_ctrl::detail {

/// MODE_VELOCITY at `utime` in the convention `frame` (own_pose_t.FRAME_*): velocity and yaw swapped
/// to NED when frame is NED (the yaw rate changes sign: NED yaw turns about down).
wingman::setpoint_t velocity_setpoint(int64_t utime, int8_t frame, const VelocityCommand& command, int32_t track_id,
                                      int8_t detection_source);

/// MODE_HOLD at `utime`: velocity and yaw rate zero; position and yaw are the own pose's (the place
/// the autopilot holds), zero when no own pose is known; frame that of `own`, else ENU.
wingman::setpoint_t hold_setpoint(int64_t utime, const OwnState* own, int8_t detection_source);

}  // namespace wingman::follower_ctrl::detail
