// SPDX-License-Identifier: MIT
// Validation of SimOptions.
#include "wingman/sim/sim_options.hpp"

#include <wingman/common/config.hpp>
#include <wingman/common/message_validation.hpp>

#include <cmath>
#include <set>

namespace wingman::sim {

using common::problem;

std::vector<std::string> SimCameraOptions::validate() const {
  const common::ImageLimits published;  // what every subscriber of the images accepts
  std::vector<std::string> p = CameraModelOptions::validate(published.max_width, published.max_height);
  if (!(rate_hz > 0 && rate_hz <= 1000)) p.push_back(problem("camera.rate_hz", rate_hz, "must be in (0, 1000]"));
  return p;
}

std::vector<std::string> TruthDetectionOptions::validate() const {
  std::vector<std::string> p;
  if (box != "silhouette" && box != "sphere")
    p.push_back(problem("detections.box", box, "must be silhouette or sphere"));
  if (!(noise_px >= 0) || !std::isfinite(noise_px))
    p.push_back(problem("detections.noise_px", noise_px, "must be >= 0"));
  if (seed < 0) p.push_back(problem("detections.seed", static_cast<double>(seed), "must be >= 0"));
  if (!(min_size_px >= 0) || !std::isfinite(min_size_px))
    p.push_back(problem("detections.min_size_px", min_size_px, "must be >= 0"));
  if (!(max_range_m >= 0) || !std::isfinite(max_range_m))
    p.push_back(problem("detections.max_range_m", max_range_m, "must be >= 0 (0 = no limit)"));
  return p;
}

std::vector<std::string> SyncOptions::validate() const {
  std::vector<std::string> p;
  if (mode != "lockstep" && mode != "free" && mode != "realtime")
    p.push_back(problem("sync.mode", mode, "must be lockstep, free or realtime"));
  if (!(timeout_s > 0 && timeout_s <= 3600)) p.push_back(problem("sync.timeout_s", timeout_s, "must be in (0, 3600]"));
  if (!(speed > 0 && speed <= 1000)) p.push_back(problem("sync.speed", speed, "must be in (0, 1000]"));
  if (!(max_speed >= 0 && max_speed <= 1e6))
    p.push_back(problem("sync.max_speed", max_speed, "must be 0 (no cap) or in (0, 1e6]"));
  if (!(startup_timeout_s > 0 && startup_timeout_s <= 3600))
    p.push_back(problem("sync.startup_timeout_s", startup_timeout_s, "must be in (0, 3600]"));
  std::set<std::string> seen;
  for (const auto& name : wait_for) {
    if (name.empty()) p.push_back(problem("sync.wait_for", name, "names must not be empty"));
    if (!seen.insert(name).second) p.push_back(problem("sync.wait_for", name, "listed twice"));
  }
  return p;
}

std::vector<std::string> SimOptions::validate() const {
  std::vector<std::string> p;
  auto channel = [&](const char* key, const std::string& value) {
    if (value.empty()) p.push_back(problem(key, value, "must not be empty"));
  };
  channel("input.setpoint_channel", setpoint_channel);
  channel("output.image_channel", image_channel);
  channel("output.own_pose_channel", own_pose_channel);
  channel("output.ground_truth_channel", ground_truth_channel);
  channel("output.detections_channel", detections_channel);
  if (!(camera_stagger_s >= 0) || !std::isfinite(camera_stagger_s))
    p.push_back(problem("cameras.stagger_s", camera_stagger_s, "must be >= 0 (0 = cameras exposed together)"));
  else if (camera_stagger_s > 0 && camera_rig.empty())
    p.push_back(
        problem("cameras.stagger_s", camera_stagger_s, "needs cameras.rig (one camera has nothing to stagger)"));
  if (autopilot != "lcm" && autopilot != "mavlink")
    p.push_back(problem("autopilot", autopilot, "must be lcm or mavlink"));
  for (const auto& part :
       {camera.validate(), extrinsics.validate(), detections.validate(), sync.validate(), render_options.validate(),
        mavlink.validate(), own_pose_error.validate(), preview.validate()}) {
    p.insert(p.end(), part.begin(), part.end());
  }
  return p;
}

}  // namespace wingman::sim
