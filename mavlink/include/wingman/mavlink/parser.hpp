// SPDX-License-Identifier: MIT
// A streaming MAVLink parser for byte streams (serial) and datagrams (UDP) that survives garbage, bad checksums,
// truncated frames and floods, counting each.
#pragma once

#include "wingman/mavlink/frame.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace wingman::mavlink {

/// What the parser has seen since it was made. Every byte fed ends in exactly one of: a good frame, an unknown
/// message's frame, a refused frame (signed, incompatible, bad length), garbage, or the current partial frame.
struct ParserStats {
  int64_t bytes = 0;               ///< bytes fed
  int64_t frames = 0;              ///< good frames of known messages handed on
  int64_t garbage_bytes = 0;       ///< bytes skipped while looking for a start byte (incl. a bad frame's start byte)
  int64_t bad_crc = 0;             ///< frames of known messages whose checksum did not match (dropped, rescanned)
  int64_t bad_length = 0;          ///< checksum good but payload shorter than a v1 frame must be (dropped)
  int64_t unknown_messages = 0;    ///< v2 frames of message ids the codec does not handle (skipped whole; v1 ones
                                   ///< cannot be told from garbage and count as garbage bytes)
  int64_t signed_refused = 0;      ///< signed v2 frames (signing is not implemented: refused)
  int64_t incompatible_flags = 0;  ///< v2 frames with incompatibility flags this codec does not know (refused)
  int64_t truncated = 0;           ///< partial frames cut off by the end of a datagram or stream

  /// One line: "frames 10, garbage 3 B, bad crc 1, ...".
  std::string summary() const;
};

/// Splits a byte stream into frames. Memory is bounded (one frame); a bad candidate frame costs only its start
/// byte, so a real frame inside garbage or after a cut-off frame is still found.
class Parser {
 public:
  using FrameHandler = std::function<void(const Frame&)>;

  /// Feeds `size` bytes; calls `on_frame` for each good frame of a known message, in order.
  void feed(const uint8_t* data, size_t size, const FrameHandler& on_frame);
  /// End of one datagram (UDP; frames never span datagrams) or of a stream that was closed: a partial frame left is
  /// counted as truncated, and frames found behind its start byte are still handed to `on_frame`.
  void end_of_datagram(const FrameHandler& on_frame);

  const ParserStats& stats() const { return stats_; }

 private:
  /// Works through buffer_ as far as it can; returns when it needs more bytes.
  void process(const FrameHandler& on_frame);
  /// Drops the first `n` bytes of buffer_.
  void consume(size_t n);

  std::vector<uint8_t> buffer_;  ///< bytes from a start byte on, at most kMaxFrameSize
  Frame frame_;                  ///< reused for every frame handed on
  ParserStats stats_;
};

}  // namespace wingman::mavlink
