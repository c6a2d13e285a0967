// SPDX-License-Identifier: MIT
// The seam between V4l2Source and the kernel: open/close/ioctl/mmap/munmap/poll with errno results.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace wingman::camera_driver {

/// The system calls V4l2Source makes, so tests can put an in-process fake device behind them.
///
/// Every call returns errno-style results: >= 0 on success, -errno on failure (never sets errno
/// for the caller to read). Implementations retry EINTR themselves.
class V4l2Io {
 public:
  virtual ~V4l2Io() = default;

  /// Opens the device node read-write and non-blocking. Returns a file descriptor >= 0 or -errno
  /// (-ENOENT when the node does not exist, -EACCES without permission, -EBUSY when in use).
  virtual int open(const std::string& path) = 0;
  /// Closes `fd`. Returns 0 or -errno.
  virtual int close(int fd) = 0;
  /// ioctl(fd, request, arg) with a V4L2 request (VIDIOC_*). Returns the ioctl's result or -errno
  /// (-EAGAIN from VIDIOC_DQBUF when no buffer is ready, -ENODEV after an unplug).
  virtual int ioctl(int fd, unsigned long request, void* arg) = 0;
  /// Maps `length` bytes of buffer memory at `offset` (from VIDIOC_QUERYBUF) shared and readable.
  /// Returns 0 and sets `*address`, or -errno.
  virtual int mmap(int fd, size_t length, int64_t offset, void** address) = 0;
  /// Unmaps a mapping made by mmap(). Returns 0 or -errno.
  virtual int munmap(void* address, size_t length) = 0;
  /// Waits up to `timeout_ms` for `fd` to become readable. Returns 1 and sets `*revents`
  /// (POLLIN, POLLERR, POLLHUP...), 0 on timeout, or -errno.
  virtual int poll(int fd, int timeout_ms, short* revents) = 0;
};

/// The real thing: libv4l2 (v4l2_fd_open with format conversion disabled, so the driver's own
/// formats are what we get) over open(2), ioctl(2), mmap(2), poll(2).
class SystemV4l2Io : public V4l2Io {
 public:
  int open(const std::string& path) override;
  int close(int fd) override;
  int ioctl(int fd, unsigned long request, void* arg) override;
  int mmap(int fd, size_t length, int64_t offset, void** address) override;
  int munmap(void* address, size_t length) override;
  int poll(int fd, int timeout_ms, short* revents) override;
};

/// "ENOENT (No such file or directory)" for error number `err` (positive or negative).
std::string errno_name(int err);

/// A V4L2 fourcc as text, e.g. "YUYV", "MJPG", "H264".
std::string fourcc_name(uint32_t fourcc);

}  // namespace wingman::camera_driver
