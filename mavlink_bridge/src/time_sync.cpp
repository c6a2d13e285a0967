// SPDX-License-Identifier: MIT
// TIMESYNC offset: median of recent round trips.
#include "wingman/mavlink_bridge/time_sync.hpp"

#include <algorithm>
#include <cstdlib>
#include <vector>

namespace wingman::mavlink_bridge {

namespace {

int64_t median(std::vector<int64_t> v) {
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  if (v.size() % 2 == 1) return v[mid];
  const int64_t upper = v[mid];
  const int64_t lower = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid));
  return lower + (upper - lower) / 2;
}

}  // namespace

bool TimeSync::on_response(int64_t tc1_ns, int64_t ts1_ns, int64_t now_epoch_ns) {
  const int64_t rtt_us = (now_epoch_ns - ts1_ns) / 1000;
  if (rtt_us < 0 || rtt_us > max_rtt_us_ || tc1_ns <= 0) {
    ++rejected_;
    return false;
  }
  const int64_t sample_us = (ts1_ns / 2 + now_epoch_ns / 2 - tc1_ns) / 1000;
  if (synced() && std::llabs(sample_us - offset_us_) > kResetUs) {
    samples_.clear();
    ++resets_;
  }
  samples_.push_back(sample_us);
  while (static_cast<int>(samples_.size()) > window_) samples_.pop_front();
  last_rtt_us_ = rtt_us;
  ++used_;
  update();
  return true;
}

void TimeSync::update() {
  const std::vector<int64_t> v(samples_.begin(), samples_.end());
  offset_us_ = median(v);
  if (v.size() < 2) {
    jitter_us_ = 0;
    return;
  }
  std::vector<int64_t> dev;
  dev.reserve(v.size());
  for (int64_t s : v) dev.push_back(std::llabs(s - offset_us_));
  jitter_us_ = 1.4826 * static_cast<double>(median(dev));
}

}  // namespace wingman::mavlink_bridge
