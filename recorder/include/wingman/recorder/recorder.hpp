// SPDX-License-Identifier: MIT
// Recording LCM events into size-rotated LCM log files on a writer thread that never blocks the caller.
#pragma once

#include "wingman/recorder/channel_pattern.hpp"
#include "wingman/recorder/recorder_options.hpp"

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

namespace wingman::recorder {

/// Which channels are recorded: include/exclude patterns (ChannelPattern), answers cached per channel (at most
/// kMaxCached names: the cache starts over beyond, so a flood of new names costs time, never unbounded memory).
class ChannelFilter {
 public:
  static constexpr size_t kMaxCached = 4096;
  /// Throws std::invalid_argument naming the pattern for a bad one (RecorderOptions::validate() reports it first).
  ChannelFilter(const std::vector<std::string>& include, const std::vector<std::string>& exclude);
  bool wants(const std::string& channel);

 private:
  std::vector<ChannelPattern> include_, exclude_;
  std::unordered_map<std::string, bool> cache_;
};

/// A snapshot of what the recorder did since it started.
struct RecorderStats {
  int64_t events_queued = 0;        ///< accepted by record()
  int64_t events_written = 0;       ///< written completely to a segment
  int64_t bytes_written = 0;        ///< bytes of those events, as stored (headers included)
  int64_t dropped_queue_full = 0;   ///< refused by record(): the queue held max_queue_mib already
  int64_t dropped_write_error = 0;  ///< lost to a failed open or write (and while waiting to retry)
  int64_t segments_opened = 0;      ///< segment files created
  int64_t write_errors = 0;         ///< failed opens or writes (each starts a retry wait)
  int64_t queued_bytes = 0;         ///< bytes waiting for the disk now
  bool failing = false;             ///< the newest open or write failed and no segment is open
  std::string segment;              ///< path of the segment being written, "" if none
  std::string last_error;           ///< newest error: the path and the reason, "" if none
};

/// Writes events to LCM log segments (the lcm_eventlog format that lcm-logplayer and lcm::LogFile read) in
/// `options.directory`, on its own thread.
///
/// record() only copies the event into a queue bounded by max_queue_mib (a full queue drops and counts the event),
/// so a slow or failing disk never stalls the caller. Segments rotate by size. A failed open or write (ENOSPC, EIO,
/// a vanished directory) closes the segment, truncated to its last complete event so it stays readable, and drops
/// and counts events until a new segment is tried retry_period_s later. Timestamps are the caller's (LCM's receive
/// time of each event); message contents are written as received.
class Recorder {
 public:
  /// Starts the writer and creates the first segment. With require_directory_at_start, throws std::runtime_error
  /// (path and errno text) if it cannot; otherwise the error is in stats() and the writer retries.
  explicit Recorder(const RecorderOptions& options);
  /// Stops the writer after it has written what is queued, waiting at most `close_timeout_s` (see close()).
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  /// Queues one event (not filtered here: see ChannelFilter). `timestamp_us`: the log event time, microseconds.
  /// Returns false when it was dropped because the queue is full. Never blocks on the disk.
  bool record(const std::string& channel, int64_t timestamp_us, const void* data, size_t size);

  RecorderStats stats() const;
  /// Events dropped per channel since the previous call (queue full and write errors together).
  std::map<std::string, int64_t> take_drops();
  /// Waits up to `timeout_s` until every queued event has been written or dropped; true if the queue is empty.
  bool wait_idle(double timeout_s);
  /// Writes what is queued (at most `timeout_s` seconds; what is left is dropped and counted), closes the segment
  /// and stops the writer. Idempotent.
  void close(double timeout_s = 0.5);

 private:
  struct Event {
    std::string channel;
    int64_t timestamp_us;
    std::vector<uint8_t> data;
  };
  void writer_loop();
  /// Writer thread only. Opens the next segment; false (and the error recorded) if it cannot.
  bool open_segment();
  /// Writer thread only. Writes one event into the open segment (rotating first if needed); false on error.
  bool write_event(const Event& ev);
  void close_segment();
  void fail(const std::string& error);
  void drop_locked(const std::string& channel, int64_t count, bool write_error);

  RecorderOptions options_;
  int64_t max_segment_bytes_;
  int64_t max_queue_bytes_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;
  std::deque<Event> queue_;
  bool stopping_ = false;
  bool writing_ = false;  ///< the writer holds an event taken from the queue
  double stop_deadline_s_ = 0;
  std::map<std::string, int64_t> drops_;
  RecorderStats stats_;

  // Writer thread state.
  int fd_ = -1;
  int64_t segment_bytes_ = 0;
  int64_t segment_events_ = 0;
  int64_t segment_number_ = 0;
  double retry_at_s_ = 0;  ///< steady clock, seconds: no new segment is tried before
  std::string segment_path_;
  std::vector<uint8_t> record_buffer_;
  std::thread writer_;
};

}  // namespace wingman::recorder
