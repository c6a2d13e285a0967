// SPDX-License-Identifier: MIT
// LCM log reader that checks every event header before allocating from it.
#include "wingman/common/lcm_log_reader.hpp"

#include <fmt/format.h>

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace wingman::common {
namespace {

constexpr uint32_t kSyncWord = 0xEDA1DA01;
constexpr int kHeaderBytes = 28;  // sync, event number, utime, channel length, data length
constexpr int32_t kMaxChannelBytes = 1023;

uint32_t be32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | uint32_t{p[3]};
}
uint64_t be64(const uint8_t* p) { return (uint64_t{be32(p)} << 32) | be32(p + 4); }

struct Header {
  int64_t eventnum = 0;
  int64_t timestamp = 0;
  int32_t channel_bytes = 0;
  int32_t data_bytes = 0;
};

/// "" when `h` (kHeaderBytes) is a valid header whose channel and data fit in `left` bytes, else why not.
std::string check_header(const uint8_t* h, int64_t left, int64_t max_event_bytes, Header* out) {
  const uint32_t sync = be32(h);
  if (sync != kSyncWord) return fmt::format("no sync word (0x{:08X} instead of 0x{:08X})", sync, kSyncWord);
  Header r;
  r.eventnum = static_cast<int64_t>(be64(h + 4));
  r.timestamp = static_cast<int64_t>(be64(h + 12));
  r.channel_bytes = static_cast<int32_t>(be32(h + 20));
  r.data_bytes = static_cast<int32_t>(be32(h + 24));
  if (r.channel_bytes < 1 || r.channel_bytes > kMaxChannelBytes)
    return fmt::format("channel length {}: must be 1..{}", r.channel_bytes, kMaxChannelBytes);
  if (r.data_bytes < 0 || r.data_bytes > max_event_bytes)
    return fmt::format("data length {}: must be 0..{}", r.data_bytes, max_event_bytes);
  const int64_t need = int64_t{r.channel_bytes} + int64_t{r.data_bytes};
  if (need > left)
    return fmt::format("channel length {} and data length {} need {} bytes, only {} left in the file", r.channel_bytes,
                       r.data_bytes, need, std::max<int64_t>(0, left));
  *out = r;
  return "";
}

}  // namespace

LcmFileUrl parse_lcm_file_url(const std::string& url) {
  if (url.rfind("file://", 0) != 0) throw std::invalid_argument(fmt::format("'{}': not a file:// URL", url));
  const std::string rest = url.substr(7);
  const size_t q = rest.find('?');
  LcmFileUrl out;
  out.path = rest.substr(0, q);
  if (out.path.empty()) throw std::invalid_argument(fmt::format("'{}': no file path", url));
  if (q == std::string::npos) return out;
  std::string query = rest.substr(q + 1);
  size_t start = 0;
  while (start <= query.size()) {
    const size_t end = std::min(query.find('&', start), query.size());
    const std::string item = query.substr(start, end - start);
    start = end + 1;
    if (item.empty()) continue;
    const size_t eq = item.find('=');
    const std::string key = item.substr(0, eq);
    const std::string value = eq == std::string::npos ? "" : item.substr(eq + 1);
    if (key == "speed") {
      char* parse_end = nullptr;
      const double v = std::strtod(value.c_str(), &parse_end);
      if (value.empty() || *parse_end != '\0' || !(v >= 0) || !std::isfinite(v))
        throw std::invalid_argument(fmt::format("'{}': speed = '{}': must be a finite number >= 0", url, value));
      out.speed = v;
    } else if (key == "mode") {
      if (value != "r")
        throw std::invalid_argument(fmt::format("'{}': mode = '{}': an input log is read (r)", url, value));
    } else {
      throw std::invalid_argument(
          fmt::format("'{}': unknown option '{}' (an input log takes speed and mode)", url, key));
    }
  }
  return out;
}

LcmLogReader::LcmLogReader(const std::string& path, LcmLogReadOptions options)
    : LcmLogReader(std::fopen(path.c_str(), "rb"), path, {}, options) {}

LcmLogReader::LcmLogReader(std::FILE* file, std::string name, std::vector<uint8_t> memory, LcmLogReadOptions options)
    : file_(file), name_(std::move(name)), memory_(std::move(memory)), options_(options) {
  if (!file_) throw LcmLogError(fmt::format("{}: cannot open LCM log for reading", name_), -1);
  if (!(options_.max_event_bytes > 0)) options_.max_event_bytes = LcmLogReadOptions{}.max_event_bytes;
}

LcmLogReader LcmLogReader::from_memory(const void* bytes, size_t size, const std::string& name,
                                       LcmLogReadOptions options) {
  std::vector<uint8_t> copy(static_cast<const uint8_t*>(bytes), static_cast<const uint8_t*>(bytes) + size);
  // fmemopen refuses a size of 0: an empty log is a one-byte buffer read as zero bytes.
  if (copy.empty()) copy.push_back(0);
  std::FILE* f = fmemopen(copy.data(), size == 0 ? 1 : size, "rb");
  if (f && size == 0) std::fseek(f, 0, SEEK_END);  // nothing to read
  LcmLogReader reader(f, name, std::move(copy), options);
  if (size == 0) reader.offset_ = 1;  // past the placeholder byte
  return reader;
}

