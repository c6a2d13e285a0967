// SPDX-License-Identifier: MIT
// The hand-computed detection case of test_detection_metrics.cpp as a YOLO dataset with saved predictions.
#pragma once

#include "test_support.hpp"

namespace wingman::training {

/// Writes into `dir`: images/val/{a,b,c}.png (400 x 400), their labels (class 1 in a: not evaluated; c: none),
/// pred/{a,b,c}.txt as `wingman predict` writes them, and data.yaml (val: images/val, names [drone, bird]).
/// The metrics: IoU >= 0.5: TP 2, FP 3 at 0.2, AP 2/3; centre in box: TP 3, FP 2, AP 1.
void write_hand_case(const testing::TempDir& dir);

}  // namespace wingman::training
