// SPDX-License-Identifier: MIT
// Frames lost upstream, counted from the gaps in a stream's sequence numbers (image_t.seq, detections_t.seq).
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>

namespace wingman::common {

/// Counts the sequence numbers missing from one stream. A message that never arrives (lost at the source, or on the
/// bus when a receive buffer overflows) leaves no trace but the gap before the next one; this turns such gaps into
/// counts a process can report as drops. Not thread-safe.
class SequenceGapCounter {
 public:
  /// Takes the next message's sequence number and returns how many numbers were skipped since the previous one:
  /// 0 for the first message, a consecutive one, a repeat, or a number at or below the previous one (the source
  /// restarted its count, e.g. a restarted camera driver: counting starts over from it). O(1) whatever the jump:
  /// a gap wider than INT64_MAX (a hostile seq, from INT64_MIN to INT64_MAX) counts as INT64_MAX, and total()
  /// saturates at INT64_MAX too, so a caller can count the gap in one step (never once per missing number).
  int64_t observe(int64_t seq) {
    int64_t missing = 0;
    if (have_previous_ && seq > previous_) {
      // seq - previous_ in unsigned arithmetic: exact for every seq > previous_ (at most 2^64 - 1).
      const uint64_t step = static_cast<uint64_t>(seq) - static_cast<uint64_t>(previous_);
      missing = static_cast<int64_t>(std::min<uint64_t>(step - 1, kMax));
    }
    have_previous_ = true;
    previous_ = seq;
    total_ = missing > kMax - total_ ? kMax : total_ + missing;
    return missing;
  }
  /// Every number skipped so far (saturates at INT64_MAX).
  int64_t total() const { return total_; }

 private:
  static constexpr int64_t kMax = std::numeric_limits<int64_t>::max();
  bool have_previous_ = false;
  int64_t previous_ = 0;
  int64_t total_ = 0;
};

}  // namespace wingman::common
