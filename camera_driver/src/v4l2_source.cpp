// SPDX-License-Identifier: MIT
// V4l2Source: negotiation, mmap streaming, drop and gap counting, timestamp conversion, reconnection.
#include "wingman/camera_driver/v4l2_source.hpp"

#include <wingman/common/config.hpp>

#include <fmt/format.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace wingman::camera_driver {
namespace {

constexpr int kMaxSide = 8192;  // pixels, as common::ImageLimits
constexpr double kMaxFps = 1000.0;
constexpr double kMaxBackoffS = 3600.0;

int64_t seconds_to_us(double s) { return static_cast<int64_t>(std::llround(s * 1e6)); }

}  // namespace

std::vector<std::string> V4l2SourceOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (device.empty()) p.push_back(problem("v4l2.device", device, "must name a device node, e.g. /dev/video0"));
  if (pixel_format != "YUYV" && pixel_format != "MJPEG") {
    p.push_back(problem("v4l2.pixel_format", pixel_format, "must be YUYV or MJPEG"));
  }
  if (width < 1 || width > kMaxSide) p.push_back(problem("v4l2.width", width, "must be in [1, 8192] pixels"));
  if (height < 1 || height > kMaxSide) p.push_back(problem("v4l2.height", height, "must be in [1, 8192] pixels"));
  if (!std::isfinite(fps) || fps < 0 || fps > kMaxFps) {
    p.push_back(problem("v4l2.fps", fps, "must be in [0, 1000] frames per second (0 = driver default)"));
  }
  if (buffers < 2 || buffers > 32) p.push_back(problem("v4l2.buffers", buffers, "must be in [2, 32]"));
  if (!std::isfinite(reconnect_initial_s) || reconnect_initial_s <= 0 || reconnect_initial_s > kMaxBackoffS) {
    p.push_back(problem("v4l2.reconnect_initial_s", reconnect_initial_s, "must be in (0, 3600] seconds"));
  }
  if (!std::isfinite(reconnect_max_s) || reconnect_max_s < reconnect_initial_s || reconnect_max_s > kMaxBackoffS) {
    p.push_back(
        problem("v4l2.reconnect_max_s", reconnect_max_s, "must be in [v4l2.reconnect_initial_s, 3600] seconds"));
  }
  if (!std::isfinite(stall_timeout_s) || stall_timeout_s < 0) {
    p.push_back(problem("v4l2.stall_timeout_s", stall_timeout_s, "must be >= 0 seconds (0 = never)"));
  }
  return p;
}

V4l2Source::V4l2Source(V4l2SourceOptions options, std::shared_ptr<V4l2Io> io, std::shared_ptr<Clock> clock)
    : options_(std::move(options)), io_(std::move(io)), clock_(std::move(clock)) {
  if (!io_ || !clock_) throw std::invalid_argument("V4l2Source: io and clock must not be null");
  const auto problems = options_.validate();
  if (!problems.empty()) throw std::invalid_argument("V4l2Source: " + problems.front());
  if (options_.pixel_format == "MJPEG") {
    format_ = PixelFormat::kMjpeg;
    fourcc_ = V4L2_PIX_FMT_MJPEG;
  } else {
    format_ = PixelFormat::kYuyv;
    fourcc_ = V4L2_PIX_FMT_YUYV;
  }
}

V4l2Source::~V4l2Source() { stop(); }

std::string V4l2Source::supported_formats() {
  std::string list;
  for (uint32_t i = 0; i < 64; ++i) {
    v4l2_fmtdesc desc{};
    desc.index = i;
    desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (io_->ioctl(fd_, VIDIOC_ENUM_FMT, &desc) < 0) break;
    list += (list.empty() ? "" : ", ") + fourcc_name(desc.pixelformat);
  }
  return list.empty() ? "none listed" : list;
}

