// SPDX-License-Identifier: MIT
// TIMESYNC offset estimation against a skewed, drifting and noisy autopilot clock.
#include <wingman/mavlink_bridge/time_sync.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using wingman::mavlink_bridge::TimeSync;

namespace {

/// An autopilot clock: boot time (ns) at our epoch time t (ns), skewed by its boot and drifting by `ppm`.
struct AutopilotClock {
  int64_t boot_epoch_ns;  ///< our epoch time at the autopilot's boot
  double ppm;             ///< its rate error, parts per million
  int64_t boot_ns(int64_t epoch_ns) const {
    return static_cast<int64_t>(static_cast<double>(epoch_ns - boot_epoch_ns) * (1.0 + ppm * 1e-6));
  }
};

}  // namespace

TEST(TimeSync, TracksASkewedDriftingClockWithinItsJitter) {
  // Epoch 2026-12-05, the autopilot booted 1234.5 s earlier and runs 200 ppm fast; round trips 2..12 ms, split
  // unevenly (up to 2 ms asymmetry); a request every 0.5 s for 10 minutes.
  const int64_t t0 = 1796428800LL * 1000000000LL;
  const AutopilotClock ap{t0 - 1234500000000LL, 200.0};
  TimeSync sync(16, 50000);
  std::mt19937 rng(11);
  std::uniform_int_distribution<int64_t> rtt_ns(2000000, 12000000);
  std::uniform_int_distribution<int64_t> asym_ns(-1000000, 1000000);
  double worst_us = 0;
  for (int i = 0; i < 1200; ++i) {
    const int64_t sent = t0 + i * 500000000LL;
    const int64_t rtt = rtt_ns(rng);
    const int64_t at_autopilot = sent + rtt / 2 + asym_ns(rng);
    ASSERT_TRUE(sync.on_response(ap.boot_ns(at_autopilot), sent, sent + rtt));
    if (i < 16) continue;
    // Map a measurement the autopilot stamps now: its boot time -> our epoch; compare with the truth.
    const int64_t truth_ns = sent + rtt;
    const int64_t mapped_us = sync.to_epoch_us(ap.boot_ns(truth_ns) / 1000);
    worst_us = std::max(worst_us, std::abs(static_cast<double>(mapped_us - truth_ns / 1000)));
  }
  // Bound: the 1 ms asymmetry, plus the drift over half the 8 s window (200 ppm x 4 s = 0.8 ms), plus rounding.
  EXPECT_LT(worst_us, 2000.0);
  EXPECT_GT(sync.jitter_us(), 0.0);
  EXPECT_LT(sync.jitter_us(), 2000.0);
  EXPECT_EQ(sync.resets(), 0);
}

TEST(TimeSync, LongRoundTripsAreNotUsed) {
  TimeSync sync(4, 10000);
  EXPECT_FALSE(sync.on_response(1000000000, 5000000000, 5000000000 + 20000000));  // 20 ms > 10 ms
  EXPECT_FALSE(sync.synced());
  EXPECT_FALSE(sync.on_response(1000000000, 5000000000, 4000000000));  // negative round trip
  EXPECT_TRUE(sync.on_response(1000000000, 5000000000, 5000000000 + 2000000));
  EXPECT_EQ(sync.offset_us(), (5001000000 - 1000000000) / 1000);
  EXPECT_EQ(sync.samples_rejected(), 2);
}

TEST(TimeSync, AnAutopilotRebootStartsTheEstimateAgain) {
  TimeSync sync(8, 50000);
  const int64_t t0 = 1796428800LL * 1000000000LL;
  for (int i = 0; i < 8; ++i)
    sync.on_response(100000000000LL + i * 500000000LL, t0 + i * 500000000LL, t0 + i * 500000000LL + 2000000);
  const int64_t before = sync.offset_us();
  // It rebooted: its clock restarts near zero.
  const int64_t t1 = t0 + 8 * 500000000LL;
  sync.on_response(3000000000LL, t1, t1 + 2000000);
  EXPECT_EQ(sync.resets(), 1);
  EXPECT_EQ(sync.offset_us(), (t1 + 1000000 - 3000000000LL) / 1000);
  EXPECT_NE(sync.offset_us(), before);
}
