// SPDX-License-Identifier: MIT
// Helpers of the fuzz targets: splitting one input into several messages, temporary files, and the handler path
// of Runtime's subscriptions (decode_message, then the handler, whose exceptions drop the message).
#pragma once

#include <wingman/common/message_limits.hpp>

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>

namespace wingman::fuzz {

/// Reads an input as records: one selector byte, a 2-byte big-endian length, then that many payload bytes (cut
/// short at the end of the input). The seeds in tests/fuzz/corpus are written in this layout (make_seeds.cpp).
class Records {
 public:
  Records(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  /// False at the end of the input; else the next record's selector and payload.
  bool next(uint8_t* selector, const uint8_t** payload, size_t* payload_size) {
    if (pos_ >= size_) return false;
    *selector = data_[pos_++];
    size_t n = 0;
    for (int i = 0; i < 2 && pos_ < size_; ++i) n = (n << 8) | data_[pos_++];
    if (n > size_ - pos_) n = size_ - pos_;
    *payload = data_ + pos_;
    *payload_size = n;
    pos_ += n;
    return true;
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
};

/// What Runtime::Subscription::on_message does with one payload: decode and check it (common/message_limits.hpp)
/// and call `handler`, whose std::exception drops the message. Returns true when the handler ran to its end.
template <class Msg>
bool deliver(const uint8_t* data, size_t size, const common::MessageLimits& limits,
             const std::function<std::string(const Msg&)>& validate, const std::function<void(const Msg&)>& handler) {
  Msg msg;
  const std::string problem = common::decode_message<Msg>(data, size, limits, msg, validate);
  if (!problem.empty()) return false;
  try {
    handler(msg);
  } catch (const std::exception&) {
    return false;  // the process drops and counts it
  }
  return true;
}

/// The default validator of Runtime::subscribe (validate_message).
template <class Msg>
std::function<std::string(const Msg&)> default_validator() {
  return [](const Msg& m) { return common::validate_message(m); };
}

/// A file in $TMPDIR (or /tmp) unique to this process, named with `suffix`, removed when destroyed; for the
/// parsers that read files only.
class TempFile {
 public:
  explicit TempFile(const std::string& suffix) {
    const char* dir = std::getenv("TMPDIR");
    path_ = std::string(dir && *dir ? dir : "/tmp") + "/wingman_fuzz_" + std::to_string(getpid()) + suffix;
  }
  ~TempFile() { std::remove(path_.c_str()); }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;

  /// Replaces the file's content; returns its path.
  const std::string& write(const uint8_t* data, size_t size) {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    if (!out) throw std::runtime_error("fuzz: cannot write " + path_);
    return path_;
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace wingman::fuzz
