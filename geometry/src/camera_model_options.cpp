// SPDX-License-Identifier: MIT
// Validation of CameraModelOptions (the camera.* keys shared by wingman-localizer and wingman-sim).
#include "wingman/geometry/camera_model_options.hpp"

#include <fmt/format.h>
#include <wingman/common/config.hpp>

#include <cmath>

namespace wingman::geometry {

std::vector<std::string> CameraModelOptions::validate(int max_width_px, int max_height_px) const {
  using common::problem;
  std::vector<std::string> p;
  if (kalibr_camera.empty()) p.push_back(problem("camera.kalibr_camera", kalibr_camera, "must not be empty"));
  if (camera_id < 0) p.push_back(problem("camera.camera_id", camera_id, "must be >= 0"));
  if (width < 1 || width > max_width_px)
    p.push_back(problem("camera.width", width, fmt::format("must be in 1..{}", max_width_px)));
  if (height < 1 || height > max_height_px)
    p.push_back(problem("camera.height", height, fmt::format("must be in 1..{}", max_height_px)));
  if (!(focal_px > 0) || !std::isfinite(focal_px))
    p.push_back(problem("camera.focal_px", focal_px, "must be finite and > 0"));
  return p;
}

}  // namespace wingman::geometry
