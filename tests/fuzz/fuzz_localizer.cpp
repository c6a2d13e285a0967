// SPDX-License-Identifier: MIT
// Fuzz target: wingman-localizer's handlers. The input is a sequence of records (fuzz_support.hpp); selector
// even = an own_pose_t payload, odd = a detections_t payload, each delivered as localizer/main.cpp does
// (Runtime's decode and validate_message, then Localizer::on_own_pose / on_detections; exceptions drop it).
// Two localizers: the default camera, and one that rescales to the detections' image size.
#include "fuzz_support.hpp"

#include <wingman/localizer/localizer.hpp>

namespace {

using namespace wingman;

localizer::Localizer make(bool scale_to_image) {
  localizer::LocalizerOptions o;
  o.camera.width = 640;
  o.camera.height = 480;
  o.camera.focal_px = 400.0;
  o.camera.scale_to_image = scale_to_image;
  return localizer::Localizer(
      o, geometry::CameraModel::pinhole(o.camera.width, o.camera.height, o.camera.focal_px, o.camera.focal_px,
                                        0.5 * o.camera.width - 0.5, 0.5 * o.camera.height - 0.5));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const common::MessageLimits limits;
  localizer::Localizer fixed = make(false);
  localizer::Localizer scaled = make(true);
  fuzz::Records records(data, size);
  uint8_t selector = 0;
  const uint8_t* payload = nullptr;
  size_t n = 0;
  for (int i = 0; i < 64 && records.next(&selector, &payload, &n); ++i) {
    localizer::Localizer& loc = (selector & 2) ? scaled : fixed;
    if (selector % 2 == 0) {
      fuzz::deliver<own_pose_t>(payload, n, limits, fuzz::default_validator<own_pose_t>(),
                                [&](const own_pose_t& p) { loc.on_own_pose(p); });
    } else {
      fuzz::deliver<detections_t>(payload, n, limits, fuzz::default_validator<detections_t>(),
                                  [&](const detections_t& d) {
                                    const localizer::LocalizerOutput out = loc.on_detections(d);
                                    if (out.targets) (void)common::validate_message(*out.targets);
                                  });
    }
  }
  return 0;
}
