// SPDX-License-Identifier: MIT
// Validation of LocalizerOptions.
#include "wingman/localizer/localizer_options.hpp"

#include <wingman/common/config.hpp>
#include <wingman/geometry/camera_rig.hpp>

#include <cmath>
#include <sstream>

namespace wingman::localizer {

std::vector<std::string> CameraRigOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (!(silent_after_s > 0) || !std::isfinite(silent_after_s))
    p.push_back(problem("cameras.silent_after_s", silent_after_s, "must be finite and > 0"));
  if (max_pending < 1) p.push_back(problem("cameras.max_pending", max_pending, "must be >= 1"));
  if (!rig.empty()) {
    try {
      (void)geometry::load_camera_rig(rig);
    } catch (const std::exception& e) {  // common::ConfigError: every problem of the file, each on its own line
      // One line (the process's error is one line): "FILE: N problems in the camera rig: FILE:L: ...; FILE:L: ...".
      std::istringstream lines(e.what());
      std::string line, all;
      while (std::getline(lines, line)) {
        const size_t start = line.find_first_not_of(' ');
        if (start == std::string::npos) continue;
        all += (all.empty() ? "" : all.back() == ':' ? " " : "; ") + line.substr(start);
      }
      p.push_back(problem("cameras.rig", rig, all));
    }
  }
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
                           tracker.validate(), windows.validate(), time.validate(), cameras.validate()}) {
    p.insert(p.end(), part.begin(), part.end());
  }
  return p;
}

}  // namespace wingman::localizer
