// SPDX-License-Identifier: MIT
// The interface every frame source implements (V4L2 camera, video file, image folder).
#pragma once

#include "wingman/camera_driver/frame.hpp"

#include <cstdint>
#include <string>

namespace wingman::camera_driver {

/// What one FrameSource::read() produced.
enum class ReadStatus {
  kFrame,         ///< `out` holds a new frame (lost > 0 when frames were lost just before it)
  kTimeout,       ///< no frame within the timeout; call again
  kEnd,           ///< the source is exhausted (end of a file without loop); stays kEnd
  kDropped,       ///< a frame arrived but was unusable (error flag, empty, undecodable); counted
  kDisconnected,  ///< the device is gone; the source retries with backoff on later calls
};

/// "frame", "timeout", "end", "dropped", "disconnected".
const char* read_status_name(ReadStatus status);

/// Result of FrameSource::read().
struct ReadResult {
  ReadStatus status = ReadStatus::kTimeout;
  /// Frames lost before this result: the sequence gap before a kFrame, 1 for kDropped, 0 otherwise.
  int64_t lost = 0;
  /// One line on a drop, a loss or a disconnection (names the device or file); "" otherwise.
  std::string reason;
  /// True when this result comes right after a successful reconnection.
  bool reconnected = false;
};

/// Counters of one source since it was opened.
struct SourceStats {
  int64_t frames = 0;        ///< frames delivered (kFrame results)
  int64_t dropped = 0;       ///< frames that arrived unusable (kDropped results)
  int64_t lost_in_gaps = 0;  ///< frames missing from the sequence numbers (never arrived)
  int64_t disconnects = 0;   ///< times the device went away
  int64_t reconnects = 0;    ///< successful reopenings after a disconnect
  /// dropped + lost_in_gaps.
  int64_t total_lost() const { return dropped + lost_in_gaps; }
};

/// A source of frames. Not thread-safe; use from one thread.
///
/// Usage: construct, open() (throws std::runtime_error naming the device or file when it cannot
/// start, unless the source waits for its device: waiting_reason()), then read() in a loop. read() never blocks longer
/// than about `timeout_ms`, so the caller can check for a stop request between calls.
class FrameSource {
 public:
  virtual ~FrameSource() = default;

  /// Opens the device or file. Throws std::runtime_error with a message naming it on failure.
  virtual void open() = 0;
  /// Waits up to `timeout_ms` milliseconds (>= 0) for the next frame and fills `out` on kFrame.
  /// Throws std::runtime_error only for errors that retrying cannot fix.
  virtual ReadResult read(Frame& out, int timeout_ms) = 0;
  /// One line on what the source is and how it was negotiated, e.g.
  /// "v4l2 /dev/video0 YUYV 640x480 stride 1280 @ 30 fps".
  virtual std::string describe() const = 0;
  /// Counters since open().
  virtual const SourceStats& stats() const = 0;
  /// Why the source has delivered nothing since open(), when it is waiting for a device that was not there at
  /// start (V4l2SourceOptions::wait_for_device); empty otherwise.
  virtual std::string waiting_reason() const { return ""; }
};

}  // namespace wingman::camera_driver
