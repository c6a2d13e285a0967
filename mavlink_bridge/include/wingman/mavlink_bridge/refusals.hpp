// SPDX-License-Identifier: MIT
// Counted refusals: every time the bridge refuses or changes what it was asked to do, by reason.
#pragma once

#include <cstdint>
#include <map>
#include <string>

namespace wingman::mavlink_bridge {

/// Counts refusals by reason (a short snake_case word, e.g. "speed_clamped") and remembers the first message of each.
class Refusals {
 public:
  /// Counts one refusal. Returns true the first time `reason` is counted (the caller logs `message` once).
  bool count(const std::string& reason) { return ++counts_[reason] == 1; }
  int64_t count_of(const std::string& reason) const {
    auto it = counts_.find(reason);
    return it == counts_.end() ? 0 : it->second;
  }
  int64_t total() const {
    int64_t n = 0;
    for (const auto& [reason, c] : counts_) n += c;
    return n;
  }
  /// "reason n, reason n" in reason order; "none" when empty.
  std::string summary() const {
    std::string s;
    for (const auto& [reason, c] : counts_) s += (s.empty() ? "" : ", ") + reason + " " + std::to_string(c);
    return s.empty() ? "none" : s;
  }

 private:
  std::map<std::string, int64_t> counts_;
};

}  // namespace wingman::mavlink_bridge
