// SPDX-License-Identifier: MIT
// StatusTracker: counts per channel, drops, rates, latency percentiles and input staleness in the heartbeat.
#include <gtest/gtest.h>
#include <wingman/common/message_validation.hpp>
#include <wingman/common/status_tracker.hpp>

namespace {

TEST(StatusTracker, HeartbeatListsDeclaredChannelsWithCountsDropsAndRates) {
  wingman::common::StatusTracker t("detector", 42);
  t.declare_input("IMAGE_CAM0");
  t.declare_output("DETECTIONS_CAM0");
  t.input("IMAGE_CAM0", 1000);
  t.input("IMAGE_CAM0", 2000);
  t.input_dropped("IMAGE_CAM0", "bad image");
  t.output("DETECTIONS_CAM0", 2000);
  t.item_dropped("IMAGE_CAM0", "one box");
  t.source_dropped("DETECTIONS_CAM0", 3, "gap");
  t.set_last_processed_seq(7);
  const wingman::status_t s = t.heartbeat(5, 6, 2.0);
  EXPECT_EQ(s.process, "detector");
  EXPECT_EQ(s.pid, 42);
  EXPECT_EQ(s.num_channels, 2);
  ASSERT_EQ(s.channels.size(), 2u);
  EXPECT_EQ(s.channels[0].channel, "IMAGE_CAM0");
  EXPECT_EQ(s.channels[0].count, 3);
  EXPECT_EQ(s.channels[0].drops, 2);
  EXPECT_FLOAT_EQ(s.channels[0].rate_hz, 1.5f);
  EXPECT_EQ(s.channels[1].drops, 3);
  EXPECT_EQ(s.drops_total, 5);
  EXPECT_EQ(s.messages_handled, 3);
  EXPECT_EQ(s.last_input_utime, 2000);
  EXPECT_EQ(s.last_processed_seq, 7);
  EXPECT_EQ(s.last_error, "gap");
  EXPECT_EQ(wingman::common::validate_message(s), "");
  // Rates restart after each heartbeat; totals do not.
  const wingman::status_t s2 = t.heartbeat(7, 8, 1.0);
  EXPECT_FLOAT_EQ(s2.channels[0].rate_hz, 0.0f);
  EXPECT_EQ(s2.channels[0].count, 3);
}

TEST(StatusTracker, LatencyPercentilesMatchNearestRankOverTheWindow) {
  wingman::common::StatusTracker t("p", 1, 100);
  for (int i = 200; i >= 1; --i) t.record_latency_ms(i);  // window keeps the newest 100: 100..1
  const wingman::status_t s = t.heartbeat(0, 0, 1.0);
  EXPECT_FLOAT_EQ(s.latency_p50_ms, 50.0f);
  EXPECT_FLOAT_EQ(s.latency_p90_ms, 90.0f);
  EXPECT_FLOAT_EQ(s.latency_p99_ms, 99.0f);
  EXPECT_FLOAT_EQ(s.latency_max_ms, 100.0f);
}

constexpr int64_t kS = 1000000;  // one second in microseconds
// Copies of the LCM constants (the generated static members have no definition to bind a reference to).
constexpr int8_t kOk = wingman::status_t::STATE_OK;
constexpr int8_t kDegraded = wingman::status_t::STATE_DEGRADED;
constexpr int8_t kError = wingman::status_t::STATE_ERROR;
constexpr int8_t kStopping = wingman::status_t::STATE_STOPPING;

TEST(StatusTracker, OkWithFreshInputsStaysOk) {
  wingman::common::StatusTracker t("localizer", 1);
  t.declare_input("DETECTIONS_CAM0");
  t.set_state(kOk, "");
  for (int i = 0; i < 5; ++i) {
    t.input("DETECTIONS_CAM0", i);
    const wingman::status_t s = t.heartbeat(100 * kS + i * kS, 0, 1.0);
    EXPECT_EQ(s.state, kOk) << s.detail;
    EXPECT_EQ(s.detail, "");
  }
}

TEST(StatusTracker, AnInputSilentForLongerThanStaleAfterIsNamedAndOkBecomesDegraded) {
  wingman::common::StatusTracker t("localizer", 1);
  EXPECT_DOUBLE_EQ(t.stale_after_s(), 3.0);  // the default
  t.set_stale_after_s(2.0);
  t.declare_input("DETECTIONS_CAM0");
  t.declare_input("OWN_POSE");
  t.set_state(kOk, "tracking");
  t.input("DETECTIONS_CAM0", 1);
  t.input("OWN_POSE", 1);
  EXPECT_EQ(t.heartbeat(10 * kS, 0, 1.0).state, kOk);
  // Own poses keep coming; detections stop. 2.0 s after the last window with one: still fresh (not more than).
  t.input("OWN_POSE", 2);
  EXPECT_EQ(t.heartbeat(11 * kS, 0, 1.0).state, kOk);
  t.input("OWN_POSE", 3);
  EXPECT_EQ(t.heartbeat(12 * kS, 0, 1.0).state, kOk);
  t.input("OWN_POSE", 4);
  const wingman::status_t s = t.heartbeat(13 * kS, 0, 1.0);
  EXPECT_EQ(s.state, kDegraded);
  EXPECT_EQ(s.detail, "tracking; stale input: no message on DETECTIONS_CAM0 for 3.0 s");
  EXPECT_EQ(t.state(), kOk);  // the process's own state is unchanged
  // Dropped messages are not fresh data.
  t.input_dropped("DETECTIONS_CAM0", "bad");
  t.input("OWN_POSE", 5);
  EXPECT_EQ(t.heartbeat(14 * kS, 0, 1.0).state, kDegraded);
  // A handled message makes it fresh again.
  t.input("DETECTIONS_CAM0", 6);
  t.input("OWN_POSE", 6);
  const wingman::status_t back = t.heartbeat(15 * kS, 0, 1.0);
  EXPECT_EQ(back.state, kOk);
  EXPECT_EQ(back.detail, "tracking");
}

TEST(StatusTracker, AnInputThatNeverHadAMessageIsStaleAfterStaleAfterFromTheFirstHeartbeat) {
  wingman::common::StatusTracker t("detector", 1);
  t.set_stale_after_s(5.0);
  EXPECT_DOUBLE_EQ(t.stale_after_s(), 5.0);
  t.declare_input("IMAGE_CAM0");
  t.set_state(kOk, "");
  EXPECT_EQ(t.heartbeat(20 * kS, 0, 1.0).state, kOk);
  EXPECT_EQ(t.heartbeat(25 * kS, 0, 1.0).state, kOk);
  const wingman::status_t s = t.heartbeat(26 * kS, 0, 1.0);
  EXPECT_EQ(s.state, kDegraded);
  EXPECT_EQ(s.detail, "stale input: no message yet on IMAGE_CAM0 (6.0 s)");
}

TEST(StatusTracker, ErrorAndDegradedKeepTheirStateWithTheStaleInputAddedStoppingIsLeftAlone) {
  wingman::common::StatusTracker t("camera_driver", 1);
  t.set_stale_after_s(2.0);
  t.declare_input("A");
  t.heartbeat(0, 0, 1.0);
  t.set_state(kError, "camera unplugged");
  wingman::status_t s = t.heartbeat(3 * kS, 0, 1.0);
  EXPECT_EQ(s.state, kError);
  EXPECT_EQ(s.detail, "camera unplugged; stale input: no message yet on A (3.0 s)");
  t.set_state(kDegraded, "");
  s = t.heartbeat(4 * kS, 0, 1.0);
  EXPECT_EQ(s.state, kDegraded);
  EXPECT_EQ(s.detail, "stale input: no message yet on A (4.0 s)");
  t.set_state(kStopping, "signal 15");
  s = t.heartbeat(5 * kS, 0, 1.0);
  EXPECT_EQ(s.state, kStopping);
  EXPECT_EQ(s.detail, "signal 15");
}

TEST(StatusTracker, OnlyDeclaredInputsAreWatchedAChannelOnlySeenIsNot) {
  // A recorder takes every channel: one that came once (LCM_SELF_TEST) and went quiet is not a stale input.
  wingman::common::StatusTracker t("recorder", 1);
  t.set_stale_after_s(2.0);
  t.set_state(kOk, "recording");
  t.input("LCM_SELF_TEST", 1);
  EXPECT_EQ(t.heartbeat(0, 0, 1.0).state, kOk);
  const wingman::status_t s = t.heartbeat(10 * kS, 0, 1.0);
  EXPECT_EQ(s.state, kOk);
  EXPECT_EQ(s.detail, "recording");
}

TEST(StatusTracker, OutputsAreNeverStale) {
  wingman::common::StatusTracker t("camera_driver", 1);
  t.declare_output("IMAGE_CAM0");
  t.set_state(kOk, "file clip.avi");
  t.heartbeat(0, 0, 1.0);
  EXPECT_EQ(t.heartbeat(60 * kS, 0, 60.0).state, kOk);
}

// Issue 33, finding 5: the recorder's heartbeat listed every channel name ever seen (8.4 MB after 200 k names).
TEST(StatusTracker, AFloodOfChannelNamesSharesOneEntryAndTheHeartbeatStaysBounded) {
  using wingman::common::StatusTracker;
  StatusTracker t("recorder", 7);
  t.declare_input("IMAGE_CAM0");
  for (int i = 0; i < 200000; ++i) t.input("FLOOD_" + std::to_string(i), 0);
  t.declare_output("LATE_DECLARED");  // declared channels are always listed
  const wingman::status_t s = t.heartbeat(0, 0, 1.0);
  EXPECT_EQ(s.num_channels, static_cast<int32_t>(StatusTracker::kMaxChannels) + 2);
  EXPECT_LT(s.getEncodedSize(), 64 * 1024);
  int64_t counted = 0;
  for (const auto& c : s.channels) counted += c.count;
  EXPECT_EQ(counted, 200000) << "every message is still counted";
  EXPECT_EQ(t.input_count(StatusTracker::kOtherChannels),
            200000 - static_cast<int64_t>(StatusTracker::kMaxChannels) + 1);
  EXPECT_EQ(t.messages_handled(), 200000);
}

}  // namespace
