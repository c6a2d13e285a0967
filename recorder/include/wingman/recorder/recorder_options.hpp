// SPDX-License-Identifier: MIT
// Options of wingman-recorder (config/recorder.yaml).
#pragma once

#include <string>
#include <vector>

namespace wingman::recorder {

/// What wingman-recorder records, where, and how it bounds memory and retries after errors.
struct RecorderOptions {
  /// Directory the log segments are written to. It is not created: a missing or unwritable directory is an error
  /// (see require_directory_at_start).
  std::string directory = "recordings";
  /// Segment file names: `<prefix>-<UTC date>-<UTC time>-<segment number>.lcmlog`.
  std::string file_prefix = "wingman";
  /// Channel patterns (ChannelPattern: bounded POSIX extended regular expressions, whole channel name); a channel is
  /// recorded when it matches one of `include` and none of `exclude`.
  std::vector<std::string> include = {".*"};
  std::vector<std::string> exclude = {"IMAGE.*"};  ///< images are large: left out unless asked for
  /// A segment is closed and the next one opened before it would grow past this size, MiB.
  double max_segment_mib = 256.0;
  /// Most bytes of events waiting for the disk, MiB; an event that does not fit is dropped and counted.
  double max_queue_mib = 32.0;
  /// After a failed open or write: events are dropped (and counted) until the next attempt, this many seconds
  /// later, opens a new segment.
  double retry_period_s = 2.0;
  /// At start-up, the first segment cannot be created (missing or unwritable directory, full disk): true = exit 1
  /// with one line naming the path and the reason; false = keep running with state ERROR and retry.
  bool require_directory_at_start = false;

  template <class V>
  void visit(V& v) {
    v("output.directory", directory, "directory of the log segments (not created; must exist and be writable)");
    v("output.file_prefix", file_prefix, "segment names: <prefix>-<UTC date>-<UTC time>-<number>.lcmlog");
    v("output.max_segment_mib", max_segment_mib, "start a new segment before one grows past this size, MiB");
    v("channels.include", include, "record channels matching one of these regular expressions (whole name)");
    v("channels.exclude", exclude, "... and none of these (images are large: excluded by default)");
    v("buffer.max_queue_mib", max_queue_mib, "most event bytes waiting for the disk, MiB; beyond: dropped, counted");
    v("errors.retry_period_s", retry_period_s,
      "after a failed open or write, drop and count events, then open a new segment this many seconds later");
    v("errors.require_directory_at_start", require_directory_at_start,
      "first segment cannot be created at start-up: true = exit 1, false = run with state ERROR and retry");
  }
  /// One "key = value: rule" line per problem; empty when valid (regular expressions are compiled here).
  std::vector<std::string> validate() const;
};

}  // namespace wingman::recorder
