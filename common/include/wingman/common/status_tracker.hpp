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
///
/// Health: the heartbeat's state is the one the process set (set_state), except that a process that
/// says OK but has a stale input is reported DEGRADED. A declared input channel (declare_input: every
/// subscription; channels only seen, e.g. by a recorder that takes every channel, are not watched) is stale
/// when no message was handled on it (dropped ones do not count) for more than stale_after_s of wall
/// time: each heartbeat marks the channels that had a message since the previous heartbeat as fresh
/// at its wall_utime, so staleness is known to within one heartbeat period (1 s by default). A
/// channel that never had a message is stale once stale_after_s has passed since the first
/// heartbeat. Every stale channel is named in the detail ("stale input: no message on IMAGE_CAM0 for
/// 3.0 s"), appended to the process's own detail in every state but STOPPING. Wall time is used
/// because this is a liveness signal for monitoring; nothing in the data path depends on it.
class StatusTracker {
 public:
  /// Default of stale_after_s(), seconds of wall time.
  static constexpr double kDefaultStaleAfterS = 3.0;
  /// Most channels listed one by one; messages on further channels that were not declared (a recorder that takes
  /// every channel, under a flood of names) are counted together under kOtherChannels, so the heartbeat stays
  /// bounded. input_count() and friends of such a channel are those of the shared entry's name only.
  static constexpr size_t kMaxChannels = 256;
  static constexpr const char* kOtherChannels = "(other channels)";

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
  void item_dropped(const std::string& channel, const std::string& reason) { items_dropped(channel, 1, reason); }
  /// `count` (>= 0) such drops at once, in O(1) (e.g. frames missing from a sequence gap); the counters saturate
  /// at INT64_MAX instead of overflowing.
  void items_dropped(const std::string& channel, int64_t count, const std::string& reason);
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
  /// Seconds of wall time without a handled message after which an input counts as stale (> 0).
  void set_stale_after_s(double seconds) { stale_after_s_ = seconds > 0.0 ? seconds : kDefaultStaleAfterS; }
  double stale_after_s() const { return stale_after_s_; }

  int8_t state() const { return state_; }
  int64_t messages_handled() const { return messages_handled_; }
  int64_t drops_total() const { return drops_total_; }
  int64_t input_count(const std::string& channel) const;
  int64_t input_drops(const std::string& channel) const;
  int64_t output_count(const std::string& channel) const;
  const std::string& last_error() const { return last_error_; }

  /// Builds a heartbeat. `wall_utime`: now (monitoring only; also the clock of the input staleness);
  /// `window_s`: seconds since the previous heartbeat, over which rates are computed (rate counters
  /// restart after each call).
  wingman::status_t heartbeat(int64_t wall_utime, int64_t uptime_us, double window_s);

 private:
  struct Channel {
    int8_t direction = 0;
    int64_t count = 0;
    int64_t drops = 0;
    int64_t window_count = 0;
    int64_t window_handled = 0;  ///< inputs: messages handled (not dropped) since the previous heartbeat
    int64_t last_utime = 0;
    int64_t fresh_wall_utime = -1;  ///< inputs: wall time of the heartbeat that last saw a handled message, -1 never
    bool declared = false;          ///< inputs: declared with declare_input (watched for staleness)
  };
  /// The entry of `name`; past kMaxChannels entries, an undeclared new name shares the kOtherChannels entry.
  Channel& channel(const std::string& name, int8_t direction, bool declaring = false);

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
  double stale_after_s_ = kDefaultStaleAfterS;
  int64_t first_heartbeat_wall_utime_ = -1;
};

}  // namespace wingman::common
