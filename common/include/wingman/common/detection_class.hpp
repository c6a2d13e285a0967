// SPDX-License-Identifier: MIT
// The detector model's classes (detection_t.class_id): 0 is the drone, the others are distractors.
#pragma once

#include <array>
#include <string>

namespace wingman::common {

/// detection_t.class_id of a drone: the one class wingman-localizer tracks and the 1-D follower flies on.
/// A single-class model reports only this class.
inline constexpr int kDroneClassId = 0;

/// The multi-class model's class names by class_id (the order of its training labels; models/wingman-small.md).
inline constexpr std::array<const char*, 4> kDetectionClassNames = {"drone", "airplane", "bird", "helicopter"};

/// "drone", "airplane", "bird" or "helicopter" for class_id 0..3; "class <N>" for any other id (a model with more
/// classes than these, or a bad id: the name is for messages and counts, never for a decision).
inline std::string detection_class_name(int class_id) {
  if (class_id >= 0 && class_id < static_cast<int>(kDetectionClassNames.size())) return kDetectionClassNames[class_id];
  return "class " + std::to_string(class_id);
}

}  // namespace wingman::common
