// SPDX-License-Identifier: MIT
// Writing JSON by hand: one string literal.
#pragma once

#include <string>
#include <string_view>

namespace wingman::common {

/// `s` as a JSON string literal, quotes included: `"` and `\` escaped, control characters (below 0x20) as
/// \u00XX; every other byte as it is (UTF-8 passes through).
std::string json_string(std::string_view s);

}  // namespace wingman::common
