// SPDX-License-Identifier: MIT
// LCM log files read with every event header checked before anything is allocated from it.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace wingman::common {

/// A corrupt or unreadable LCM log. what() is one line naming the file, the byte offset of the bad event and why,
/// e.g. "in.lcmlog: corrupt event at byte 4711: data length 2147483647 exceeds the 12 bytes left in the file".
class LcmLogError : public std::runtime_error {
 public:
  LcmLogError(const std::string& what, int64_t offset) : std::runtime_error(what), offset_(offset) {}
  /// Byte offset of the event that is corrupt (-1: the file could not be opened or read).
  int64_t offset() const { return offset_; }

 private:
  int64_t offset_;
};

/// A file:// LCM URL taken apart: file://PATH?speed=S (LCM's file provider syntax, read side).
struct LcmFileUrl {
  std::string path;
  double speed = 1.0;  ///< playback speed: 1 = the log's pace, 0 = as fast as possible
};
/// Parses `url` ("file://PATH[?speed=S][&mode=r]"). Throws std::invalid_argument naming the URL and the bad part
/// (not a file:// URL, an empty path, a speed that is not a finite number >= 0, a mode other than r, another key).
LcmFileUrl parse_lcm_file_url(const std::string& url);

/// How an LcmLogReader treats a corrupt event.
struct LcmLogReadOptions {
  /// false (default): a corrupt event throws LcmLogError. true: it is skipped up to the next event whose header
  /// is valid (found by its sync word) and counted (LcmLogReader::corrupt_events(), skipped_bytes()).
  bool skip_corrupt = false;
  /// Largest data length of one event, bytes (> 0); a longer one is corrupt. Default 1 GiB: far above any
  /// Wingman message (a 4K BGR image is 25 MB) while a length field can never make the reader allocate more.
  int64_t max_event_bytes = int64_t{1} << 30;
};

/// One event of an LCM log. `data` points into the reader's buffer: valid until the next read_next().
struct LcmLogEvent {
  int64_t eventnum = 0;
  int64_t timestamp = 0;  ///< the log's event time, microseconds (lcm-logger: receive time)
  std::string channel;
  int32_t datalen = 0;
  const void* data = nullptr;
  int64_t offset = 0;  ///< byte offset of the event's sync word in the file
};

/// Reads an LCM log (the format of lcm-logger and LCM's file:// provider): events of
///
///     uint32 sync word 0xEDA1DA01, int64 event number, int64 utime, int32 channel length, int32 data length,
///     channel bytes, data bytes                                              (all integers big-endian)
///
/// Every header is checked before anything is allocated from it: the sync word, a channel length of 1..1023 bytes
/// without NUL, a data length of 0..max_event_bytes, and that the channel and data fit in the bytes left in the
/// file. (LCM 1.3.1's own reader allocates datalen + 1 bytes first, and overflows at 2^31 - 1.) An event cut short
/// by the end of the file is corrupt too. Not thread-safe.
class LcmLogReader {
 public:
  /// Opens `path`. Throws LcmLogError (offset -1): "<path>: cannot open LCM log for reading".
  explicit LcmLogReader(const std::string& path, LcmLogReadOptions options = {});
  /// Reads from `size` bytes in memory (`name` stands for the file name in messages): tests and fuzzing.
  static LcmLogReader from_memory(const void* bytes, size_t size, const std::string& name,
                                  LcmLogReadOptions options = {});
  ~LcmLogReader();
  LcmLogReader(LcmLogReader&& other) noexcept;
  LcmLogReader& operator=(LcmLogReader&&) = delete;
  LcmLogReader(const LcmLogReader&) = delete;
  LcmLogReader& operator=(const LcmLogReader&) = delete;

  /// The next event, or nullptr at the end of the file. A corrupt event throws LcmLogError naming its offset
  /// (options.skip_corrupt false), or is skipped and counted. The pointer is valid until the next call.
  const LcmLogEvent* read_next();

  /// Corrupt stretches skipped so far (skip_corrupt), and their bytes.
  int64_t corrupt_events() const { return corrupt_events_; }
  int64_t skipped_bytes() const { return skipped_bytes_; }
  /// The first corrupt event's error line ("" when none was met).
  const std::string& first_corruption() const { return first_corruption_; }
  const std::string& name() const { return name_; }
  /// The underlying file, for progress reports (its position is after the last event read). Do not read from it.
  std::FILE* file_ptr() const { return file_; }

 private:
  LcmLogReader(std::FILE* file, std::string name, std::vector<uint8_t> memory, LcmLogReadOptions options);
  /// Reads the event at the current offset into event_: "" when done (event_ready_ set, or the end), else why it
  /// is corrupt. Allocates only after the header has been checked.
  std::string read_at(int64_t offset);
  /// Whether a valid header starts at `offset` (for resynchronising after a corrupt event).
  bool header_valid_at(int64_t offset);
  int64_t file_size();

  std::FILE* file_ = nullptr;
  std::string name_;
  std::vector<uint8_t> memory_;  ///< from_memory(): the bytes the FILE reads (fmemopen)
  LcmLogReadOptions options_;
  int64_t offset_ = 0;  ///< where the next event starts
  LcmLogEvent event_;
  bool event_ready_ = false;
  std::vector<uint8_t> data_;
  int64_t corrupt_events_ = 0;
  int64_t skipped_bytes_ = 0;
  std::string first_corruption_;
};

}  // namespace wingman::common
