// SPDX-License-Identifier: MIT
// Validation of LocalizerOptions.
#include "wingman/localizer/localizer_options.hpp"

#include <wingman/common/config.hpp>

namespace wingman::localizer {

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
