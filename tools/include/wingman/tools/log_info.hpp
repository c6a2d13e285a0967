// SPDX-License-Identifier: MIT
// `wingman loginfo`: what an LCM log holds, per channel, and each process's last status.
#pragma once

#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace wingman::tools {

/// Per-channel summary of a log.
struct ChannelSummary {
  std::string channel;
  std::string type;         ///< wingman message type found by fingerprint, or "?" if unknown
  int64_t count = 0;        ///< events
  int64_t undecodable = 0;  ///< events of a known type that failed to decode or validate
  int64_t bytes = 0;        ///< payload bytes
  int64_t first_utime = 0;  ///< utime field of the first decoded message (0 if none)
  int64_t last_utime = 0;   ///< utime field of the last decoded message
};

/// What `loginfo` found.
struct LogSummary {
  std::vector<ChannelSummary> channels;         ///< in order of first appearance
  std::map<std::string, std::string> statuses;  ///< process -> one line from its last status_t
  /// 1 when the last valid image_t could be turned into a picture (the snapshot), else 0: only the last image is
  /// decoded (a log holds thousands).
  int64_t images_with_pixels = 0;
  int64_t corrupt_events = 0;  ///< corrupt stretches skipped (skip_corrupt), and their bytes
  int64_t corrupt_bytes = 0;
  std::string first_corruption;  ///< the first one's line (offset and reason)
  std::string report() const;    ///< a table for people
};

/// Reads `log_path` (throws std::runtime_error naming it when unreadable). When `snapshot_png` is
/// not empty, the last image_t is saved there as PNG (MJPEG and YUYV are decoded). A corrupt event throws
/// common::LcmLogError naming its byte offset, or with `skip_corrupt` is skipped and counted in the summary.
/// Progress through the log (common::Progress, every 5 s) goes to `progress` (nullptr: quiet).
LogSummary summarize_log(const std::string& log_path, const std::string& snapshot_png = "", bool skip_corrupt = false,
                         std::ostream* progress = nullptr);

}  // namespace wingman::tools
