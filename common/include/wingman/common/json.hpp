// SPDX-License-Identifier: MIT
// How Wingman writes its JSON documents (nlohmann::json): key order kept, two-space indents, NaN and inf as null.
// Header-only: a target that includes it links nlohmann_json::nlohmann_json itself.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace wingman::common {

/// A JSON document under construction. Keys stay in the order they are set (the documents list them in a fixed,
/// readable order; readers must not rely on it).
using Json = nlohmann::ordered_json;

/// `j` as text, without a trailing newline: two-space indents, so a scalar member reads `"key": value` on its own
/// line. Numbers: integers exactly, doubles with the fewest digits that read back to the same double. NaN and
/// +-infinity are written as null (JSON has no such numbers; nlohmann's rule, kept deliberately: a reader sees
/// "no value", never an unparseable token). Bytes that are not UTF-8 in a string (file names are bytes) are
/// replaced by U+FFFD instead of throwing.
inline std::string json_text(const Json& j) { return j.dump(2, ' ', false, Json::error_handler_t::replace); }

}  // namespace wingman::common