std::string V4l2Source::start() {
  const std::string& dev = options_.device;
  auto fail = [&](const std::string& what) {
    stop();
    return fmt::format("device {}: {}", dev, what);
  };

  const int fd = io_->open(dev);
  if (fd < 0) {
    std::string hint;
    if (fd == -ENOENT) hint = " (no such device node; is the camera plugged in?)";
    if (fd == -EACCES) hint = " (no permission; add the user to the 'video' group)";
    if (fd == -EBUSY) hint = " (in use by another process)";
    return fmt::format("device {}: cannot open: {}{}", dev, errno_name(fd), hint);
  }
  fd_ = fd;

  // Capabilities: single-planar video capture with streaming I/O.
  v4l2_capability cap{};
  if (int r = io_->ioctl(fd_, VIDIOC_QUERYCAP, &cap); r < 0) {
    return fail(fmt::format("VIDIOC_QUERYCAP failed: {} (not a V4L2 device?)", errno_name(r)));
  }
  const uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  const std::string card(reinterpret_cast<const char*>(cap.card),
                         strnlen(reinterpret_cast<const char*>(cap.card), sizeof(cap.card)));
  if (!(caps & V4L2_CAP_VIDEO_CAPTURE)) {
    return fail(fmt::format("'{}' is not a single-planar video capture device (capabilities 0x{:08x})", card, caps));
  }
  if (!(caps & V4L2_CAP_STREAMING)) {
    return fail(fmt::format("'{}' does not support streaming I/O (mmap)", card));
  }

  // Format: accept the driver's rounded size; insist on the pixel format.
  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  fmt.fmt.pix.width = static_cast<uint32_t>(options_.width);
  fmt.fmt.pix.height = static_cast<uint32_t>(options_.height);
  fmt.fmt.pix.pixelformat = fourcc_;
  fmt.fmt.pix.field = V4L2_FIELD_ANY;
  if (int r = io_->ioctl(fd_, VIDIOC_S_FMT, &fmt); r < 0) {
    return fail(fmt::format("VIDIOC_S_FMT {} {}x{} failed: {}", fourcc_name(fourcc_), options_.width, options_.height,
                            errno_name(r)));
  }
  const uint32_t got = fmt.fmt.pix.pixelformat;
  const bool jpeg_alias = fourcc_ == V4L2_PIX_FMT_MJPEG && got == V4L2_PIX_FMT_JPEG;
  if (got != fourcc_ && !jpeg_alias) {
    const std::string offered = supported_formats();
    return fail(fmt::format("pixel format '{}' not supported (driver chose '{}'; it offers {}; expected YUYV or MJPG)",
                            fourcc_name(fourcc_), fourcc_name(got), offered));
  }
  width_ = static_cast<int>(fmt.fmt.pix.width);
  height_ = static_cast<int>(fmt.fmt.pix.height);
  if (width_ <= 0 || height_ <= 0 || width_ > kMaxSide || height_ > kMaxSide) {
    return fail(fmt::format("driver set an unusable frame size {}x{}", width_, height_));
  }
  if (width_ != options_.width || height_ != options_.height) {
    spdlog::info("device {}: asked for {}x{}, driver set {}x{}", dev, options_.width, options_.height, width_, height_);
  }
  sizeimage_ = fmt.fmt.pix.sizeimage;
  if (format_ == PixelFormat::kYuyv) {
    if (width_ % 2 != 0) return fail(fmt::format("driver set an odd YUYV width {}", width_));
    const uint32_t min_stride = static_cast<uint32_t>(width_) * 2;
    const uint32_t bpl = fmt.fmt.pix.bytesperline == 0 ? min_stride : fmt.fmt.pix.bytesperline;
    if (bpl < min_stride) {
      return fail(fmt::format("driver set bytesperline {} < 2 * width {}", bpl, min_stride));
    }
    stride_ = static_cast<int>(bpl);
    const uint64_t frame_bytes = static_cast<uint64_t>(bpl) * static_cast<uint64_t>(height_);
    if (sizeimage_ == 0) sizeimage_ = static_cast<uint32_t>(frame_bytes);
    if (sizeimage_ < frame_bytes - (bpl - min_stride)) {
      return fail(fmt::format("driver set sizeimage {} < bytesperline {} * height {}", sizeimage_, bpl, height_));
    }
  } else {
    stride_ = 0;
  }
  if (fmt.fmt.pix.field != V4L2_FIELD_NONE && fmt.fmt.pix.field != V4L2_FIELD_ANY) {
    spdlog::warn("device {}: driver set field order {} (interlaced); frames are published as delivered", dev,
                 fmt.fmt.pix.field);
  }

  // Frame rate: ask when the driver supports it, keep what it grants.
  fps_ = 0.0;
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  const bool have_parm = io_->ioctl(fd_, VIDIOC_G_PARM, &parm) >= 0;
  auto parm_fps = [](const v4l2_streamparm& p) {
    const auto& t = p.parm.capture.timeperframe;
    return (t.numerator > 0 && t.denominator > 0) ? static_cast<double>(t.denominator) / t.numerator : 0.0;
  };
  if (have_parm) fps_ = parm_fps(parm);
  if (options_.fps > 0) {
    if (have_parm && (parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) {
      const bool whole = std::fabs(options_.fps - std::round(options_.fps)) < 1e-9;
      parm.parm.capture.timeperframe.numerator = whole ? 1 : 1000;
      parm.parm.capture.timeperframe.denominator =
          static_cast<uint32_t>(std::llround(whole ? options_.fps : options_.fps * 1000.0));
      if (int r = io_->ioctl(fd_, VIDIOC_S_PARM, &parm); r < 0) {
        spdlog::warn("device {}: VIDIOC_S_PARM {} fps failed: {}; keeping {} fps", dev, options_.fps, errno_name(r),
                     fps_);
      } else {
        fps_ = parm_fps(parm);
        if (std::fabs(fps_ - options_.fps) > 1e-3) {
          spdlog::info("device {}: asked for {} fps, driver set {} fps", dev, options_.fps, fps_);
        }
      }
    } else {
      spdlog::warn("device {}: driver does not support setting the frame rate; running at {} fps", dev,
                   fps_ > 0 ? fmt::format("{}", fps_) : std::string("its own"));
    }
  }

  // Buffers: mmap streaming.
  v4l2_requestbuffers req{};
  req.count = static_cast<uint32_t>(options_.buffers);
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  if (int r = io_->ioctl(fd_, VIDIOC_REQBUFS, &req); r < 0) {
    return fail(fmt::format("VIDIOC_REQBUFS {} mmap buffers failed: {}", options_.buffers, errno_name(r)));
  }
  if (req.count < 2) return fail(fmt::format("driver granted {} buffers, need at least 2", req.count));
  for (uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer buf{};
    buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = i;
    if (int r = io_->ioctl(fd_, VIDIOC_QUERYBUF, &buf); r < 0) {
      return fail(fmt::format("VIDIOC_QUERYBUF {} failed: {}", i, errno_name(r)));
    }
    void* address = nullptr;
    if (int r = io_->mmap(fd_, buf.length, buf.m.offset, &address); r < 0) {
      return fail(fmt::format("mmap of buffer {} ({} bytes) failed: {}", i, buf.length, errno_name(r)));
    }
    buffers_.push_back(Buffer{address, buf.length});
  }
  for (uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer buf{};
    buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = i;
    if (int r = io_->ioctl(fd_, VIDIOC_QBUF, &buf); r < 0) {
      return fail(fmt::format("VIDIOC_QBUF {} failed: {}", i, errno_name(r)));
    }
  }
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (int r = io_->ioctl(fd_, VIDIOC_STREAMON, &type); r < 0) {
    return fail(fmt::format("VIDIOC_STREAMON failed: {}", errno_name(r)));
  }
  streaming_ = true;
  have_last_sequence_ = false;
  last_frame_mono_us_ = clock_->monotonic_utime();
  return "";
}

void V4l2Source::stop() {
  if (fd_ >= 0 && streaming_) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    io_->ioctl(fd_, VIDIOC_STREAMOFF, &type);
  }
  streaming_ = false;
  for (const Buffer& b : buffers_) io_->munmap(b.address, b.length);
  if (fd_ >= 0) {
    if (!buffers_.empty()) {
      v4l2_requestbuffers req{};
      req.count = 0;
      req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      req.memory = V4L2_MEMORY_MMAP;
      io_->ioctl(fd_, VIDIOC_REQBUFS, &req);  // frees the buffers; fails harmlessly after an unplug
    }
    io_->close(fd_);
  }
  buffers_.clear();
  fd_ = -1;
}

