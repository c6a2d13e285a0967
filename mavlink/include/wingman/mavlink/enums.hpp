// SPDX-License-Identifier: MIT
// The MAVLink enum values Wingman uses (message_definitions/v1.0/minimal.xml, common.xml, ardupilotmega.xml).
#pragma once

#include <cstdint>

namespace wingman::mavlink {

// MAV_TYPE
constexpr uint8_t kMavTypeQuadrotor = 2;
constexpr uint8_t kMavTypeOnboardController = 18;
// MAV_AUTOPILOT
constexpr uint8_t kMavAutopilotArdupilotmega = 3;
constexpr uint8_t kMavAutopilotInvalid = 8;  ///< not an autopilot (a companion computer, a GCS)
constexpr uint8_t kMavAutopilotPx4 = 12;
// MAV_MODE_FLAG (HEARTBEAT.base_mode bits)
constexpr uint8_t kMavModeFlagCustomModeEnabled = 1;
constexpr uint8_t kMavModeFlagSafetyArmed = 128;
// MAV_STATE
constexpr uint8_t kMavStateStandby = 3;
constexpr uint8_t kMavStateActive = 4;
// MAV_COMPONENT
constexpr uint8_t kMavCompIdAutopilot1 = 1;
constexpr uint8_t kMavCompIdOnboardComputer = 191;
// MAV_FRAME
constexpr uint8_t kMavFrameLocalNed = 1;
constexpr uint8_t kMavFrameBodyFrd = 12;
constexpr uint8_t kMavFrameLocalFrd = 20;
// MAV_CMD
constexpr uint16_t kMavCmdDoSetMode = 176;           ///< param1 base_mode, param2 custom_mode (main), param3 sub mode
constexpr uint16_t kMavCmdComponentArmDisarm = 400;  ///< param1 1 arm / 0 disarm
constexpr uint16_t kMavCmdSetMessageInterval = 511;  ///< param1 message id, param2 interval us (-1 off, 0 default)
// MAV_RESULT
constexpr uint8_t kMavResultAccepted = 0;
constexpr uint8_t kMavResultTemporarilyRejected = 1;
constexpr uint8_t kMavResultDenied = 2;
constexpr uint8_t kMavResultUnsupported = 3;
constexpr uint8_t kMavResultFailed = 4;
// POSITION_TARGET_TYPEMASK (SET_POSITION_TARGET_LOCAL_NED.type_mask: set bits = ignore that field)
constexpr uint16_t kTypemaskXIgnore = 1;
constexpr uint16_t kTypemaskYIgnore = 2;
constexpr uint16_t kTypemaskZIgnore = 4;
constexpr uint16_t kTypemaskVxIgnore = 8;
constexpr uint16_t kTypemaskVyIgnore = 16;
constexpr uint16_t kTypemaskVzIgnore = 32;
constexpr uint16_t kTypemaskAxIgnore = 64;
constexpr uint16_t kTypemaskAyIgnore = 128;
constexpr uint16_t kTypemaskAzIgnore = 256;
constexpr uint16_t kTypemaskYawIgnore = 1024;
constexpr uint16_t kTypemaskYawRateIgnore = 2048;
constexpr uint16_t kTypemaskPositionIgnore = kTypemaskXIgnore | kTypemaskYIgnore | kTypemaskZIgnore;
constexpr uint16_t kTypemaskVelocityIgnore = kTypemaskVxIgnore | kTypemaskVyIgnore | kTypemaskVzIgnore;
constexpr uint16_t kTypemaskAccelerationIgnore = kTypemaskAxIgnore | kTypemaskAyIgnore | kTypemaskAzIgnore;

// PX4's custom mode (px4_custom_mode.h): main mode in bits 16..23, sub mode in bits 24..31 of custom_mode.
constexpr uint8_t kPx4MainModeOffboard = 6;
constexpr uint8_t kPx4MainModePosctl = 3;
constexpr uint8_t kPx4MainModeAuto = 4;
constexpr uint8_t kPx4SubModeAutoLoiter = 3;
/// PX4's main mode in a HEARTBEAT.custom_mode.
constexpr uint8_t px4_main_mode(uint32_t custom_mode) { return static_cast<uint8_t>((custom_mode >> 16) & 0xFF); }
/// A PX4 HEARTBEAT.custom_mode from main and sub mode.
constexpr uint32_t px4_custom_mode(uint8_t main_mode, uint8_t sub_mode = 0) {
  return (static_cast<uint32_t>(main_mode) << 16) | (static_cast<uint32_t>(sub_mode) << 24);
}
// ArduCopter's custom modes (COPTER_MODE): HEARTBEAT.custom_mode is the mode number.
constexpr uint32_t kCopterModeLoiter = 5;
constexpr uint32_t kCopterModeGuided = 4;
constexpr uint32_t kCopterModeBrake = 17;

}  // namespace wingman::mavlink
