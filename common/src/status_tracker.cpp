// SPDX-License-Identifier: MIT
// Status bookkeeping and heartbeat construction.
#include "wingman/common/status_tracker.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace wingman::common {
namespace {
// Copies of lcm-gen's in-class constants, which have no out-of-class definition: binding those to a
// reference (std::pair, std::map::find) fails to link in unoptimised builds.
constexpr int8_t kIn = wingman::channel_stats_t::DIRECTION_IN;
constexpr int8_t kOut = wingman::channel_stats_t::DIRECTION_OUT;

// a + b for b >= 0, saturated at INT64_MAX (drop counts from hostile sequence gaps can be that large).
int64_t saturating_add(int64_t a, int64_t b) {
  int64_t sum = 0;
  return __builtin_add_overflow(a, b, &sum) ? std::numeric_limits<int64_t>::max() : sum;
}
}  // namespace

StatusTracker::StatusTracker(std::string process, int32_t pid, size_t latency_window)
    : process_(std::move(process)),
      pid_(pid),
      latency_window_(std::max<size_t>(1, latency_window)),
      state_(wingman::status_t::STATE_STARTING) {}

StatusTracker::Channel& StatusTracker::channel(const std::string& name, int8_t direction, bool declaring) {
  auto key = std::make_pair(name, direction);
  auto it = channels_.find(key);
  if (it == channels_.end() && !declaring && channels_.size() >= kMaxChannels) {
    // A table that grew with every name ever seen made the recorder's heartbeat 8.4 MB after 200k names (issue 33).
    key = std::make_pair(std::string(kOtherChannels), direction);
    it = channels_.find(key);
  }
  if (it == channels_.end()) {
    it = channels_.emplace(key, Channel{}).first;
    it->second.direction = direction;
    channel_order_.push_back(key);
  }
  return it->second;
}

void StatusTracker::declare_input(const std::string& ch) { channel(ch, kIn, true).declared = true; }
void StatusTracker::declare_output(const std::string& ch) { channel(ch, kOut, true); }

void StatusTracker::input(const std::string& ch, int64_t utime) {
  Channel& c = channel(ch, kIn);
  ++c.count;
  ++c.window_count;
  ++c.window_handled;
  c.last_utime = utime;
  last_input_utime_ = std::max(last_input_utime_, utime);
  ++messages_handled_;
}

void StatusTracker::input_dropped(const std::string& ch, const std::string& reason) {
  Channel& c = channel(ch, kIn);
  ++c.count;
  ++c.window_count;
  ++c.drops;
  ++drops_total_;
  ++messages_handled_;
  last_error_ = reason;
}

void StatusTracker::items_dropped(const std::string& ch, int64_t count, const std::string& reason) {
  Channel& c = channel(ch, kIn);
  const int64_t n = std::max<int64_t>(0, count);
  c.drops = saturating_add(c.drops, n);
  drops_total_ = saturating_add(drops_total_, n);
  last_error_ = reason;
}

void StatusTracker::output(const std::string& ch, int64_t utime) {
  Channel& c = channel(ch, kOut);
  ++c.count;
  ++c.window_count;
  c.last_utime = utime;
}

void StatusTracker::source_dropped(const std::string& ch, int64_t count, const std::string& reason) {
  Channel& c = channel(ch, kOut);
  c.drops += count;
  drops_total_ += count;
  last_error_ = reason;
}

void StatusTracker::record_latency_ms(double latency_ms) {
  latencies_ms_.push_back(static_cast<float>(latency_ms));
  while (latencies_ms_.size() > latency_window_) latencies_ms_.pop_front();
}

void StatusTracker::set_state(int8_t state, const std::string& detail) {
  state_ = state;
  detail_ = detail;
}

int64_t StatusTracker::input_count(const std::string& ch) const {
  auto it = channels_.find({ch, kIn});
  return it == channels_.end() ? 0 : it->second.count;
}
int64_t StatusTracker::input_drops(const std::string& ch) const {
  auto it = channels_.find({ch, kIn});
  return it == channels_.end() ? 0 : it->second.drops;
}
int64_t StatusTracker::output_count(const std::string& ch) const {
  auto it = channels_.find({ch, kOut});
  return it == channels_.end() ? 0 : it->second.count;
}

wingman::status_t StatusTracker::heartbeat(int64_t wall_utime, int64_t uptime_us, double window_s) {
  wingman::status_t s;
  s.utime = wall_utime;
  s.process = process_;
  s.pid = pid_;
  if (first_heartbeat_wall_utime_ < 0) first_heartbeat_wall_utime_ = wall_utime;
  // Input freshness (see the class comment): channels with a handled message in this window are fresh now.
  std::string stale;
  for (const auto& key : channel_order_) {
    if (key.second != kIn) continue;
    Channel& c = channels_.at(key);
    if (c.window_handled > 0) c.fresh_wall_utime = wall_utime;
    c.window_handled = 0;
    if (!c.declared) continue;
    const int64_t since = c.fresh_wall_utime >= 0 ? c.fresh_wall_utime : first_heartbeat_wall_utime_;
    const double silent_s = static_cast<double>(wall_utime - since) * 1e-6;
    if (silent_s <= stale_after_s_) continue;
    stale += stale.empty() ? "stale input: " : ", ";
    stale += c.fresh_wall_utime >= 0 ? fmt::format("no message on {} for {:.1f} s", key.first, silent_s)
                                     : fmt::format("no message yet on {} ({:.1f} s)", key.first, silent_s);
  }
  s.state = state_;
  s.detail = detail_;
  if (!stale.empty() && state_ != wingman::status_t::STATE_STOPPING) {
    if (state_ == wingman::status_t::STATE_OK) s.state = wingman::status_t::STATE_DEGRADED;
    s.detail = detail_.empty() ? stale : detail_ + "; " + stale;
  }
  s.uptime_us = uptime_us;
  s.last_input_utime = last_input_utime_;
  s.last_processed_seq = last_processed_seq_;
  s.messages_handled = messages_handled_;
  s.drops_total = drops_total_;
  std::vector<float> sorted(latencies_ms_.begin(), latencies_ms_.end());
  std::sort(sorted.begin(), sorted.end());
  auto pct = [&](double p) -> float {
    if (sorted.empty()) return 0.0f;
    const size_t i = static_cast<size_t>(std::ceil(p * static_cast<double>(sorted.size())));
    return sorted[std::min(sorted.size() - 1, i == 0 ? 0 : i - 1)];
  };
  s.latency_p50_ms = pct(0.50);
  s.latency_p90_ms = pct(0.90);
  s.latency_p99_ms = pct(0.99);
  s.latency_max_ms = sorted.empty() ? 0.0f : sorted.back();
  s.last_error = last_error_;
  for (const auto& key : channel_order_) {
    Channel& c = channels_.at(key);
    wingman::channel_stats_t cs;
    cs.channel = key.first;
    cs.direction = c.direction;
    cs.count = c.count;
    cs.drops = c.drops;
    cs.rate_hz = window_s > 0 ? static_cast<float>(static_cast<double>(c.window_count) / window_s) : 0.0f;
    cs.last_utime = c.last_utime;
    c.window_count = 0;
    s.channels.push_back(cs);
  }
  s.num_channels = static_cast<int32_t>(s.channels.size());
  return s;
}

}  // namespace wingman::common
