// SPDX-License-Identifier: MIT
// Non-maximum suppression (Algorithm 1 of the thesis).
#pragma once

#include "wingman/detector/box.hpp"

#include <vector>

namespace wingman::detector {

/// Algorithm 1, in place: sorts `boxes` by confidence, descending (stable: ties keep their order), then
/// repeatedly keeps the most confident remaining box and removes every other remaining box whose IoU
/// with it exceeds `o_thresh` (strictly greater). On return `boxes` holds the kept boxes, most confident
/// first. No allocation. Precondition: 0 <= o_thresh <= 1.
void non_max_suppression(std::vector<Box>& boxes, float o_thresh);

}  // namespace wingman::detector
