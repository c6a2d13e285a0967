// SPDX-License-Identifier: MIT
// One detector Box as the detection_t that wingman-detector publishes in detections_t.
#pragma once

#include "wingman/detector/box.hpp"

#include <wingman/detection_t.hpp>

#include <cstdint>

namespace wingman::detector {

/// The detection_t of `b`: centre and size (pixels of the source image), confidence, class_id (0 = drone),
/// drone_score and pass, unchanged. Every class is published; the consumers choose (the localizer tracks
/// class 0 only). Precondition: 0 <= b.class_id <= INT16_MAX (a model's class index).
inline wingman::detection_t to_detection(const Box& b) {
  wingman::detection_t d{};
  d.cx = b.cx;
  d.cy = b.cy;
  d.w = b.w;
  d.h = b.h;
  d.confidence = b.confidence;
  d.class_id = static_cast<int16_t>(b.class_id);
  d.pass_kind = static_cast<int8_t>(b.pass);
  d.drone_score = b.drone_score;
  return d;
}

}  // namespace wingman::detector
