// SPDX-License-Identifier: MIT
// The thesis network (models/tiny-yolo-thesis.cfg) for the detector's tests, defined once so that the test files of
// one unity-build batch do not each define it.
#pragma once

#include <wingman/detector/darknet_cfg.hpp>

#include "test_support.hpp"

namespace wingman::detector::test {

/// The thesis network's .cfg, parsed.
inline DarknetModel thesis() { return parse_darknet_cfg(wingman::testing::source_path("models/tiny-yolo-thesis.cfg")); }

}  // namespace wingman::detector::test
