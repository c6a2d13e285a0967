// SPDX-License-Identifier: MIT
// Warm-up and step learning-rate schedule.
#include "wingman/training/lr_schedule.hpp"

#include <fmt/format.h>

#include <cmath>

namespace wingman::training {

double LearningRateSchedule::at(int64_t iteration) const {
  if (iteration < burn_in) return base * std::pow(static_cast<double>(iteration + 1) / burn_in, power);
  double rate = base;
  for (size_t k = 0; k < steps.size() && k < scales.size(); ++k) {
    if (steps[k] > iteration) break;
    rate *= scales[k];
  }
  return rate;
}

std::vector<std::string> LearningRateSchedule::validate() const {
  std::vector<std::string> p;
  if (!(base > 0.0)) p.push_back(fmt::format("learning_rate = {}: must be > 0", base));
  if (burn_in < 0) p.push_back(fmt::format("burn_in = {}: must be >= 0", burn_in));
  if (!(power > 0.0)) p.push_back(fmt::format("power = {}: must be > 0", power));
  if (steps.size() != scales.size())
    p.push_back(fmt::format("steps has {} entries, scales {}: must be the same", steps.size(), scales.size()));
  for (size_t k = 0; k < steps.size(); ++k)
    if (steps[k] < 0 || (k > 0 && steps[k] <= steps[k - 1]))
      p.push_back(fmt::format("steps[{}] = {}: steps must be >= 0 and increasing", k, steps[k]));
  for (size_t k = 0; k < scales.size(); ++k)
    if (!(scales[k] > 0.0)) p.push_back(fmt::format("scales[{}] = {}: must be > 0", k, scales[k]));
  return p;
}

}  // namespace wingman::training
