// SPDX-License-Identifier: MIT
// StageClock and the checked ages (issue 33): future-dated messages refused, negative ages stale, no latching.
#include <gtest/gtest.h>
#include <wingman/common/config.hpp>
#include <wingman/common/time_sanity.hpp>

#include <limits>
#include <stdexcept>

namespace wingman::common {
namespace {

constexpr int64_t kT0 = 1700000000000000;  // a message time, microseconds
constexpr int64_t kS = 1000000;            // one second in utime units
constexpr int64_t kMax = std::numeric_limits<int64_t>::max();
constexpr int64_t kMin = std::numeric_limits<int64_t>::min();
using Verdict = TimeAdmission::Verdict;

TEST(TimeSanityOptions, DefaultsAreValidAndBadValuesAreNamed) {
  EXPECT_TRUE(TimeSanityOptions{}.validate().empty());
  TimeSanityOptions o;
  o.max_ahead_s = std::numeric_limits<double>::infinity();
  o.resync_after_s = 0;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 2u);
  EXPECT_NE(p[0].find("time.max_ahead_s = inf"), std::string::npos) << p[0];
  EXPECT_NE(p[1].find("time.resync_after_s = 0"), std::string::npos) << p[1];
  EXPECT_THROW(StageClock{o}, std::invalid_argument);
  const auto loaded = load_options_from_string<TimeSanityOptions>("time: {max_ahead_s: 0.25}\n", "t.yaml");
  EXPECT_EQ(loaded.max_ahead_us(), 250000);
}

TEST(TimeSanity, NegativeAgesBeyondTheToleranceAreStaleAndOverflowIsNeverFresh) {
  EXPECT_TRUE(is_fresh(kT0, kT0, 0));
  EXPECT_TRUE(is_fresh(kT0, kT0 - 500000, 500000));
  EXPECT_FALSE(is_fresh(kT0, kT0 - 500001, 500000));
  EXPECT_FALSE(is_fresh(kT0, kT0 + 1, 500000)) << "data from the future is not fresh";
  EXPECT_FALSE(is_fresh(kT0, kT0 + 1000 * kS, 500000));
  EXPECT_TRUE(is_fresh(kT0, kT0 + kS, 500000, kS)) << "within the cross-input tolerance";
  EXPECT_FALSE(is_fresh(kT0, kT0 + kS + 1, 500000, kS));
  EXPECT_FALSE(is_fresh(kMax, kMin, kMax));
  EXPECT_FALSE(is_fresh(kMin, kMax, kMax, kMax));
  EXPECT_FALSE(age_us(kMax, -1).has_value());
  EXPECT_EQ(*age_us(kT0, kT0 - 7), 7);
}

TEST(StageClock, AFutureDatedMessageIsRefusedAndNeverBecomesTheClock) {
  StageClock clock;
  const int pose = clock.add_input("own_pose_t.utime", "own pose", true);
  const int targets = clock.add_input("targets_t.utime", "targets_t", false);
  EXPECT_TRUE(clock.admit(pose, kT0).accepted());
  const TimeAdmission ahead = clock.admit(targets, kT0 + 1000 * kS);
  EXPECT_EQ(ahead.verdict, Verdict::kAhead);
  EXPECT_EQ(ahead.problem,
            "targets_t.utime = 1700001000000000: 1000.000 s ahead of the newest message time 1700000000000000 "
            "(time.max_ahead_s = 1)");
  EXPECT_EQ(*clock.now(), kT0);
  EXPECT_FALSE(clock.previous(targets).has_value());
  // The next real messages are taken at once: nothing latched.
  EXPECT_TRUE(clock.admit(targets, kT0 - 50000).accepted()) << "inputs may lag the clock";
  EXPECT_TRUE(clock.admit(pose, kT0 + 20000).accepted());
  EXPECT_TRUE(clock.admit(pose, kT0 + kS + 20000).accepted()) << "exactly max_ahead_s ahead is accepted";
  EXPECT_EQ(clock.admit(pose, kMax).verdict, Verdict::kAhead);
  EXPECT_EQ(*clock.now(), kT0 + kS + 20000);
}

TEST(StageClock, OrderIsPerInputDuplicatesRefusedOnStrictInputs) {
  StageClock clock;
  const int pose = clock.add_input("own_pose_t.utime", "own pose", true);
  const int targets = clock.add_input("targets_t.utime", "targets_t", false);
  EXPECT_TRUE(clock.admit(pose, kT0 + 10000).accepted());
  const TimeAdmission dup = clock.admit(pose, kT0 + 10000);
  EXPECT_EQ(dup.verdict, Verdict::kDuplicate);
  EXPECT_EQ(dup.problem,
            "own_pose_t.utime = 1700000000010000: not after the previous own pose (1700000000010000): "
            "duplicate");
  EXPECT_EQ(clock.admit(pose, kT0).verdict, Verdict::kOutOfOrder);
  EXPECT_TRUE(clock.admit(targets, kT0).accepted());
  EXPECT_TRUE(clock.admit(targets, kT0).accepted()) << "a non-strict input takes the same time again";
  EXPECT_EQ(clock.admit(targets, kT0 - 1).verdict, Verdict::kOutOfOrder);
  EXPECT_EQ(clock.admit(pose, kMin).verdict, Verdict::kOutOfOrder);
}

TEST(StageClock, ABadFirstMessageLatchesForAtMostResyncAfterSecondsOfMessageTime) {
  StageClock clock;
  const int pose = clock.add_input("own_pose_t.utime", "own pose", true);
  const int targets = clock.add_input("targets_t.utime", "targets_t", false);
  ASSERT_TRUE(clock.admit(pose, kT0 + 1000 * kS).accepted());  // nothing to compare the first message with
  ASSERT_TRUE(clock.admit(targets, kT0 + 1000 * kS).accepted());
  // The real poses at 50 Hz are refused as out of order, until they have come for time.resync_after_s.
  int refused = 0;
  int64_t t = kT0;
  for (;; t += 20000) {
    const TimeAdmission a = clock.admit(pose, t);
    if (a.accepted()) {
      EXPECT_TRUE(a.resynced());
      EXPECT_NE(a.problem.find("every own pose refused for 1.000 s of message time"), std::string::npos) << a.problem;
      break;
    }
    EXPECT_EQ(a.verdict, Verdict::kOutOfOrder);
    ASSERT_LT(++refused, 100);
  }
  EXPECT_EQ(t, kT0 + kS);
  EXPECT_EQ(refused, 50);
  EXPECT_EQ(*clock.now(), t);
  EXPECT_FALSE(clock.previous(targets).has_value()) << "the targets' bad time is forgotten with it";
  EXPECT_TRUE(clock.admit(targets, t - 30000).accepted());
  EXPECT_TRUE(clock.admit(pose, t + 20000).accepted());
  EXPECT_EQ(clock.resyncs(), 1);
}

TEST(StageClock, ASourceWhoseTimeReallyJumpedIsFollowedAfterTheResyncTime) {
  StageClock clock;
  const int pose = clock.add_input("own_pose_t.utime", "own pose", true);
  ASSERT_TRUE(clock.admit(pose, kT0).accepted());
  const int64_t later = kT0 + 3600 * kS;  // e.g. a simulation restarted an hour later
  int64_t t = later;
  while (!clock.admit(pose, t).accepted()) {
    t += 100000;
    ASSERT_LE(t, later + 2 * kS);
  }
  EXPECT_EQ(t, later + kS);
  EXPECT_EQ(*clock.now(), later + kS);
}

TEST(StageClock, InterleavedLiesNeverResyncWhileRealMessagesAreAccepted) {
  StageClock clock;
  const int pose = clock.add_input("own_pose_t.utime", "own pose", true);
  for (int k = 0; k < 500; ++k) {
    const int64_t t = kT0 + k * 20000;
    EXPECT_TRUE(clock.admit(pose, t).accepted()) << k;
    // A lie after every real message, consistent among the lies: each accepted real message ends their run.
    EXPECT_FALSE(clock.admit(pose, t + 1000 * kS).accepted()) << k;
  }
  EXPECT_EQ(clock.resyncs(), 0);
  EXPECT_EQ(*clock.now(), kT0 + 499 * 20000);
}

TEST(StageClock, ScatteredLiesDoNotFormARun) {
  StageClock clock;
  const int pose = clock.add_input("own_pose_t.utime", "own pose", true);
  ASSERT_TRUE(clock.admit(pose, kT0).accepted());
  // Two future lies far apart: each starts a run of its own (steps over time.resync_after_s), so no resync.
  EXPECT_FALSE(clock.admit(pose, kT0 + 1000 * kS).accepted());
  EXPECT_FALSE(clock.admit(pose, kT0 + 2000 * kS).accepted());
  EXPECT_FALSE(clock.admit(pose, kMax).accepted());
  EXPECT_EQ(clock.resyncs(), 0);
  EXPECT_TRUE(clock.admit(pose, kT0 + 1).accepted());
}

}  // namespace
}  // namespace wingman::common
