// SPDX-License-Identifier: MIT
// Counters, rates and latency percentiles of one process, turned into status_t heartbeats.
#pragma once

#include <wingman/status_t.hpp>

#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <vector>

namespace wingman::common {

/// Collects what a process did (messages in and out per channel, drops, latencies, errors) and
/// builds its status_t heartbeat. Not thread-safe: use it from the process's main loop only.
class StatusTracker {
 public:
  /// `process`: instance name shown in status_t.process. `latency_window`: how many recent
  /// latency samples the percentiles cover.
  StatusTracker(std::string process, int32_t pid, size_t latency_window = 256);

  /// Declares a channel so it is listed (with zero counts) before its first message.
  void declare_input(const std::string& channel);
  void declare_output(const std::string& channel);

  /// An input message was handled. `utime`: its utime field (message time, microseconds).
  void input(const std::string& channel, int64_t utime);
  /// An input message was dropped (could not be decoded or validated); `reason` names the channel and field.
  void input_dropped(const std::string& channel, const std::string& reason);
  /// Part of a handled input could not be used (e.g. one box of a detections message); counts a drop
  /// on `channel` without counting another message. `reason` names the field.
  void item_dropped(const std::string& channel, const std::string& reason);
  /// A message was published. `utime`: its utime field.
  void output(const std::string& channel, int64_t utime);
  /// The source lost `count` frames before they reached `channel` (e.g. a V4L2 sequence gap).
  void source_dropped(const std::string& channel, int64_t count, const std::string& reason);

  /// One processing-latency sample, milliseconds.
  void record_latency_ms(double latency_ms);
  void set_last_processed_seq(int64_t seq) { last_processed_seq_ = seq; }
  /// Sets the state (status_t::STATE_*) and its one-line detail.
  void set_state(int8_t state, const std::string& detail);
  /// Remembers an error as last_error (does not change the state).
  void set_error(const std::string& error) { last_error_ = error; }

  int8_t state() const { return state_; }
  int64_t messages_handled() const { return messages_handled_; }
  int64_t drops_total() const { return drops_total_; }
  int64_t input_count(const std::string& channel) const;
  int64_t input_drops(const std::string& channel) const;
  int64_t output_count(const std::string& channel) const;
  const std::string& last_error() const { return last_error_; }

  /// Builds a heartbeat. `wall_utime`: now (monitoring only); `window_s`: seconds since the previous
  /// heartbeat, over which rates are computed (rate counters restart after each call).
  wingman::status_t heartbeat(int64_t wall_utime, int64_t uptime_us, double window_s);

 private:
  struct Channel {
    int8_t direction = 0;
    int64_t count = 0;
    int64_t drops = 0;
    int64_t window_count = 0;
    int64_t last_utime = 0;
  };
  Channel& channel(const std::string& name, int8_t direction);

  std::string process_;
  int32_t pid_;
  size_t latency_window_;
  std::map<std::pair<std::string, int8_t>, Channel> channels_;
  std::vector<std::pair<std::string, int8_t>> channel_order_;
  std::deque<float> latencies_ms_;
  int8_t state_;
  std::string detail_;
  std::string last_error_;
  int64_t last_input_utime_ = 0;
  int64_t last_processed_seq_ = -1;
  int64_t messages_handled_ = 0;
  int64_t drops_total_ = 0;
};

}  // namespace wingman::common
