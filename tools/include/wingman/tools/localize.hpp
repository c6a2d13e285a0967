// SPDX-License-Identifier: MIT
// `wingman localize`: one box through a calibration file to a direction, a range and a camera-frame position.
#pragma once

#include <wingman/localizer/sphere_localizer.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace wingman::tools {

/// Options of `wingman localize`.
struct LocalizeToolOptions {
  std::string calibration;             ///< calibration file (ROS camera_info, OpenCV FileStorage or Kalibr YAML)
  std::string kalibr_camera = "cam0";  ///< camera entry of a Kalibr camchain
  std::vector<double> box;             ///< cx, cy, w, h in pixels (origin at the top-left pixel's corner)
  std::string image_size;              ///< "WxH" of the images the box comes from ("" = the calibration's)
  bool scale_calibration = false;      ///< scale the calibration to image_size instead of failing on a mismatch
  bool json = false;                   ///< print one JSON object instead of text
  localizer::SphereLocalizerOptions localizer;  ///< radius, range method and limits, noise, border margin
};

/// Runs `wingman localize`: loads the calibration, localizes the box, prints the result on `out`.
/// Returns the exit code: 0 localized (also when the range is invalid because the box is cut on both axes: the
/// output says so), 1 the box is rejected or the calibration cannot be used, 2 bad arguments. Errors are one line
/// on `err` ("wingman localize: error: ...").
int run_localize(const LocalizeToolOptions& options, std::ostream& out, std::ostream& err);

}  // namespace wingman::tools
