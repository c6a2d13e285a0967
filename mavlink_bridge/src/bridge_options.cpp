// SPDX-License-Identifier: MIT
// Validation of BridgeOptions.
#include "wingman/mavlink_bridge/bridge_options.hpp"

#include "wingman/mavlink_bridge/link.hpp"

#include <wingman/common/config.hpp>

#include <cmath>
#include <stdexcept>

namespace wingman::mavlink_bridge {

namespace {

bool positive(double x) { return std::isfinite(x) && x > 0; }

}  // namespace

std::vector<std::string> BridgeOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  try {
    make_link(link_url, baud);  // checks the URL's form and the baud rate; opens nothing
  } catch (const std::invalid_argument& e) {
    p.push_back(e.what());
  }
  if (!positive(reopen_period_s)) p.push_back(problem("link.reopen_period_s", reopen_period_s, "must be > 0"));
  if (system_id < 1 || system_id > 255) p.push_back(problem("link.system_id", system_id, "must be in 1..255"));
  if (component_id < 1 || component_id > 255)
    p.push_back(problem("link.component_id", component_id, "must be in 1..255"));
  if (autopilot_system_id < 0 || autopilot_system_id > 255)
    p.push_back(problem("autopilot.system_id", autopilot_system_id, "must be in 0..255"));
  if (autopilot_component_id < 1 || autopilot_component_id > 255)
    p.push_back(problem("autopilot.component_id", autopilot_component_id, "must be in 1..255"));
  if (autopilot != "auto" && autopilot != "px4" && autopilot != "ardupilot")
    p.push_back(problem("autopilot.kind", autopilot, "must be auto, px4 or ardupilot"));
  if (!positive(heartbeat_timeout_s))
    p.push_back(problem("autopilot.heartbeat_timeout_s", heartbeat_timeout_s, "must be > 0"));
  if (setpoint_channel.empty()) p.push_back(problem("input.setpoint_channel", setpoint_channel, "must not be empty"));
  if (own_pose_channel.empty()) p.push_back(problem("output.own_pose_channel", own_pose_channel, "must not be empty"));
  if (own_pose_frame != "enu" && own_pose_frame != "ned")
    p.push_back(problem("output.own_pose_frame", own_pose_frame, "must be enu or ned"));
  if (pose_source != "auto" && pose_source != "odometry" && pose_source != "attitude_position")
    p.push_back(problem("pose.source", pose_source, "must be auto, odometry or attitude_position"));
  if (!positive(max_attitude_age_s)) p.push_back(problem("pose.max_attitude_age_s", max_attitude_age_s, "must be > 0"));
  for (auto [key, hz] : {std::pair<const char*, double>{"rates.attitude_quaternion_hz", attitude_rate_hz},
                         {"rates.local_position_ned_hz", local_position_rate_hz},
                         {"rates.odometry_hz", odometry_rate_hz}})
    if (!std::isfinite(hz) || hz < 0 || hz > 1000) p.push_back(problem(key, hz, "must be in 0..1000"));
  if (!positive(timesync_period_s)) p.push_back(problem("time.timesync_period_s", timesync_period_s, "must be > 0"));
  if (!positive(timesync_max_rtt_s)) p.push_back(problem("time.timesync_max_rtt_s", timesync_max_rtt_s, "must be > 0"));
  if (timesync_window < 2 || timesync_window > 256)
    p.push_back(problem("time.timesync_window", timesync_window, "must be in 2..256"));
  if (!std::isfinite(stream_rate_hz) || stream_rate_hz < 2 || stream_rate_hz > 200)
    p.push_back(problem("stream.rate_hz", stream_rate_hz, "must be in 2..200 (autopilots drop offboard below 2 Hz)"));
  if (!positive(setpoint_timeout_s))
    p.push_back(problem("stream.setpoint_timeout_s", setpoint_timeout_s, "must be > 0"));
  if (!positive(max_setpoint_age_s))
    p.push_back(problem("stream.max_setpoint_age_s", max_setpoint_age_s, "must be > 0"));
  if (!std::isfinite(hover_s) || hover_s < 0) p.push_back(problem("stream.hover_s", hover_s, "must be >= 0"));
  if (!positive(max_horizontal_speed_mps))
    p.push_back(problem("limits.max_horizontal_speed_mps", max_horizontal_speed_mps, "must be > 0"));
  if (!positive(max_vertical_speed_mps))
    p.push_back(problem("limits.max_vertical_speed_mps", max_vertical_speed_mps, "must be > 0"));
  if (!positive(max_acceleration_mps2))
    p.push_back(problem("limits.max_acceleration_mps2", max_acceleration_mps2, "must be > 0"));
  if (!std::isfinite(min_altitude_m)) p.push_back(problem("limits.min_altitude_m", min_altitude_m, "must be finite"));
  if (!std::isfinite(max_altitude_m) || !(max_altitude_m > min_altitude_m))
    p.push_back(problem("limits.max_altitude_m", max_altitude_m, "must be finite and above limits.min_altitude_m"));
  return p;
}

AutopilotKind BridgeOptions::autopilot_kind() const {
  if (autopilot == "px4") return AutopilotKind::kPx4;
  if (autopilot == "ardupilot") return AutopilotKind::kArdupilot;
  return AutopilotKind::kAuto;
}

}  // namespace wingman::mavlink_bridge
