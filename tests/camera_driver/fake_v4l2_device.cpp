// SPDX-License-Identifier: MIT
// FakeV4l2Device: the V4L2 ioctls V4l2Source uses, on in-process buffers, driven by a script.
#include "fake_v4l2_device.hpp"

#include <poll.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

namespace wingman::camera_driver::testing {
namespace {

constexpr int64_t kOffsetStep = 0x10000;  // mmap offset of buffer i is i * kOffsetStep

int round_to_multiple(int v, int m, int lo, int hi) {
  const int r = static_cast<int>(std::lround(static_cast<double>(v) / m)) * m;
  return std::clamp(r, lo, hi);
}

}  // namespace

uint8_t fake_pixel(uint32_t sequence, int y, int x) {
  return static_cast<uint8_t>((sequence * 31u + static_cast<uint32_t>(y) * 7u + static_cast<uint32_t>(x) * 3u) & 0xffu);
}

FakeV4l2Device::FakeV4l2Device(FakeDeviceConfig config, FakeClock* clock) : config_(std::move(config)), clock_(clock) {}

void FakeV4l2Device::push_frame(uint32_t sequence, uint32_t extra_flags, int64_t bytesused) {
  FakeEvent e;
  e.sequence = sequence;
  e.extra_flags = extra_flags;
  e.bytesused = bytesused;
  events_.push_back(std::move(e));
}

void FakeV4l2Device::push_frames(uint32_t first, int count) {
  for (int i = 0; i < count; ++i) push_frame(first + static_cast<uint32_t>(i));
}

void FakeV4l2Device::push_unplug(int failing_opens) {
  FakeEvent e;
  e.kind = FakeEvent::Kind::kUnplug;
  e.failing_opens = failing_opens;
  events_.push_back(std::move(e));
}

int FakeV4l2Device::open(const std::string& path) {
  ++open_calls_;
  if (clock_ != nullptr) open_attempts_us_.push_back(clock_->monotonic_utime());
  if (path != config_.path || !config_.present) return -ENOENT;
  if (open_calls_ <= config_.absent_opens) return -ENOENT;
  if (unplugged_) {
    if (failing_opens_ > 0) {
      --failing_opens_;
      return -ENOENT;
    }
    unplugged_ = false;  // plugged in again: a fresh device
  }
  if (open_fd_ >= 0) return -EBUSY;
  streaming_ = false;
  queued_.clear();
  if (live_mappings_ == 0) buffers_.clear();
  format_ = v4l2_pix_format{};
  open_fd_ = next_fd_++;
  return open_fd_;
}

int FakeV4l2Device::close(int fd) {
  if (fd != open_fd_ || fd < 0) return -EBADF;
  open_fd_ = -1;
  streaming_ = false;
  queued_.clear();
  if (live_mappings_ == 0) buffers_.clear();
  return 0;
}

int FakeV4l2Device::check_fd(int fd) const {
  if (fd < 0 || fd != open_fd_) return -EBADF;
  if (unplugged_) return -ENODEV;
  return 0;
}

void FakeV4l2Device::fill(Buffer& b, const FakeEvent& e, v4l2_buffer* out) {
  size_t used = 0;
  if (format_.pixelformat == V4L2_PIX_FMT_YUYV) {
    std::fill(b.memory.begin(), b.memory.end(), config_.padding_byte);
    for (uint32_t y = 0; y < format_.height; ++y) {
      uint8_t* row = b.memory.data() + static_cast<size_t>(y) * format_.bytesperline;
      for (uint32_t x = 0; x < format_.width * 2; ++x)
        row[x] = fake_pixel(e.sequence, static_cast<int>(y), static_cast<int>(x));
    }
    used = static_cast<size_t>(format_.bytesperline) * format_.height;
  } else {
    static const std::vector<uint8_t> kMinimalJpeg = {0xFF, 0xD8, 0xFF, 0xE0, 0x00, 0x04, 0x00, 0x00, 0xFF, 0xD9};
    const std::vector<uint8_t>& p = e.payload.empty() ? kMinimalJpeg : e.payload;
    used = std::min(p.size(), b.memory.size());
    std::memcpy(b.memory.data(), p.data(), used);
  }
  if (e.bytesused >= 0) used = static_cast<size_t>(e.bytesused);
  out->bytesused = static_cast<uint32_t>(used);
  out->length = static_cast<uint32_t>(b.memory.size());
  out->sequence = e.sequence;
  out->flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC |
               (config_.timestamp_end_of_frame ? V4L2_BUF_FLAG_TSTAMP_SRC_EOF : V4L2_BUF_FLAG_TSTAMP_SRC_SOE) |
               e.extra_flags;
  out->field = V4L2_FIELD_NONE;
  int64_t ts = e.timestamp_us;
  if (ts < 0) ts = clock_ != nullptr ? clock_->monotonic_utime() : 1'000'000'000 + int64_t{e.sequence} * 33'333;
  out->timestamp.tv_sec = static_cast<time_t>(ts / 1'000'000);
  out->timestamp.tv_usec = static_cast<suseconds_t>(ts % 1'000'000);
}

int FakeV4l2Device::ioctl(int fd, unsigned long request, void* arg) {
  if (int r = check_fd(fd); r < 0) return r;
  switch (request) {
    case VIDIOC_QUERYCAP: {
      auto* cap = static_cast<v4l2_capability*>(arg);
      *cap = v4l2_capability{};
      std::strncpy(reinterpret_cast<char*>(cap->driver), "fake", sizeof(cap->driver) - 1);
      std::strncpy(reinterpret_cast<char*>(cap->card), config_.card.c_str(), sizeof(cap->card) - 1);
      cap->capabilities = config_.capabilities | V4L2_CAP_DEVICE_CAPS;
      cap->device_caps = config_.capabilities;
      return 0;
    }
    case VIDIOC_ENUM_FMT: {
      auto* d = static_cast<v4l2_fmtdesc*>(arg);
      if (d->index >= config_.formats.size()) return -EINVAL;
      d->pixelformat = config_.formats[d->index];
      return 0;
    }
    case VIDIOC_S_FMT:
    case VIDIOC_TRY_FMT: {
      auto* f = static_cast<v4l2_format*>(arg);
      if (f->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return -EINVAL;
      if (streaming_ || !buffers_.empty()) return -EBUSY;
      v4l2_pix_format& p = f->fmt.pix;
      requested_width_ = p.width;
      requested_height_ = p.height;
      if (std::find(config_.formats.begin(), config_.formats.end(), p.pixelformat) == config_.formats.end()) {
        p.pixelformat = config_.formats.front();
      }
      p.width = static_cast<uint32_t>(round_to_multiple(static_cast<int>(p.width), config_.width_multiple,
                                                        config_.width_multiple, config_.max_width));
      p.height = static_cast<uint32_t>(round_to_multiple(static_cast<int>(p.height), config_.height_multiple,
                                                         config_.height_multiple, config_.max_height));
      p.field = V4L2_FIELD_NONE;
      if (p.pixelformat == V4L2_PIX_FMT_YUYV) {
        const uint32_t a = static_cast<uint32_t>(config_.stride_align);
        p.bytesperline = (p.width * 2 + a - 1) / a * a;
        p.sizeimage = p.bytesperline * p.height;
      } else {
        p.bytesperline = 0;
        p.sizeimage = p.width * p.height * 2;  // a JPEG fits (UVC drivers give a similar bound)
      }
      if (request == VIDIOC_S_FMT) format_ = p;
      return 0;
    }
    case VIDIOC_G_FMT: {
      auto* f = static_cast<v4l2_format*>(arg);
      f->fmt.pix = format_;
      return 0;
    }
    case VIDIOC_G_PARM:
    case VIDIOC_S_PARM: {
      auto* p = static_cast<v4l2_streamparm*>(arg);
      if (p->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return -EINVAL;
      if (request == VIDIOC_S_PARM) {
        if (!config_.supports_timeperframe) return -ENOTTY;
        const auto& t = p->parm.capture.timeperframe;
        if (t.numerator == 0 || t.denominator == 0) return -EINVAL;
        const double want = static_cast<double>(t.denominator) / t.numerator;
        fps_ = *std::min_element(config_.frame_rates.begin(), config_.frame_rates.end(),
                                 [&](double a, double b) { return std::fabs(a - want) < std::fabs(b - want); });
      }
      p->parm.capture = v4l2_captureparm{};
      p->parm.capture.capability = config_.supports_timeperframe ? V4L2_CAP_TIMEPERFRAME : 0;
      p->parm.capture.timeperframe.numerator = 1;
      p->parm.capture.timeperframe.denominator = static_cast<uint32_t>(std::lround(fps_));
      return 0;
    }
    case VIDIOC_REQBUFS: {
      auto* r = static_cast<v4l2_requestbuffers*>(arg);
      if (r->memory != V4L2_MEMORY_MMAP || r->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return -EINVAL;
      if (streaming_) return -EBUSY;
      if (r->count == 0) {
        if (live_mappings_ > 0) return -EBUSY;
        buffers_.clear();
        queued_.clear();
        return 0;
      }
      if (!buffers_.empty()) return -EBUSY;
      r->count = std::min(r->count, config_.max_buffers);
      buffers_.resize(r->count);
      for (auto& b : buffers_) b.memory.assign(format_.sizeimage, 0);
      return 0;
    }
    case VIDIOC_QUERYBUF: {
      auto* b = static_cast<v4l2_buffer*>(arg);
      if (b->index >= buffers_.size()) return -EINVAL;
      b->length = static_cast<uint32_t>(buffers_[b->index].memory.size());
      b->m.offset = static_cast<uint32_t>(b->index * kOffsetStep);
      return 0;
    }
    case VIDIOC_QBUF: {
      auto* b = static_cast<v4l2_buffer*>(arg);
      if (b->index >= buffers_.size() || buffers_[b->index].state == Buffer::State::kQueued) return -EINVAL;
      buffers_[b->index].state = Buffer::State::kQueued;
      queued_.push_back(b->index);
      return 0;
    }
    case VIDIOC_DQBUF: {
      if (!streaming_) return -EINVAL;
      if (!events_.empty() && events_.front().kind == FakeEvent::Kind::kUnplug) {
        failing_opens_ = events_.front().failing_opens;
        events_.pop_front();
        unplugged_ = true;
        streaming_ = false;
        return -ENODEV;
      }
      if (events_.empty() || queued_.empty()) return -EAGAIN;
      const FakeEvent e = events_.front();
      events_.pop_front();
      const uint32_t index = queued_.front();
      queued_.pop_front();
      auto* b = static_cast<v4l2_buffer*>(arg);
      b->index = index;
      fill(buffers_[index], e, b);
      buffers_[index].state = Buffer::State::kDequeued;
      return 0;
    }
    case VIDIOC_STREAMON:
      if (buffers_.empty()) return -EINVAL;
      streaming_ = true;
      return 0;
    case VIDIOC_STREAMOFF:
      streaming_ = false;
      queued_.clear();
      for (auto& b : buffers_) b.state = Buffer::State::kIdle;
      return 0;
    default:
      return -ENOTTY;
  }
}

int FakeV4l2Device::mmap(int fd, size_t length, int64_t offset, void** address) {
  if (int r = check_fd(fd); r < 0) return r;
  if (offset % kOffsetStep != 0) return -EINVAL;
  const size_t index = static_cast<size_t>(offset / kOffsetStep);
  if (index >= buffers_.size() || buffers_[index].memory.size() != length || buffers_[index].mapped) return -EINVAL;
  buffers_[index].mapped = true;
  ++live_mappings_;
  *address = buffers_[index].memory.data();
  return 0;
}

int FakeV4l2Device::munmap(void* address, size_t length) {
  for (auto& b : buffers_) {
    if (b.mapped && b.memory.data() == address && b.memory.size() == length) {
      b.mapped = false;
      --live_mappings_;
      return 0;
    }
  }
  return -EINVAL;
}

int FakeV4l2Device::poll(int fd, int timeout_ms, short* revents) {
  if (fd < 0 || fd != open_fd_) return -EBADF;
  if (!unplugged_ && !events_.empty() && events_.front().kind == FakeEvent::Kind::kUnplug && streaming_) {
    failing_opens_ = events_.front().failing_opens;
    events_.pop_front();
    unplugged_ = true;
    streaming_ = false;
  }
  if (unplugged_) {
    *revents = POLLERR | POLLHUP;
    return 1;
  }
  if (!streaming_) {
    *revents = POLLERR;
    return 1;
  }
  if (!events_.empty() && !queued_.empty()) {
    *revents = POLLIN;
    return 1;
  }
  if (clock_ != nullptr) clock_->advance(int64_t{timeout_ms} * 1000);  // waited in vain for the whole timeout
  return 0;
}

}  // namespace wingman::camera_driver::testing
