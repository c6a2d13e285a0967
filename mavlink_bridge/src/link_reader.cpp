// SPDX-License-Identifier: MIT
// The link's reading thread.
#include "wingman/mavlink_bridge/link_reader.hpp"

#include <wingman/common/time.hpp>

#include <poll.h>

#include <cmath>

namespace wingman::mavlink_bridge {

namespace {
constexpr size_t kReadSize = 4096;
constexpr int kPollMs = 50;  ///< the thread notices stop() within this
}  // namespace

LinkReader::LinkReader(std::unique_ptr<Link> link, double reopen_period_s, size_t max_queued,
                       std::function<void()> notify)
    : link_(std::move(link)),
      description_(link_->describe()),
      reopen_us_(static_cast<int64_t>(std::llround(reopen_period_s * 1e6))),
      max_queued_(max_queued),
      notify_(std::move(notify)),
      thread_([this] { run(); }) {}

LinkReader::~LinkReader() {
  stop_ = true;
  thread_.join();
  std::lock_guard<std::mutex> lock(link_mutex_);
  link_->close();
}

bool LinkReader::write(const std::vector<uint8_t>& frame) {
  std::lock_guard<std::mutex> lock(link_mutex_);
  return link_->write(frame);
}

bool LinkReader::is_open() const {
  std::lock_guard<std::mutex> lock(link_mutex_);
  return link_->is_open();
}

void LinkReader::take(std::vector<LinkChunk>& out) {
  std::lock_guard<std::mutex> lock(queue_mutex_);
  for (auto& c : queue_) out.push_back(std::move(c));
  queue_.clear();
}

void LinkReader::push(LinkChunk chunk) {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    if (queue_.size() >= max_queued_ && chunk.event.empty()) {
      ++dropped_;
      return;
    }
    queue_.push_back(std::move(chunk));
  }
  if (notify_) notify_();
}

void LinkReader::run() {
  int64_t next_open_us = 0;
  std::string last_open_error;
  std::vector<uint8_t> buf(kReadSize);
  while (!stop_) {
    int fd = -1;
    {
      std::lock_guard<std::mutex> lock(link_mutex_);
      if (!link_->is_open() && common::monotonic_utime() >= next_open_us) {
        try {
          link_->open();
          last_open_error.clear();
          LinkChunk c;
          c.event = "link open: " + description_;
          push(std::move(c));
        } catch (const std::exception& e) {
          next_open_us = common::monotonic_utime() + reopen_us_;
          if (e.what() != last_open_error) {  // each different reason once
            last_open_error = e.what();
            LinkChunk c;
            c.event = e.what();
            push(std::move(c));
          }
        }
      }
      fd = link_->fd();
    }
    if (fd < 0) {
      ::poll(nullptr, 0, kPollMs);
      continue;
    }
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, kPollMs) <= 0) continue;
    LinkChunk c;
    long n = 0;
    {
      std::lock_guard<std::mutex> lock(link_mutex_);
      n = link_->read(buf.data(), buf.size());
      c.mono_us = common::monotonic_utime();
      c.wall_ns = common::wall_utime() * 1000;
      c.datagram = link_->datagrams();
      if (n < 0) next_open_us = c.mono_us + reopen_us_;
    }
    if (n == 0) continue;
    if (n < 0) {
      c.event = "link lost: " + description_;
      c.lost = true;
    } else {
      c.bytes.assign(buf.begin(), buf.begin() + n);
    }
    push(std::move(c));
  }
}

}  // namespace wingman::mavlink_bridge
