// SPDX-License-Identifier: MIT
// Validation of OpenClOptions.
#include "wingman/detector/opencl_options.hpp"

#include <wingman/common/config.hpp>

namespace wingman::detector {

std::vector<std::string> OpenClOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (max_batch < 1 || max_batch > 64) p.push_back(problem("opencl.max_batch", max_batch, "must be in 1..64"));
  return p;
}

}  // namespace wingman::detector
