// SPDX-License-Identifier: MIT
// JSON string literals.
#include "wingman/common/json.hpp"

#include <fmt/format.h>

namespace wingman::common {

std::string json_string(std::string_view s) {
  std::string out = "\"";
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20) {
      out += fmt::format("\\u{:04x}", static_cast<int>(u));
    } else {
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace wingman::common
