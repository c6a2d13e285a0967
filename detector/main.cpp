// SPDX-License-Identifier: MIT
// wingman-detector: camera images in, drone detections out (the CNN arrives with the detector issue).
#include "wingman/detector/detector_options.hpp"

#include <wingman/common/runtime.hpp>
#include <wingman/status_t.hpp>

int main(int argc, char** argv) {
  using namespace wingman;
  const common::ProcessInfo info{"detector", "wingman-detector", "Detects drones in camera images (OpenCL CNN)"};
  return common::run_process<detector::DetectorOptions>(
      info, argc, argv, [](common::Runtime& rt, const detector::DetectorOptions& o) {
        const common::ImageLimits limits{o.max_image_width, o.max_image_height};
        rt.status().declare_output(o.output_channel);
        rt.status().set_state(status_t::STATE_DEGRADED, "no detection model yet: images are checked and counted only");
        rt.subscribe<image_t>(
            o.input_channel, [&rt](const image_t& img) { rt.status().set_last_processed_seq(img.seq); },
            [limits](const image_t& img) { return common::validate_message(img, limits); });
        return rt.spin();
      });
}
