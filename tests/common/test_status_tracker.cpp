// SPDX-License-Identifier: MIT
// StatusTracker: counts per channel, drops, rates and latency percentiles in the heartbeat.
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

}  // namespace
