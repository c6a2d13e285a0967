// SPDX-License-Identifier: MIT
// Names of the height modes.
#include "wingman/follower_ctrl/height_mode.hpp"

namespace wingman::follower_ctrl {

std::optional<HeightMode> parse_height_mode(const std::string& name) {
  if (name == "start") return HeightMode::kStart;
  if (name == "fixed") return HeightMode::kFixed;
  if (name == "target") return HeightMode::kTarget;
  return std::nullopt;
}

}  // namespace wingman::follower_ctrl
