// SPDX-License-Identifier: MIT
// Recorder: a bounded queue in front of a writer thread that writes size-rotated LCM log segments.
#include "wingman/recorder/recorder.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <ctime>
#include <stdexcept>

namespace wingman::recorder {
namespace {

constexpr uint32_t kEventMagic = 0xEDA1DA01;  // lcm_eventlog: every event starts with it
constexpr size_t kEventHeaderBytes = 4 + 8 + 8 + 4 + 4;
constexpr double kMiB = 1024.0 * 1024.0;

double now_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

void put_be(std::vector<uint8_t>& out, uint64_t v, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}

ChannelPattern compile(const std::string& pattern) {
  std::string why;
  auto p = ChannelPattern::compile(pattern, &why);
  if (!p) throw std::invalid_argument(fmt::format("channel pattern '{}': {}", pattern, why));
  return std::move(*p);
}

/// Bytes an event holds in the queue (what max_queue_mib bounds).
int64_t queued_size(const std::string& channel, size_t size) {
  return static_cast<int64_t>(channel.size() + size + kEventHeaderBytes);
}

}  // namespace

ChannelFilter::ChannelFilter(const std::vector<std::string>& include, const std::vector<std::string>& exclude) {
  for (const auto& p : include) include_.push_back(compile(p));
  for (const auto& p : exclude) exclude_.push_back(compile(p));
}

bool ChannelFilter::wants(const std::string& channel) {
  const auto it = cache_.find(channel);
  if (it != cache_.end()) return it->second;
  bool wanted = false;
  for (const auto& p : include_) wanted = wanted || p.matches(channel);
  for (const auto& p : exclude_) wanted = wanted && !p.matches(channel);
  if (cache_.size() >= kMaxCached) cache_.clear();
  cache_.emplace(channel, wanted);
  return wanted;
}

Recorder::Recorder(const RecorderOptions& options)
    : options_(options),
      max_segment_bytes_(static_cast<int64_t>(options.max_segment_mib * kMiB)),
      max_queue_bytes_(static_cast<int64_t>(options.max_queue_mib * kMiB)) {
  if (!open_segment()) {
    if (options_.require_directory_at_start) throw std::runtime_error(stats_.last_error);
    retry_at_s_ = now_s() + options_.retry_period_s;
  }
  writer_ = std::thread([this] { writer_loop(); });
}

Recorder::~Recorder() { close(); }

bool Recorder::record(const std::string& channel, int64_t timestamp_us, const void* data, size_t size) {
  const int64_t bytes = queued_size(channel, size);
  std::lock_guard<std::mutex> lock(mutex_);
  if (stopping_ || stats_.queued_bytes + bytes > max_queue_bytes_) {
    drop_locked(channel, 1, /*write_error=*/false);
    return false;
  }
  const auto* p = static_cast<const uint8_t*>(data);
  queue_.push_back(Event{channel, timestamp_us, std::vector<uint8_t>(p, p + size)});
  stats_.queued_bytes += bytes;
  ++stats_.events_queued;
  wake_.notify_one();
  return true;
}

RecorderStats Recorder::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

std::map<std::string, int64_t> Recorder::take_drops() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::map<std::string, int64_t> out;
  out.swap(drops_);
  return out;
}

bool Recorder::wait_idle(double timeout_s) {
  std::unique_lock<std::mutex> lock(mutex_);
  return idle_.wait_for(lock, std::chrono::duration<double>(timeout_s), [this] { return queue_.empty() && !writing_; });
}

void Recorder::close(double timeout_s) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!writer_.joinable()) return;
    if (!stopping_) {
      stopping_ = true;
      stop_deadline_s_ = now_s() + timeout_s;
    }
  }
  wake_.notify_all();
  writer_.join();
}

void Recorder::drop_locked(const std::string& channel, int64_t count, bool write_error) {
  drops_[channel] += count;
  if (write_error)
    stats_.dropped_write_error += count;
  else
    stats_.dropped_queue_full += count;
}

void Recorder::fail(const std::string& error) {
  std::lock_guard<std::mutex> lock(mutex_);
  stats_.failing = true;
  stats_.segment.clear();
  stats_.last_error = error;
  ++stats_.write_errors;
}

