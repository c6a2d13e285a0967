// SPDX-License-Identifier: MIT
// V4L2 camera capture with mmap streaming, format negotiation, drop counting and reconnection.
#pragma once

#include "wingman/camera_driver/clock.hpp"
#include "wingman/camera_driver/frame_source.hpp"
#include "wingman/camera_driver/v4l2_io.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

struct v4l2_buffer;  // <linux/videodev2.h>

namespace wingman::camera_driver {

/// What to ask the camera for. The driver may round size and rate; V4l2Source accepts what it gets
/// (and logs it) as long as the pixel format is the one asked for.
struct V4l2SourceOptions {
  /// Device node, e.g. /dev/video0 or /dev/v4l/by-id/usb-...-video-index0 (stable across replugs).
  std::string device = "/dev/video0";
  /// Pixel format to request: YUYV (raw 4:2:2) or MJPEG (compressed, published undecoded by default).
  std::string pixel_format = "YUYV";
  /// Requested width, pixels (the driver may round it).
  int width = 640;
  /// Requested height, pixels (the driver may round it).
  int height = 480;
  /// Requested frame rate, frames per second; 0 keeps the driver's current rate.
  double fps = 30.0;
  /// Number of mmap buffers to request (the driver may grant more or fewer; at least 2 are needed).
  int buffers = 4;
  /// First wait before reopening an unplugged device, seconds; doubles after each failed attempt.
  double reconnect_initial_s = 0.5;
  /// Longest wait between reopening attempts, seconds.
  double reconnect_max_s = 8.0;
  /// Streaming with no frame for this long counts as a disconnect (reopen), seconds; 0 = never.
  double stall_timeout_s = 2.0;
  /// A device that cannot be opened or negotiated at start (not plugged in yet, still enumerating at boot, busy) is
  /// retried like an unplugged one (reconnect_initial_s, doubling up to reconnect_max_s) instead of failing open():
  /// the process stays up and reports why in its heartbeat. false: open() throws (the process exits 1).
  bool wait_for_device = true;

  /// One line per problem ("v4l2.width = 0: must be in [1, 8192]"); empty when valid.
  std::vector<std::string> validate() const;
};

/// Captures from a V4L2 device through the V4l2Io seam.
///
/// Negotiation (open()): VIDIOC_QUERYCAP (needs video capture and streaming I/O), VIDIOC_S_FMT
/// (accepts the driver's rounded size and reads back bytesperline as the stride and sizeimage;
/// rejects any pixel format other than the requested YUYV/MJPG, naming what the driver offers),
/// VIDIOC_S_PARM (frame rate, if the driver supports it; the granted rate is logged),
/// VIDIOC_REQBUFS/QUERYBUF + mmap + QBUF, VIDIOC_STREAMON.
///
/// Capture (read()): poll + VIDIOC_DQBUF; the buffer is copied out and queued again at once.
/// - A buffer flagged V4L2_BUF_FLAG_ERROR, with bytesused 0, or (raw formats) with fewer than
///   stride * height bytes is a kDropped result, counted in stats().dropped.
/// - A gap in the driver's sequence numbers is reported as ReadResult::lost on the next frame and
///   counted in stats().lost_in_gaps (the dropped buffers' own numbers are not counted twice).
/// - Frame::seq starts at the driver's first sequence number and then advances by 1 + gap per
///   dequeued buffer, so it keeps increasing across reconnects (where the driver restarts at 0);
///   frames missed while unplugged show up in stats().disconnects, not as a seq gap.
///
/// Timestamps: V4L2 buffer timestamps are CLOCK_MONOTONIC (V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC; for
/// UVC the start of exposure). They are converted to epoch time as
///   utime = t_buffer_mono + (realtime_utime() - monotonic_utime())
/// with the offset sampled right after the dequeue, so the conversion error is the few microseconds
/// between the two clock reads and NTP steps of the wall clock are followed. Buffers with a zero
/// timestamp (some drivers) are stamped with the dequeue time instead. What the stamps mark, from the first buffer's
/// V4L2_BUF_FLAG_TSTAMP_SRC_* flag, is logged once and ends describe(): "stamps at the start of exposure" (SOE) or
/// "stamps at the end of the frame" (EOF: later than the exposure by its readout; a warning points to the camera
/// driver's output.time_offset_s).
///
/// Unplug: any failure of poll/DQBUF/QBUF once streaming (ENODEV, EIO, ...) or no frame for
/// stall_timeout_s tears the stream down and returns kDisconnected. Later read() calls reopen the
/// device after reconnect_initial_s, then 2x, 4x ... up to reconnect_max_s between attempts,
/// sleeping through the Clock at most `timeout_ms` per call (so a caller stays responsive).
/// Negotiation failures during reconnection are retried the same way; only open() throws.
class V4l2Source : public FrameSource {
 public:
  /// `io` and `clock` must not be null.
  V4l2Source(V4l2SourceOptions options, std::shared_ptr<V4l2Io> io, std::shared_ptr<Clock> clock);
  ~V4l2Source() override;
  V4l2Source(const V4l2Source&) = delete;
  V4l2Source& operator=(const V4l2Source&) = delete;

