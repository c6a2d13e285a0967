// SPDX-License-Identifier: MIT
// SystemV4l2Io: libv4l2 and POSIX system calls behind the V4l2Io seam; errno and fourcc names.
#include "wingman/camera_driver/v4l2_io.hpp"

#include <fcntl.h>
#include <libv4l2.h>
#include <poll.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace wingman::camera_driver {

int SystemV4l2Io::open(const std::string& path) {
  int fd;
  do {
    fd = ::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  } while (fd < 0 && errno == EINTR);
  if (fd < 0) return -errno;
  // libv4l2 without conversion: we want the driver's own formats, not a silent CPU conversion.
  const int wrapped = v4l2_fd_open(fd, V4L2_DISABLE_CONVERSION);
  if (wrapped < 0) {
    const int err = errno;
    ::close(fd);
    return -err;
  }
  return wrapped;
}

int SystemV4l2Io::close(int fd) { return v4l2_close(fd) < 0 ? -errno : 0; }

int SystemV4l2Io::ioctl(int fd, unsigned long request, void* arg) {
  int r;
  do {
    r = v4l2_ioctl(fd, request, arg);
  } while (r < 0 && errno == EINTR);
  return r < 0 ? -errno : r;
}

int SystemV4l2Io::mmap(int fd, size_t length, int64_t offset, void** address) {
  void* p = v4l2_mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, static_cast<int64_t>(offset));
  if (p == MAP_FAILED) return -errno;
  *address = p;
  return 0;
}

int SystemV4l2Io::munmap(void* address, size_t length) { return v4l2_munmap(address, length) < 0 ? -errno : 0; }

int SystemV4l2Io::poll(int fd, int timeout_ms, short* revents) {
  pollfd p{};
  p.fd = fd;
  p.events = POLLIN;
  const int r = ::poll(&p, 1, timeout_ms);
  if (r < 0) return errno == EINTR ? 0 : -errno;  // a signal: report a timeout, the caller checks for stop
  *revents = p.revents;
  return r;
}

std::string errno_name(int err) {
  if (err < 0) err = -err;
  struct Name {
    int value;
    const char* name;
  };
  static constexpr Name kNames[] = {
      {EPERM, "EPERM"},   {ENOENT, "ENOENT"},   {EINTR, "EINTR"},         {EIO, "EIO"},
      {ENXIO, "ENXIO"},   {EBADF, "EBADF"},     {EAGAIN, "EAGAIN"},       {ENOMEM, "ENOMEM"},
      {EACCES, "EACCES"}, {EFAULT, "EFAULT"},   {EBUSY, "EBUSY"},         {ENODEV, "ENODEV"},
      {EINVAL, "EINVAL"}, {ENOTTY, "ENOTTY"},   {ENOSPC, "ENOSPC"},       {EPIPE, "EPIPE"},
      {EPROTO, "EPROTO"}, {ENOTDIR, "ENOTDIR"}, {ETIMEDOUT, "ETIMEDOUT"}, {ENOTSUP, "ENOTSUP"},
  };
  const std::string text = std::strerror(err);
  for (const Name& n : kNames) {
    if (n.value == err) return std::string(n.name) + " (" + text + ")";
  }
  return "errno " + std::to_string(err) + " (" + text + ")";
}

std::string fourcc_name(uint32_t fourcc) {
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((fourcc >> (8 * i)) & 0xff);
    s += (c >= 0x20 && c < 0x7f) ? c : '?';
  }
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

}  // namespace wingman::camera_driver
