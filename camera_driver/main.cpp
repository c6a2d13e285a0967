// SPDX-License-Identifier: MIT
// wingman-camera-driver: publishes frames from a V4L2 camera or a video file / image folder as image_t.
#include "wingman/camera_driver/camera_driver.hpp"
#include "wingman/camera_driver/driver_loop.hpp"

#include <wingman/common/runtime.hpp>

#include <memory>

namespace {

namespace cd = wingman::camera_driver;
namespace common = wingman::common;

int run(common::Runtime& rt, const cd::CameraDriverOptions& options) {
  cd::CameraDriver driver(options.output, cd::make_source(options, std::make_shared<cd::SystemV4l2Io>(),
                                                          std::make_shared<cd::SystemClock>()));
  driver.open();  // an unreadable file (a missing device with v4l2.wait_for_device false) throws: one line, exit 1
  return cd::run_driver_loop(rt, driver, options.output.channel, options.preview);
}

}  // namespace

int main(int argc, char** argv) {
  const common::ProcessInfo info{"camera_driver", "wingman-camera-driver",
                                 "Captures frames from a V4L2 camera (or plays a video file or image folder) and "
                                 "publishes them as wingman image_t messages"};
  return common::run_process<cd::CameraDriverOptions>(info, argc, argv, run);
}
