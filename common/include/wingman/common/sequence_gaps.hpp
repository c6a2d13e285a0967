// SPDX-License-Identifier: MIT
// Frames lost upstream, counted from the gaps in a stream's sequence numbers (image_t.seq, detections_t.seq).
#pragma once

#include <cstdint>

namespace wingman::common {

/// Counts the sequence numbers missing from one stream. A message that never arrives (lost at the source, or on the
/// bus when a receive buffer overflows) leaves no trace but the gap before the next one; this turns such gaps into
/// counts a process can report as drops. Not thread-safe.
class SequenceGapCounter {
 public:
  /// Takes the next message's sequence number and returns how many numbers were skipped since the previous one:
  /// 0 for the first message, a consecutive one, a repeat, or a number at or below the previous one (the source
  /// restarted its count, e.g. a restarted camera driver: counting starts over from it).
  int64_t observe(int64_t seq) {
    int64_t missing = 0;
    if (have_previous_ && seq > previous_ + 1) missing = seq - previous_ - 1;
    have_previous_ = true;
    previous_ = seq;
    total_ += missing;
    return missing;
  }
  /// Every number skipped so far.
  int64_t total() const { return total_; }

 private:
  bool have_previous_ = false;
  int64_t previous_ = 0;
  int64_t total_ = 0;
};

}  // namespace wingman::common