LcmLogReader::LcmLogReader(LcmLogReader&& other) noexcept
    : file_(other.file_),
      name_(std::move(other.name_)),
      memory_(std::move(other.memory_)),  // the buffer moves with its heap block: fmemopen's pointer stays valid
      options_(other.options_),
      offset_(other.offset_),
      event_(std::move(other.event_)),
      event_ready_(other.event_ready_),
      data_(std::move(other.data_)),
      corrupt_events_(other.corrupt_events_),
      skipped_bytes_(other.skipped_bytes_),
      first_corruption_(std::move(other.first_corruption_)) {
  other.file_ = nullptr;
}

LcmLogReader::~LcmLogReader() {
  if (file_) std::fclose(file_);
}

int64_t LcmLogReader::file_size() {
  if (!memory_.empty()) return static_cast<int64_t>(memory_.size());
  struct stat st {};
  if (fstat(fileno(file_), &st) != 0) return 0;
  return static_cast<int64_t>(st.st_size);  // read again each time: a log still being written grows
}

std::string LcmLogReader::read_at(int64_t offset) {
  event_ready_ = false;
  const int64_t size = file_size();
  if (offset >= size) return "";  // the end
  if (fseeko(file_, static_cast<off_t>(offset), SEEK_SET) != 0)
    throw LcmLogError(fmt::format("{}: cannot seek to byte {}: {}", name_, offset, std::strerror(errno)), offset);
  uint8_t h[kHeaderBytes];
  const size_t got = std::fread(h, 1, kHeaderBytes, file_);
  if (got < static_cast<size_t>(kHeaderBytes))
    return fmt::format("header cut short by the end of the file ({} of {} bytes)", got, kHeaderBytes);
  Header header;
  if (std::string bad = check_header(h, size - offset - kHeaderBytes, options_.max_event_bytes, &header); !bad.empty())
    return bad;
  // Only now, with lengths that fit in the file, are the channel and data read.
  event_.channel.assign(static_cast<size_t>(header.channel_bytes), '\0');
  data_.resize(static_cast<size_t>(header.data_bytes));
  if (std::fread(event_.channel.data(), 1, event_.channel.size(), file_) != event_.channel.size() ||
      std::fread(data_.data(), 1, data_.size(), file_) != data_.size())
    return "channel or data cut short by the end of the file";
  if (event_.channel.find('\0') != std::string::npos) return "channel name contains a NUL byte";
  event_.eventnum = header.eventnum;
  event_.timestamp = header.timestamp;
  event_.datalen = header.data_bytes;
  event_.data = data_.data();
  event_.offset = offset;
  offset_ = offset + kHeaderBytes + header.channel_bytes + header.data_bytes;
  event_ready_ = true;
  return "";
}

bool LcmLogReader::header_valid_at(int64_t offset) {
  const int64_t size = file_size();
  if (offset + kHeaderBytes > size || fseeko(file_, static_cast<off_t>(offset), SEEK_SET) != 0) return false;
  uint8_t h[kHeaderBytes];
  if (std::fread(h, 1, kHeaderBytes, file_) != static_cast<size_t>(kHeaderBytes)) return false;
  Header header;
  return check_header(h, size - offset - kHeaderBytes, options_.max_event_bytes, &header).empty();
}

const LcmLogEvent* LcmLogReader::read_next() {
  const std::string why = read_at(offset_);
  if (why.empty()) return event_ready_ ? &event_ : nullptr;
  const std::string line = fmt::format("{}: corrupt event at byte {}: {}", name_, offset_, why);
  if (!options_.skip_corrupt) throw LcmLogError(line, offset_);
  if (first_corruption_.empty()) first_corruption_ = line;
  ++corrupt_events_;
  // Resynchronise: the next sync word after the bad one that starts a valid header.
  const int64_t size = file_size();
  const int64_t bad = offset_;
  std::vector<uint8_t> block(64 * 1024);
  int64_t pos = bad + 1;
  while (pos + kHeaderBytes <= size) {
    if (fseeko(file_, static_cast<off_t>(pos), SEEK_SET) != 0) break;
    const size_t got = std::fread(block.data(), 1, block.size(), file_);
    if (got < 4) break;
    for (size_t i = 0; i + 4 <= got; ++i) {
      if (be32(&block[i]) != kSyncWord) continue;
      const int64_t candidate = pos + static_cast<int64_t>(i);
      if (!header_valid_at(candidate)) continue;
      if (read_at(candidate).empty() && event_ready_) {  // (read_at moved offset_ past the event)
        skipped_bytes_ += candidate - bad;
        return &event_;
      }
    }
    pos += static_cast<int64_t>(got) - 3;  // a sync word may straddle two blocks
  }
  skipped_bytes_ += size - bad;
  offset_ = size;
  return nullptr;
}

}  // namespace wingman::common
