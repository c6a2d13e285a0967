// SPDX-License-Identifier: MIT
// What a launcher sees of its processes on the LCM bus: their status heartbeats and how many messages channels carried.
#pragma once

#include <lcm/lcm-cpp.hpp>
#include <wingman/status_t.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace wingman::launcher {

/// Listens to a bus: every STATUS_* heartbeat (the newest per process instance, status_t.process) and the message
/// count of the channels matching `count_channels`. A heartbeat that does not decode or fails common::validate_message
/// is counted in bad_messages() and otherwise ignored. Wall-clock waits only (starting processes); nothing read here
/// is a message time. Not thread-safe. The one way a program waits for processes' heartbeats: the launchers (`wingman
/// fly`, `demo-camera`, `load`), `wingman replay --wait-for` and wingman-sim's sync.wait_for.
class BusWatch {
 public:
  /// Opens `lcm_url` (a udpm URL in a private network namespace). `count_channels`: a regular expression of channels to
  /// count ("" = none). Throws std::runtime_error naming the URL when LCM cannot open it.
  explicit BusWatch(const std::string& lcm_url, const std::string& count_channels = "");
  /// Listens on the caller's `lcm` instead, which must outlive the watch: its other subscriptions are handled by the
  /// same spins (and the watch's by the caller's handle calls). The watch unsubscribes when destroyed.
  explicit BusWatch(lcm::LCM& lcm, const std::string& count_channels = "");
  ~BusWatch();
  BusWatch(const BusWatch&) = delete;
  BusWatch& operator=(const BusWatch&) = delete;

  /// Handles what arrives within `timeout_ms` milliseconds (>= 0), then returns.
  void spin(int timeout_ms);
  /// Spins until `done()` is true (returns true), `stop()` is true or `timeout_s` seconds have passed (false).
  bool spin_until(const std::function<bool()>& done, double timeout_s, const std::function<bool()>& stop = nullptr);
  /// Spins until every instance in `names` has sent a heartbeat, `stop()` or `timeout_s`; returns those still missing.
  std::vector<std::string> wait_for_status(const std::vector<std::string>& names, double timeout_s,
                                           const std::function<bool()>& stop = nullptr);

  /// The newest heartbeat of process instance `name`, nullptr when none arrived.
  const status_t* status(const std::string& name) const;
  /// Messages seen on `channel` (one that matches count_channels) so far.
  int64_t count(const std::string& channel) const;
  /// STATUS_* messages that did not decode.
  int64_t bad_messages() const { return bad_messages_; }

 private:
  void on_status(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void on_counted(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  void subscribe(const std::string& count_channels);

  std::unique_ptr<lcm::LCM> owned_lcm_;  ///< the URL constructor's; null when listening on the caller's
  lcm::LCM* lcm_ = nullptr;
  std::vector<lcm::Subscription*> subscriptions_;
  std::map<std::string, status_t> statuses_;
  std::map<std::string, int64_t> counts_;
  int64_t bad_messages_ = 0;
};

/// A channel's count in a heartbeat's channel list (`direction`: channel_stats_t::DIRECTION_IN or _OUT), 0 when absent.
int64_t channel_count(const status_t& status, const std::string& channel, int8_t direction);

}  // namespace wingman::launcher
