// SPDX-License-Identifier: MIT
// Which height a controller holds: the height at start, a fixed height, or the target's height plus an offset.
#pragma once

#include <optional>
#include <string>

namespace wingman::follower_ctrl {

/// How the reference height (ENU z, metres) is chosen. Every reference is raised to limits.floor_height_m.
enum class HeightMode {
  kStart,   ///< "start": the height of the first own pose the process received
  kFixed,   ///< "fixed": a configured height
  kTarget,  ///< "target": the target's height plus the formation offset's z (formation only)
};

/// "start", "fixed" or "target"; nullopt for anything else.
std::optional<HeightMode> parse_height_mode(const std::string& name);

}  // namespace wingman::follower_ctrl
