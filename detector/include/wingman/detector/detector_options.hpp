// SPDX-License-Identifier: MIT
// Options of wingman-detector (config/detector.yaml).
#pragma once

#include <string>
#include <vector>

namespace wingman::detector {

/// Options of the detector process. The CNN and its OpenCL backend arrive with the detector issue;
/// until then the process checks and counts images and publishes no detections.
struct DetectorOptions {
  std::string input_channel = "IMAGE_CAM0";        ///< image_t input channel
  std::string output_channel = "DETECTIONS_CAM0";  ///< detections_t output channel
  int max_image_width = 8192;                      ///< larger images are dropped and counted, pixels
  int max_image_height = 8192;                     ///< pixels

  template <class V>
  void visit(V& v) {
    v("input.channel", input_channel, "image_t channel to read camera frames from");
    v("output.channel", output_channel, "detections_t channel to publish detections on");
    v("input.max_image_width", max_image_width, "wider images are dropped and counted, pixels");
    v("input.max_image_height", max_image_height, "taller images are dropped and counted, pixels");
  }
  std::vector<std::string> validate() const;
};

}  // namespace wingman::detector