void V4l2Source::open() {
  if (opened_) throw std::logic_error("V4l2Source::open: already open");
  const std::string err = start();
  if (!err.empty()) {
    if (!options_.wait_for_device) throw std::runtime_error(err);
    // Not there yet: wait for it as for a replug (no disconnect counted: it never streamed).
    opened_ = true;
    disconnected_ = true;
    backoff_us_ = seconds_to_us(options_.reconnect_initial_s);
    next_attempt_mono_us_ = clock_->monotonic_utime() + backoff_us_;
    disconnect_reason_ = err;
    spdlog::warn("{}; waiting for the device (v4l2.wait_for_device), next attempt in {} s", err,
                 options_.reconnect_initial_s);
    return;
  }
  opened_ = true;
  ever_streamed_ = true;
  spdlog::info("{}", describe());
}

std::string V4l2Source::describe() const {
  if (!opened_) return fmt::format("v4l2 {} (not open)", options_.device);
  if (disconnected_ && !ever_streamed_) return fmt::format("v4l2 {} (waiting for the device)", options_.device);
  if (disconnected_) return fmt::format("v4l2 {} (disconnected, reconnecting)", options_.device);
  std::string s = fmt::format("v4l2 {} {} {}x{}", options_.device, pixel_format_name(format_), width_, height_);
  if (stride_ > 0) s += fmt::format(" stride {}", stride_);
  s += fps_ > 0 ? fmt::format(" @ {} fps", fps_) : std::string(" @ driver rate");
  s += fmt::format(", {} buffers", buffers_.size());
  if (!timestamp_source_.empty()) s += ", stamps at the " + timestamp_source_;
  return s;
}

