// SPDX-License-Identifier: MIT
// A thread that reads the autopilot's link as soon as bytes arrive and stamps them with their arrival time, so
// TIMESYNC round trips are measured at the link, not when the main loop gets to them.
#pragma once

#include "wingman/mavlink_bridge/link.hpp"

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace wingman::mavlink_bridge {

/// Bytes as read from the link, with the clocks at the read.
struct LinkChunk {
  std::vector<uint8_t> bytes;  ///< one datagram (UDP) or what a read returned (serial); empty for an event
  int64_t mono_us = 0;         ///< monotonic clock at the read, microseconds
  int64_t wall_ns = 0;         ///< epoch clock at the read, nanoseconds
  bool datagram = false;       ///< the bytes are one whole datagram
  std::string event;           ///< "" for bytes; else what happened ("link open: ...", "link lost: ...", an open error)
  bool lost = false;           ///< the event is a lost link (a partial frame before it is cut off)
};

/// Owns the link: opens it (again every `reopen_period_s` while it is closed), reads it on its own thread into a
/// bounded queue and calls `notify` after each read (the process wakes its main loop). The main thread writes frames
/// and takes the chunks. Beyond `max_queued` chunks waiting, new reads are dropped and counted (a flood cannot grow
/// memory).
class LinkReader {
 public:
  LinkReader(std::unique_ptr<Link> link, double reopen_period_s, size_t max_queued, std::function<void()> notify);
  ~LinkReader();  ///< stops the thread and closes the link
  LinkReader(const LinkReader&) = delete;
  LinkReader& operator=(const LinkReader&) = delete;

  /// Writes one frame (false: not open, no peer yet, or the write failed).
  bool write(const std::vector<uint8_t>& frame);
  /// Moves every waiting chunk to `out` (appended), oldest first.
  void take(std::vector<LinkChunk>& out);
  bool is_open() const;
  std::string describe() const { return description_; }
  /// Chunks dropped because the queue was full.
  int64_t dropped_chunks() const { return dropped_.load(); }

 private:
  void run();
  void push(LinkChunk chunk);

  std::unique_ptr<Link> link_;
  std::string description_;
  int64_t reopen_us_;
  size_t max_queued_;
  std::function<void()> notify_;
  mutable std::mutex link_mutex_;  ///< guards link_
  std::mutex queue_mutex_;
  std::deque<LinkChunk> queue_;
  std::atomic<int64_t> dropped_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace wingman::mavlink_bridge