  /// Opens and starts streaming. On failure, with wait_for_device (default) the source starts out disconnected:
  /// read() returns kDisconnected naming the device and the failed step until an attempt succeeds (that frame's
  /// ReadResult::reconnected is true; stats().reconnects does not count it). Without it, throws
  /// std::runtime_error naming them, e.g. "device /dev/video0: cannot open: ENOENT (No such file or directory)".
  void open() override;
  ReadResult read(Frame& out, int timeout_ms) override;
  std::string describe() const override;
  const SourceStats& stats() const override { return stats_; }
  std::string waiting_reason() const override { return disconnected_ && !ever_streamed_ ? disconnect_reason_ : ""; }

  /// True while streaming (false while disconnected and before open()).
  bool streaming() const { return fd_ >= 0 && streaming_; }
  /// Negotiated values (valid after open()).
  int width() const { return width_; }
  int height() const { return height_; }
  /// Bytes per row from the driver (bytesperline); 0 for MJPEG.
  int stride() const { return stride_; }
  PixelFormat format() const { return format_; }
  /// Frame rate the driver granted, frames per second; 0 when unknown.
  double fps() const { return fps_; }
  /// Number of buffers the driver granted.
  int buffer_count() const { return static_cast<int>(buffers_.size()); }
  /// Current wait between reconnection attempts, microseconds.
  int64_t backoff_us() const { return backoff_us_; }

 private:
  struct Buffer {
    void* address = nullptr;
    size_t length = 0;
  };

  /// Opens and negotiates; returns "" or one line naming the device and the failed step.
  std::string start();
  /// Stops streaming, unmaps and closes (ignores errors: the device may be gone).
  void stop();
  /// Tears down after a failure and schedules the first reconnection attempt.
  ReadResult disconnect(const std::string& why);
  /// Waits for the next attempt (at most `timeout_ms`), then tries to reopen.
  ReadResult try_reconnect(Frame& out, int timeout_ms);
  ReadResult capture(Frame& out, int timeout_ms);
  /// Queues `buf` again; returns "" or one line on the failure.
  std::string requeue(v4l2_buffer& buf);
  /// The formats VIDIOC_ENUM_FMT lists, e.g. "YUYV, MJPG".
  std::string supported_formats();

  V4l2SourceOptions options_;
  std::shared_ptr<V4l2Io> io_;
  std::shared_ptr<Clock> clock_;
  PixelFormat format_;
  uint32_t fourcc_ = 0;

  int fd_ = -1;
  bool streaming_ = false;
  bool opened_ = false;
  std::vector<Buffer> buffers_;
  int width_ = 0;
  int height_ = 0;
  int stride_ = 0;
  uint32_t sizeimage_ = 0;
  double fps_ = 0.0;

  bool have_last_sequence_ = false;  // false after each (re)open: the driver restarts its count
  uint32_t last_sequence_ = 0;       // driver sequence of the last dequeued buffer
  bool seq_started_ = false;         // false until the first buffer ever
  int64_t next_seq_ = 0;             // Frame::seq of the next buffer when there is no gap
  int64_t last_frame_mono_us_ = 0;   // monotonic time of the last dequeue (stall detection), microseconds
  bool warned_zero_timestamp_ = false;
  /// What the driver's buffer timestamps mark (V4L2_BUF_FLAG_TSTAMP_SRC_*), from the first buffer: "" until then.
  std::string timestamp_source_;
  std::string pending_failure_;  // a QBUF failure after a delivered frame: disconnect on the next read

  bool disconnected_ = false;
  bool ever_streamed_ = false;  // false while waiting for the device at start (wait_for_device)
  bool just_reconnected_ = false;
  std::string disconnect_reason_;
  int64_t backoff_us_ = 0;
  int64_t next_attempt_mono_us_ = 0;
  SourceStats stats_;
};

}  // namespace wingman::camera_driver
