// SPDX-License-Identifier: MIT
// Options of wingman-localizer (config/localizer.yaml).
#pragma once

#include <string>
#include <vector>

namespace wingman::localizer {

/// Options of the localizer process. Box-to-3D localization and tracking arrive with the localizer
/// issue; until then the process checks and counts its inputs and publishes no targets.
struct LocalizerOptions {
  std::string detections_channel = "DETECTIONS_CAM0";  ///< detections_t input channel
  std::string own_pose_channel = "OWN_POSE";           ///< own_pose_t input channel
  std::string output_channel = "TARGETS";              ///< targets_t output channel

  template <class V>
  void visit(V& v) {
    v("input.detections_channel", detections_channel, "detections_t channel from wingman-detector");
    v("input.own_pose_channel", own_pose_channel, "own_pose_t channel with the camera vehicle's pose");
    v("output.channel", output_channel, "targets_t channel to publish tracked targets on");
  }
  std::vector<std::string> validate() const;
};

}  // namespace wingman::localizer