bool Recorder::open_segment() {
  for (int attempt = 0; attempt < 100; ++attempt) {
    const std::time_t t = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&t, &utc);
    char stamp[32];
    std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &utc);
    const std::string path =
        fmt::format("{}/{}-{}-{:04d}.lcmlog", options_.directory, options_.file_prefix, stamp, segment_number_++);
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) {
      if (errno == EEXIST) continue;
      const int err = errno;
      struct stat st {};
      const bool dir_ok = ::stat(options_.directory.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
      fail(dir_ok ? fmt::format("cannot create log segment {}: {}", path, std::strerror(err))
                  : fmt::format("recording directory {} is unusable: cannot create {}: {}", options_.directory, path,
                                std::strerror(err)));
      return false;
    }
    fd_ = fd;
    segment_bytes_ = 0;
    segment_events_ = 0;
    segment_path_ = path;
    std::lock_guard<std::mutex> lock(mutex_);
    stats_.failing = false;
    stats_.segment = path;
    ++stats_.segments_opened;
    return true;
  }
  fail(fmt::format("cannot create a new log segment in {}: 100 names taken", options_.directory));
  return false;
}

void Recorder::close_segment() {
  if (fd_ < 0) return;
  ::close(fd_);
  fd_ = -1;
  std::lock_guard<std::mutex> lock(mutex_);
  stats_.segment.clear();
}

bool Recorder::write_event(const Event& ev) {
  const int64_t size = static_cast<int64_t>(kEventHeaderBytes + ev.channel.size() + ev.data.size());
  if (segment_bytes_ > 0 && segment_bytes_ + size > max_segment_bytes_) {
    close_segment();
    if (!open_segment()) return false;
  }
  record_buffer_.clear();
  put_be(record_buffer_, kEventMagic, 4);
  put_be(record_buffer_, static_cast<uint64_t>(segment_events_), 8);
  put_be(record_buffer_, static_cast<uint64_t>(ev.timestamp_us), 8);
  put_be(record_buffer_, ev.channel.size(), 4);
  put_be(record_buffer_, ev.data.size(), 4);
  record_buffer_.insert(record_buffer_.end(), ev.channel.begin(), ev.channel.end());
  record_buffer_.insert(record_buffer_.end(), ev.data.begin(), ev.data.end());

  size_t done = 0;
  while (done < record_buffer_.size()) {
    const ssize_t n = ::write(fd_, record_buffer_.data() + done, record_buffer_.size() - done);
    if (n > 0) {
      done += static_cast<size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    const int err = n < 0 ? errno : ENOSPC;  // write() returning 0 for a regular file: no room
    // Cut the partial event off so the segment ends with a complete one and stays readable.
    const bool truncated = ::ftruncate(fd_, static_cast<off_t>(segment_bytes_)) == 0;
    const std::string path = segment_path_;
    const int64_t events = segment_events_;
    ::close(fd_);
    fd_ = -1;
    if (events == 0) ::unlink(path.c_str());  // no empty segments from retries on a full disk
    fail(fmt::format("cannot write log segment {}: {} (segment {} after {} events{})", path, std::strerror(err),
                     events == 0 ? "removed" : "closed", events, truncated ? "" : "; could not cut the partial event"));
    return false;
  }
  segment_bytes_ += size;
  ++segment_events_;
  return true;
}

void Recorder::writer_loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    wake_.wait_for(lock, std::chrono::milliseconds(100), [this] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) {
      if (stopping_) break;
      continue;
    }
    if (stopping_ && now_s() > stop_deadline_s_) {
      // Out of time at shutdown: what is left is dropped and counted.
      for (const auto& ev : queue_) drop_locked(ev.channel, 1, /*write_error=*/true);
      queue_.clear();
      stats_.queued_bytes = 0;
      idle_.notify_all();
      break;
    }
    Event ev = std::move(queue_.front());
    queue_.pop_front();
    stats_.queued_bytes -= queued_size(ev.channel, ev.data.size());
    writing_ = true;
    lock.unlock();

    bool written = false;
    if (fd_ < 0 && now_s() >= retry_at_s_) open_segment();
    if (fd_ >= 0) written = write_event(ev);
    if (!written && fd_ < 0 && now_s() >= retry_at_s_) retry_at_s_ = now_s() + options_.retry_period_s;

    lock.lock();
    writing_ = false;
    if (written) {
      ++stats_.events_written;
      stats_.bytes_written += static_cast<int64_t>(kEventHeaderBytes + ev.channel.size() + ev.data.size());
    } else {
      drop_locked(ev.channel, 1, /*write_error=*/true);
    }
    if (queue_.empty()) idle_.notify_all();
  }
  lock.unlock();
  close_segment();
}

}  // namespace wingman::recorder
