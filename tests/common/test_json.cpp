// SPDX-License-Identifier: MIT
// How Wingman writes JSON (common/json.hpp): key order, escapes, NaN and infinities, bytes that are not UTF-8.
#include <wingman/common/json.hpp>

#include <gtest/gtest.h>

#include <limits>

namespace wingman::common {
namespace {

TEST(JsonText, KeepsKeyOrderAndIndentsTwoSpaces) {
  Json j;
  j["zeta"] = 1;
  j["alpha"] = {0.5, true, nullptr};
  j["name"] = "images/val/000001.jpg";
  EXPECT_EQ(json_text(j),
            "{\n  \"zeta\": 1,\n  \"alpha\": [\n    0.5,\n    true,\n    null\n  ],\n"
            "  \"name\": \"images/val/000001.jpg\"\n}");
}

TEST(JsonText, EscapesQuotesBackslashesAndControlCharactersAndKeepsUtf8) {
  EXPECT_EQ(json_text(Json("a \"b\"\\c")), "\"a \\\"b\\\"\\\\c\"");
  EXPECT_EQ(json_text(Json("line\nnext\ttab\x01")), "\"line\\nnext\\ttab\\u0001\"");
  EXPECT_EQ(json_text(Json("caf\xc3\xa9")), "\"caf\xc3\xa9\"");
  EXPECT_EQ(json_text(Json(std::string("a\0b", 3))), "\"a\\u0000b\"");
  EXPECT_EQ(Json::parse(json_text(Json("a \"b\"\\c\n"))).get<std::string>(), "a \"b\"\\c\n");
}

TEST(JsonText, ReplacesBytesThatAreNotUtf8InsteadOfThrowing) {
  EXPECT_EQ(json_text(Json("bad\xff.png")), "\"bad\xef\xbf\xbd.png\"");  // U+FFFD
}

TEST(JsonText, WritesNanAndInfinitiesAsNull) {
  Json j = Json::array({std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                        -std::numeric_limits<double>::infinity(), 2.5});
  const Json back = Json::parse(json_text(j));
  EXPECT_TRUE(back[0].is_null());
  EXPECT_TRUE(back[1].is_null());
  EXPECT_TRUE(back[2].is_null());
  EXPECT_EQ(back[3].get<double>(), 2.5);
}

TEST(JsonText, DoublesReadBackExactly) {
  const double values[] = {0.1, 1.0 / 3.0, 6.02214076e23, -1e-300, 0.30000000000000004};
  for (const double v : values) EXPECT_EQ(Json::parse(json_text(Json(v))).get<double>(), v) << json_text(Json(v));
  EXPECT_EQ(json_text(Json(0.3)), "0.3");  // the shortest text that reads back
}

}  // namespace
}  // namespace wingman::common
