// SPDX-License-Identifier: MIT
// Validation of DetectorOptions.
#include "wingman/detector/detector_options.hpp"

#include "wingman/detector/input_size.hpp"

#include <wingman/common/config.hpp>

namespace wingman::detector {

std::vector<std::string> DetectorOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (input_channel.empty()) p.push_back(problem("input.channel", input_channel, "must not be empty"));
  if (output_channel.empty()) p.push_back(problem("output.channel", output_channel, "must not be empty"));
  // At most 65536 each: the byte limit derived from them (width x height x 4) stays far inside int64_t.
  if (max_image_width < 1 || max_image_width > 65536)
    p.push_back(problem("input.max_image_width", max_image_width, "must be in 1..65536"));
  if (max_image_height < 1 || max_image_height > 65536)
    p.push_back(problem("input.max_image_height", max_image_height, "must be in 1..65536"));
  if (mode != "realtime" && mode != "replay") p.push_back(problem("input.mode", mode, "must be realtime or replay"));
  if (backend != "auto" && backend != "opencl" && backend != "cpu")
    p.push_back(problem("model.backend", backend, "must be auto, opencl or cpu"));
  if (!InputSize::parse(input_size))
    p.push_back(problem("model.input_size", input_size, "expected auto, cfg or WxH (multiples of 32, 32..4096)"));
  if (cfg.empty())
    p.push_back(problem("model.cfg", cfg, "must be a .cfg path, builtin:wingman-small or builtin:tiny-yolo-thesis"));
  for (const auto& part :
       {detection.validate(), windows.validate(), motion.validate(), opencl.validate(), time.validate()})
    p.insert(p.end(), part.begin(), part.end());
  return p;
}

}  // namespace wingman::detector
