// SPDX-License-Identifier: MIT
// Validation of LocalizerOptions.
#include "wingman/localizer/localizer_options.hpp"

#include <wingman/common/config.hpp>

namespace wingman::localizer {

std::vector<std::string> CameraOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (camera_id < 0) p.push_back(problem("camera.camera_id", camera_id, "must be >= 0"));
  if (width < 1 || width > 16384) p.push_back(problem("camera.width", width, "must be in 1..16384"));
  if (height < 1 || height > 16384) p.push_back(problem("camera.height", height, "must be in 1..16384"));
  if (!(focal_px > 0)) p.push_back(problem("camera.focal_px", focal_px, "must be > 0"));
  if (kalibr_camera.empty()) p.push_back(problem("camera.kalibr_camera", kalibr_camera, "must not be empty"));
  return p;
}

std::vector<std::string> LocalizerOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (detections_channel.empty())
    p.push_back(problem("input.detections_channel", detections_channel, "must not be empty"));
  if (own_pose_channel.empty()) p.push_back(problem("input.own_pose_channel", own_pose_channel, "must not be empty"));
  if (output_channel.empty()) p.push_back(problem("output.channel", output_channel, "must not be empty"));
  if (class_decision != "box" && class_decision != "track")
    p.push_back(problem("classes.decision", class_decision, "must be box or track"));
  for (const auto& part : {camera.validate(), sphere.validate(), extrinsics.validate(), pose.validate(),
                           tracker.validate(), windows.validate(), time.validate()}) {
    p.insert(p.end(), part.begin(), part.end());
  }
  return p;
}

}  // namespace wingman::localizer
