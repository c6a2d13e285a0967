// SPDX-License-Identifier: MIT
// TIMESYNC: the autopilot's boot time mapped to the pipeline's epoch microseconds.
#pragma once

#include <cstdint>
#include <deque>

namespace wingman::mavlink_bridge {

/// Estimates offset_us such that epoch_us = autopilot_boot_us + offset_us, from TIMESYNC round trips (MAVLink's
/// timesync protocol): we send ts1 = our epoch time in ns; the autopilot answers with tc1 = its boot time in ns and
/// ts1 echoed; received at our epoch time t, one sample is offset = (ts1 + t) / 2 - tc1 (the autopilot read its
/// clock half-way through the round trip). The estimate is the median of the last `window` samples whose round trip
/// was at most max_rtt; jitter is their spread. A sample more than kResetUs off the estimate (autopilot reboot,
/// clock step) starts the window again.
class TimeSync {
 public:
  static constexpr int64_t kResetUs = 1000000;

  TimeSync(int window, int64_t max_rtt_us) : window_(window), max_rtt_us_(max_rtt_us) {}

  /// A TIMESYNC response: tc1 (autopilot, ns since boot), ts1 (ours as sent, epoch ns), received at `now_epoch_ns`.
  /// Returns false when the sample was not used (round trip too long or negative).
  bool on_response(int64_t tc1_ns, int64_t ts1_ns, int64_t now_epoch_ns);

  bool synced() const { return !samples_.empty(); }
  /// epoch_us - autopilot_boot_us. Precondition: synced().
  int64_t offset_us() const { return offset_us_; }
  /// Spread of the window's samples: 1.4826 x their median absolute deviation (a standard deviation for normal
  /// noise), microseconds; 0 with fewer than 2 samples.
  double jitter_us() const { return jitter_us_; }
  /// The newest used sample's round trip, microseconds.
  int64_t last_rtt_us() const { return last_rtt_us_; }
  /// Autopilot boot time (us) to epoch us. Precondition: synced().
  int64_t to_epoch_us(int64_t autopilot_boot_us) const { return autopilot_boot_us + offset_us_; }

  int64_t samples_used() const { return used_; }
  int64_t samples_rejected() const { return rejected_; }
  int64_t resets() const { return resets_; }

 private:
  void update();

  int window_;
  int64_t max_rtt_us_;
  std::deque<int64_t> samples_;  ///< offsets, microseconds
  int64_t offset_us_ = 0;
  double jitter_us_ = 0;
  int64_t last_rtt_us_ = 0;
  int64_t used_ = 0, rejected_ = 0, resets_ = 0;
};

}  // namespace wingman::mavlink_bridge
