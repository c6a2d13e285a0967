// SPDX-License-Identifier: MIT
// Exponential moving average of a network's weights (Polyak averaging; YOLOv5's ModelEMA), for the trainer.
//
// Torch-free (the options); the averaging itself is copy_weights() / update_weight_average() in darknet_torch.hpp.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace wingman::training {

/// How the trainer averages the weights. The average after weight update i (1-based, counted from the start of
/// training, so a resumed run continues the same sequence) is
///   average_i = d_i average_{i-1} + (1 - d_i) weights_i,   d_i = decay (1 - exp(-i / ramp)),
/// starting from the weights before the first update. The ramp lets the average follow the weights closely while
/// they change fast at the start (d_1 is about decay / ramp). With decay d the average spans about 1 / (1 - d)
/// updates at the end: 0.99 -> the last ~100 iterations.
struct WeightAverageOptions {
  double decay = 0.0;  ///< 0 = no average (the default); else in (0, 1)
  double ramp = 100;   ///< iterations over which d_i rises to decay (e-folding), > 0

  bool enabled() const { return decay > 0.0; }
  /// d_i of update `update` (>= 1).
  double decay_at(int64_t update) const;
  /// One "ema_decay = ...: rule" line per invalid field; empty when valid.
  std::vector<std::string> validate() const;
};

}  // namespace wingman::training