ReadResult V4l2Source::read(Frame& out, int timeout_ms) {
  if (!opened_) throw std::logic_error("V4l2Source::read before open()");
  timeout_ms = std::max(0, timeout_ms);
  if (disconnected_) return try_reconnect(out, timeout_ms);
  if (!pending_failure_.empty()) {
    std::string why;
    why.swap(pending_failure_);
    return disconnect(why);
  }
  return capture(out, timeout_ms);
}

ReadResult V4l2Source::disconnect(const std::string& why) {
  stop();
  disconnected_ = true;
  ++stats_.disconnects;
  backoff_us_ = seconds_to_us(options_.reconnect_initial_s);
  next_attempt_mono_us_ = clock_->monotonic_utime() + backoff_us_;
  disconnect_reason_ = why;
  spdlog::warn("{}; reconnecting in {} s", why, options_.reconnect_initial_s);
  return ReadResult{ReadStatus::kDisconnected, 0, why, false};
}

ReadResult V4l2Source::try_reconnect(Frame& out, int timeout_ms) {
  int64_t now = clock_->monotonic_utime();
  if (now < next_attempt_mono_us_) {
    clock_->sleep_us(std::min<int64_t>(next_attempt_mono_us_ - now, int64_t{timeout_ms} * 1000));
    now = clock_->monotonic_utime();
    if (now < next_attempt_mono_us_) {
      return ReadResult{ReadStatus::kDisconnected, 0,
                        fmt::format("{}; next attempt in {:.1f} s", disconnect_reason_,
                                    static_cast<double>(next_attempt_mono_us_ - now) * 1e-6),
                        false};
    }
  }
  const std::string err = start();
  if (!err.empty()) {
    backoff_us_ = std::min(backoff_us_ * 2, seconds_to_us(options_.reconnect_max_s));
    next_attempt_mono_us_ = clock_->monotonic_utime() + backoff_us_;
    disconnect_reason_ = err;
    spdlog::warn("{}; next attempt in {} s", err, static_cast<double>(backoff_us_) * 1e-6);
    return ReadResult{ReadStatus::kDisconnected, 0, err, false};
  }
  disconnected_ = false;
  if (ever_streamed_) {
    ++stats_.reconnects;
    spdlog::info("reconnected: {}", describe());
  } else {
    ever_streamed_ = true;
    spdlog::info("the device is there: {}", describe());
  }
  ReadResult r = capture(out, 0);
  r.reconnected = true;
  return r;
}

