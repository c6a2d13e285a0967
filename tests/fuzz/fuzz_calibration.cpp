// SPDX-License-Identifier: MIT
// Fuzz target: the calibration reader (localizer/src/calibration.cpp: ROS camera_info, OpenCV FileStorage and
// Kalibr camchain YAML), as camera.calibration reads it: from a file. Anything wrong must be a CalibrationError.
#include "fuzz_support.hpp"

#include <wingman/geometry/calibration.hpp>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static wingman::fuzz::TempFile file(".yaml");
  const std::string& path = file.write(data, size);
  try {
    const wingman::geometry::CameraModel camera = wingman::geometry::load_calibration(path, "cam0");
    (void)camera;
  } catch (const wingman::geometry::CalibrationError&) {
  }
  return 0;
}
