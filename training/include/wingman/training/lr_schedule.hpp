// SPDX-License-Identifier: MIT
// Darknet's learning-rate schedule: polynomial warm-up (burn_in), then steps (the thesis's Table 2).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace wingman::training {

/// The learning rate of every iteration: during warm-up base * ((i + 1) / burn_in)^power, afterwards
/// base times the product of scales[k] over the steps[k] <= i (Darknet's `policy=steps`). Table 2 of the
/// thesis: 1e-3, then 5e-4, 1e-4, 5e-5 (scales 0.5, 0.2, 0.5).
struct LearningRateSchedule {
  double base = 1e-3;                              ///< learning rate after warm-up, > 0
  int burn_in = 1000;                              ///< warm-up iterations, >= 0 (0: none)
  double power = 4.0;                              ///< warm-up exponent, > 0
  std::vector<int> steps = {10000, 20000, 30000};  ///< iterations at which the rate is scaled, increasing
  std::vector<double> scales = {0.5, 0.2, 0.5};    ///< factor at each step, > 0; same length as steps

  /// The rate for the update of iteration `iteration` (0-based).
  double at(int64_t iteration) const;
  /// One "field = value: rule" line per invalid field; empty when valid.
  std::vector<std::string> validate() const;
};

}  // namespace wingman::training
