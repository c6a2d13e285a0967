// SPDX-License-Identifier: MIT
// SequenceGapCounter: skipped sequence numbers are counted once; repeats and restarts count nothing.
#include <gtest/gtest.h>
#include <wingman/common/sequence_gaps.hpp>

#include <limits>

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

// Issue 33, finding 1: a hostile seq jump is counted in one step and cannot overflow (the detector used to loop
// once per missing number; a jump of 2^62 never ended).
TEST(SequenceGapCounter, HugeJumpsAreCountedAtOnceAndSaturateInsteadOfOverflowing) {
  constexpr int64_t kMax = std::numeric_limits<int64_t>::max();
  constexpr int64_t kMin = std::numeric_limits<int64_t>::min();
  SequenceGapCounter gaps;
  EXPECT_EQ(gaps.observe(0), 0);
  EXPECT_EQ(gaps.observe(int64_t{1} << 62), (int64_t{1} << 62) - 1);
  EXPECT_EQ(gaps.observe(kMax), kMax - (int64_t{1} << 62) - 1);
  EXPECT_EQ(gaps.total(), kMax - 2);
  EXPECT_EQ(gaps.observe(kMin), 0);     // a restart
  EXPECT_EQ(gaps.observe(kMax), kMax);  // 2^64 - 2 numbers skipped: more than int64_t holds
  EXPECT_EQ(gaps.total(), kMax);        // saturated, not wrapped
  EXPECT_EQ(gaps.observe(kMin), 0);
  EXPECT_EQ(gaps.observe(kMin + 2), 1);
  EXPECT_EQ(gaps.total(), kMax);
}

}  // namespace
}  // namespace wingman::common
