// SPDX-License-Identifier: MIT
// `wingman bench detector`'s size options: N, WxH and cfg accepted; every malformed or unaligned size named.
#include <gtest/gtest.h>
#include <wingman/tools/bench.hpp>

namespace wingman::tools {
namespace {

TEST(BenchDetectorOptions, SquareWidthByHeightAndTheCfgsOwnSizeAreValid) {
  BenchDetectorOptions o;
  o.sizes = {"416", "640x352", "cfg", "32x64"};
  EXPECT_TRUE(o.validate().empty());
}

TEST(BenchDetectorOptions, EachBadSizeIsNamed) {
  BenchDetectorOptions o;
  o.sizes = {"400", "640x350", "640x", "x352", "640x352x3", "big", "0", "640X352", "8192", " 416"};
  const std::vector<std::string> problems = o.validate();
  ASSERT_EQ(problems.size(), o.sizes.size());
  for (size_t i = 0; i < o.sizes.size(); ++i) {
    EXPECT_EQ(problems[i], "sizes = " + o.sizes[i] + ": expected N or WxH (each a multiple of 32, 32..4096) or cfg");
  }
  o.sizes.clear();
  ASSERT_EQ(o.validate().size(), 1u);
  EXPECT_EQ(o.validate()[0], "sizes = (empty): give at least one size");
}

}  // namespace
}  // namespace wingman::tools
