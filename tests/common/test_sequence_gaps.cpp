// SPDX-License-Identifier: MIT
// SequenceGapCounter: skipped sequence numbers are counted once; repeats and restarts count nothing.
#include <gtest/gtest.h>
#include <wingman/common/sequence_gaps.hpp>

namespace wingman::common {
namespace {

TEST(SequenceGapCounter, CountsSkippedNumbersOnceAndStartsOverOnARestart) {
  SequenceGapCounter gaps;
  EXPECT_EQ(gaps.observe(7), 0);   // the first message: nothing known before it
  EXPECT_EQ(gaps.observe(8), 0);   // consecutive
  EXPECT_EQ(gaps.observe(11), 2);  // 9 and 10 never arrived
  EXPECT_EQ(gaps.observe(11), 0);  // a repeat
  EXPECT_EQ(gaps.observe(0), 0);   // the source restarted its count
  EXPECT_EQ(gaps.observe(1), 0);
  EXPECT_EQ(gaps.observe(5), 3);
  EXPECT_EQ(gaps.total(), 5);
}

}  // namespace
}  // namespace wingman::common
