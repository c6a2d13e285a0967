// SPDX-License-Identifier: MIT
// WeightAverageOptions: the averaging schedule and its validation.
#include "wingman/training/weight_average.hpp"

#include <fmt/format.h>

#include <cmath>

namespace wingman::training {

double WeightAverageOptions::decay_at(int64_t update) const {
  return decay * (1.0 - std::exp(-static_cast<double>(update) / ramp));
}

std::vector<std::string> WeightAverageOptions::validate() const {
  std::vector<std::string> p;
  if (!(decay >= 0.0 && decay < 1.0))
    p.push_back(fmt::format("ema_decay = {}: must be in [0, 1) (0: no weight average)", decay));
  if (!(ramp > 0.0 && std::isfinite(ramp))) p.push_back(fmt::format("ema_ramp = {}: must be > 0", ramp));
  return p;
}

}  // namespace wingman::training
