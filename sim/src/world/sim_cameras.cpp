// SPDX-License-Identifier: MIT
// The cameras wingman-sim renders: the single camera of its keys or a rig file's.
#include "wingman/sim/sim_cameras.hpp"

#include <wingman/common/config.hpp>
#include <wingman/common/message_validation.hpp>
#include <wingman/geometry/calibration.hpp>

#include <fmt/format.h>

#include <stdexcept>

namespace wingman::sim {

geometry::CameraRig load_sim_rig(const SimOptions& options) {
  if (options.camera_rig.empty()) throw std::invalid_argument("load_sim_rig: cameras.rig is empty");
  // One line, as every configuration error of the process: the rig loader's lines joined by "; ".
  auto one_line = [](const std::string& text) {
    std::string out = "cameras.rig: ";
    size_t begin = 0;
    for (int line = 0; begin <= text.size(); ++line) {
      size_t end = text.find('\n', begin);
      if (end == std::string::npos) end = text.size();
      size_t from = begin;
      while (from < end && text[from] == ' ') ++from;
      out += (line == 0 ? "" : line == 1 ? " " : "; ") + text.substr(from, end - from);
      begin = end + 1;
    }
    return out;
  };
  geometry::CameraRig rig;
  try {
    rig = geometry::load_camera_rig(options.camera_rig);
  } catch (const common::ConfigError& e) {
    throw common::ConfigError(one_line(e.what()));
  }
  std::vector<std::string> problems;
  const common::ImageLimits published;  // what every subscriber of the images accepts
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    const geometry::RigCamera& c = rig.cameras[i];
    for (const std::string& p : c.camera.validate(published.max_width, published.max_height))
      problems.push_back(fmt::format("cameras[{}].{} (an image_t subscriber's limit)", i, p));
    for (const std::string* channel : {&c.image_channel, &c.detections_channel}) {
      if (*channel == options.own_pose_channel || *channel == options.ground_truth_channel)
        problems.push_back(
            fmt::format("cameras[{}]: channel '{}' is also output.own_pose_channel or "
                        "output.ground_truth_channel",
                        i, *channel));
    }
  }
  if (!problems.empty()) {
    std::string message = fmt::format("{}: {} problem{} for the simulator:", rig.source, problems.size(),
                                      problems.size() == 1 ? "" : "s");
    for (const std::string& p : problems) message += "\n  " + p;
    throw common::ConfigError(one_line(message));
  }
  return rig;
}

std::vector<SimCameraOutput> sim_cameras(const SimOptions& options) {
  std::vector<SimCameraOutput> out;
  if (options.camera_rig.empty()) {
    // The localizer's camera from the same keys (geometry::make_camera): their defaults agree.
    out.push_back(
        {SimCamera{geometry::make_camera(options.camera), geometry::Extrinsics::from_options(options.extrinsics),
                   options.camera.rate_hz, options.camera.camera_id},
         options.image_channel, options.detections_channel});
    return out;
  }
  const geometry::CameraRig rig = load_sim_rig(options);
  const double last_offset_s = options.camera_stagger_s * static_cast<double>(rig.cameras.size() - 1);
  if (last_offset_s >= 1.0 / options.camera.rate_hz)
    throw common::ConfigError(fmt::format(
        "cameras.stagger_s = {}: the last of the {} cameras of {} would expose {} s after its frame's time, not within "
        "the frame period {} s (camera.rate_hz {})",
        options.camera_stagger_s, rig.cameras.size(), rig.source, last_offset_s, 1.0 / options.camera.rate_hz,
        options.camera.rate_hz));
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    const geometry::RigCamera& c = rig.cameras[i];
    out.push_back(
        {SimCamera{geometry::make_camera(c.camera), geometry::Extrinsics::from_options(c.extrinsics),
                   options.camera.rate_hz, c.camera.camera_id, options.camera_stagger_s * static_cast<double>(i)},
         c.image_channel, c.detections_channel});
  }
  return out;
}

}  // namespace wingman::sim