std::string V4l2Source::requeue(v4l2_buffer& buf) {
  if (int r = io_->ioctl(fd_, VIDIOC_QBUF, &buf); r < 0) {
    return fmt::format("device {}: VIDIOC_QBUF failed: {}", options_.device, errno_name(r));
  }
  return "";
}

ReadResult V4l2Source::capture(Frame& out, int timeout_ms) {
  const std::string& dev = options_.device;
  auto stalled = [&]() -> bool {
    return options_.stall_timeout_s > 0 &&
           clock_->monotonic_utime() - last_frame_mono_us_ > seconds_to_us(options_.stall_timeout_s);
  };
  short revents = 0;
  const int pr = io_->poll(fd_, timeout_ms, &revents);
  if (pr < 0) return disconnect(fmt::format("device {}: poll failed: {}", dev, errno_name(pr)));
  if (pr == 0) {
    if (stalled())
      return disconnect(fmt::format("device {}: no frame for {} s (stalled)", dev, options_.stall_timeout_s));
    return ReadResult{ReadStatus::kTimeout, 0, "", false};
  }

  v4l2_buffer buf{};
  buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buf.memory = V4L2_MEMORY_MMAP;
  const int dr = io_->ioctl(fd_, VIDIOC_DQBUF, &buf);
  if (dr == -EAGAIN) {
    if (revents & (POLLERR | POLLHUP)) {
      return disconnect(fmt::format("device {}: poll reports an error and no buffer is ready (unplugged?)", dev));
    }
    if (stalled())
      return disconnect(fmt::format("device {}: no frame for {} s (stalled)", dev, options_.stall_timeout_s));
    return ReadResult{ReadStatus::kTimeout, 0, "", false};
  }
  if (dr < 0) {
    return disconnect(
        fmt::format("device {}: VIDIOC_DQBUF failed: {}{}", dev, errno_name(dr), dr == -ENODEV ? " (unplugged)" : ""));
  }
  // Sample the clock-domain offset right after the dequeue (see the class comment).
  const int64_t mono_now = clock_->monotonic_utime();
  const int64_t real_now = clock_->realtime_utime();
  last_frame_mono_us_ = mono_now;
  if (buf.index >= buffers_.size()) {
    return disconnect(fmt::format("device {}: driver returned buffer index {} of {}", dev, buf.index, buffers_.size()));
  }

  // Sequence: a gap of n means n frames never reached us. A jump backwards (or by more than 2^31)
  // means the driver restarted its count: no gap can be inferred.
  int64_t gap = 0;
  if (have_last_sequence_) {
    const uint32_t step = buf.sequence - last_sequence_;  // wraps modulo 2^32
    if (step >= 2 && step < 0x80000000u) gap = static_cast<int64_t>(step) - 1;
  } else if (!seq_started_) {
    next_seq_ = buf.sequence;  // the very first frame keeps the driver's numbering
    seq_started_ = true;
  }
  have_last_sequence_ = true;
  last_sequence_ = buf.sequence;
  const int64_t seq = next_seq_ + gap;
  next_seq_ = seq + 1;
  stats_.lost_in_gaps += gap;
  const std::string gap_reason = gap > 0 ? fmt::format("device {}: {} frame{} lost before seq {} (sequence gap)", dev,
                                                       gap, gap == 1 ? "" : "s", seq)
                                         : std::string();

  auto drop = [&](const std::string& why) -> ReadResult {
    ++stats_.dropped;
    if (std::string e = requeue(buf); !e.empty()) pending_failure_ = e;
    const std::string reason = gap > 0 ? gap_reason + "; " + why : why;
    spdlog::debug("{}", reason);
    return ReadResult{ReadStatus::kDropped, 1 + gap, reason, false};
  };
  if (buf.flags & V4L2_BUF_FLAG_ERROR) {
    return drop(fmt::format("device {}: frame seq {} flagged V4L2_BUF_FLAG_ERROR (corrupted in transfer)", dev, seq));
  }
  const Buffer& mem = buffers_[buf.index];
  const size_t used = std::min<size_t>(buf.bytesused, mem.length);
  if (used == 0) return drop(fmt::format("device {}: frame seq {} is empty (bytesused 0)", dev, seq));
  const auto* src = static_cast<const uint8_t*>(mem.address);

  out.format = format_;
  out.width = width_;
  out.height = height_;
  out.seq = seq;
  if (format_ == PixelFormat::kYuyv) {
    // The last row may come without its padding; anything shorter is a truncated frame.
    const size_t full = static_cast<size_t>(stride_) * static_cast<size_t>(height_);
    const size_t needed = full - static_cast<size_t>(stride_ - width_ * 2);
    if (used < needed) {
      return drop(fmt::format("device {}: frame seq {} truncated: bytesused {} < {} (bytesperline {} * height {})", dev,
                              seq, used, needed, stride_, height_));
    }
    out.stride = stride_;
    out.data.assign(full, 0);
    std::memcpy(out.data.data(), src, std::min(used, full));
  } else {
    if (used < 4 || src[0] != 0xFF || src[1] != 0xD8) {
      return drop(fmt::format("device {}: frame seq {} is not a JPEG image (no SOI marker, {} bytes)", dev, seq, used));
    }
    out.stride = 0;
    out.data.assign(src, src + used);
  }

  if (timestamp_source_.empty()) {
    if ((buf.flags & V4L2_BUF_FLAG_TSTAMP_SRC_MASK) == V4L2_BUF_FLAG_TSTAMP_SRC_SOE) {
      timestamp_source_ = "start of exposure";
      spdlog::info("device {}: buffer timestamps mark the start of exposure (V4L2_BUF_FLAG_TSTAMP_SRC_SOE)", dev);
    } else {
      timestamp_source_ = "end of the frame";
      spdlog::warn(
          "device {}: buffer timestamps mark the end of the frame (V4L2_BUF_FLAG_TSTAMP_SRC_EOF), later than the "
          "exposure by its readout: set output.time_offset_s to move them to the exposure",
          dev);
    }
  }
  const int64_t t_buffer_mono = static_cast<int64_t>(buf.timestamp.tv_sec) * 1000000 + buf.timestamp.tv_usec;
  out.utime = t_buffer_mono > 0 ? t_buffer_mono + (real_now - mono_now) : real_now;
  if (t_buffer_mono <= 0 && !warned_zero_timestamp_) {
    spdlog::warn("device {}: driver gives zero buffer timestamps; stamping frames at dequeue time", dev);
    warned_zero_timestamp_ = true;
  }

  if (std::string e = requeue(buf); !e.empty()) pending_failure_ = e;  // deliver this frame, disconnect next read
  ++stats_.frames;
  return ReadResult{ReadStatus::kFrame, gap, gap_reason, false};
}

}  // namespace wingman::camera_driver
