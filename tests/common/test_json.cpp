// SPDX-License-Identifier: MIT
// JSON string literals: quotes, backslashes and control characters escaped, everything else kept.
#include <wingman/common/json.hpp>

#include <gtest/gtest.h>

namespace wingman::common {
namespace {

TEST(JsonString, EscapesQuotesBackslashesAndControlCharacters) {
  EXPECT_EQ(json_string(""), "\"\"");
  EXPECT_EQ(json_string("images/val/000001.jpg"), "\"images/val/000001.jpg\"");
  EXPECT_EQ(json_string("a \"b\"\\c"), "\"a \\\"b\\\"\\\\c\"");
  EXPECT_EQ(json_string("line\nnext\ttab\x01"), "\"line\\u000anext\\u0009tab\\u0001\"");
  EXPECT_EQ(json_string("caf\xc3\xa9"), "\"caf\xc3\xa9\"");  // UTF-8 passes through
  EXPECT_EQ(json_string(std::string_view("a\0b", 3)), "\"a\\u0000b\"");
}

}  // namespace
}  // namespace wingman::common
