// SPDX-License-Identifier: MIT
// An in-process fake V4L2 capture device behind the V4l2Io seam: rounding, padding, drops, unplug.
#pragma once

#include "fake_clock.hpp"
#include "wingman/camera_driver/v4l2_io.hpp"

#include <linux/videodev2.h>

#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

namespace wingman::camera_driver::testing {

/// How the fake device behaves (a UVC-like camera by default).
struct FakeDeviceConfig {
  std::string path = "/dev/video0";  ///< the only node that opens
  bool present = true;               ///< false: open() fails with ENOENT (missing device)
  int absent_opens = 0;              ///< the first this many open() calls fail with ENOENT (a camera enumerating late)
  std::string card = "Fake UVC Camera";
  uint32_t capabilities = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
  std::vector<uint32_t> formats = {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG};  ///< S_FMT falls back to the first
  int width_multiple = 16;                         ///< S_FMT rounds the width to the nearest multiple, pixels
  int height_multiple = 8;                         ///< S_FMT rounds the height to the nearest multiple, pixels
  int max_width = 1920;                            ///< pixels
  int max_height = 1080;                           ///< pixels
  int stride_align = 64;                           ///< YUYV bytesperline = width * 2 rounded up to this, bytes
  bool supports_timeperframe = true;               ///< whether S_PARM can set the rate
  std::vector<double> frame_rates = {15.0, 30.0};  ///< S_PARM picks the nearest, frames per second
  uint32_t max_buffers = 8;                        ///< REQBUFS grants at most this many
  uint8_t padding_byte = 0xEE;                     ///< value of the padding bytes at the end of each YUYV row
  bool timestamp_end_of_frame = false;             ///< buffers flagged TSTAMP_SRC_EOF instead of SOE
};

/// One scripted event, consumed in order by VIDIOC_DQBUF.
struct FakeEvent {
  enum class Kind { kFrame, kUnplug };
  Kind kind = Kind::kFrame;
  uint32_t sequence = 0;         ///< driver sequence number
  uint32_t extra_flags = 0;      ///< e.g. V4L2_BUF_FLAG_ERROR
  int64_t bytesused = -1;        ///< -1: the whole frame
  int64_t timestamp_us = -1;     ///< monotonic buffer timestamp; -1: the fake clock's monotonic time at DQBUF
  std::vector<uint8_t> payload;  ///< MJPEG bytes (default: a minimal SOI...EOI stream); unused for YUYV
  int failing_opens = 0;         ///< kUnplug: open() fails with ENOENT this many times before the replug
};

/// The pixel byte the fake writes at row `y`, byte `x` (x < width * 2) of the frame with `sequence`.
uint8_t fake_pixel(uint32_t sequence, int y, int x);

/// A fake /dev/videoN implementing V4l2Io. Single device, single open file at a time.
class FakeV4l2Device : public V4l2Io {
 public:
  explicit FakeV4l2Device(FakeDeviceConfig config = {}, FakeClock* clock = nullptr);

  // Script.
  void push_frame(uint32_t sequence, uint32_t extra_flags = 0, int64_t bytesused = -1);
  void push_event(FakeEvent event) { events_.push_back(std::move(event)); }
  /// Frames with sequences first .. first + count - 1.
  void push_frames(uint32_t first, int count);
  /// The device vanishes when DQBUF reaches this point; open() then fails `failing_opens` times.
  void push_unplug(int failing_opens);

  // V4l2Io.
  int open(const std::string& path) override;
  int close(int fd) override;
  int ioctl(int fd, unsigned long request, void* arg) override;
  int mmap(int fd, size_t length, int64_t offset, void** address) override;
  int munmap(void* address, size_t length) override;
  int poll(int fd, int timeout_ms, short* revents) override;

  // Observations.
  /// Monotonic time of every open() attempt (needs a clock), microseconds.
  const std::vector<int64_t>& open_attempts_us() const { return open_attempts_us_; }
  int open_calls() const { return open_calls_; }
  bool is_open() const { return open_fd_ >= 0; }
  bool streaming() const { return streaming_; }
  int live_mappings() const { return live_mappings_; }
  size_t pending_events() const { return events_.size(); }
  /// Width and height asked for in the last S_FMT, pixels.
  uint32_t requested_width() const { return requested_width_; }
  uint32_t requested_height() const { return requested_height_; }
  const FakeDeviceConfig& config() const { return config_; }
  FakeDeviceConfig& config() { return config_; }

 private:
  struct Buffer {
    std::vector<uint8_t> memory;
    enum class State { kIdle, kQueued, kDequeued } state = State::kIdle;
    bool mapped = false;
  };
  int check_fd(int fd) const;
  void fill(Buffer& b, const FakeEvent& e, v4l2_buffer* out);

  FakeDeviceConfig config_;
  FakeClock* clock_;
  std::deque<FakeEvent> events_;
  int next_fd_ = 3;
  int open_fd_ = -1;
  int open_calls_ = 0;
  int failing_opens_ = 0;
  bool unplugged_ = false;
  bool streaming_ = false;
  int live_mappings_ = 0;
  v4l2_pix_format format_{};
  double fps_ = 30.0;
  std::vector<Buffer> buffers_;
  std::deque<uint32_t> queued_;
  std::vector<int64_t> open_attempts_us_;
  uint32_t requested_width_ = 0;
  uint32_t requested_height_ = 0;
};

}  // namespace wingman::camera_driver::testing
