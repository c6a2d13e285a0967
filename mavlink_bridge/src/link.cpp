// SPDX-License-Identifier: MIT
// Serial (termios, raw, non-blocking) and UDP links.
#include "wingman/mavlink_bridge/link.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace wingman::mavlink_bridge {

namespace {

std::string errno_text() { return std::strerror(errno); }

speed_t baud_constant(int baud) {
  switch (baud) {
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    case 230400:
      return B230400;
    case 460800:
      return B460800;
    case 500000:
      return B500000;
    case 921600:
      return B921600;
    case 1000000:
      return B1000000;
    case 1500000:
      return B1500000;
    case 2000000:
      return B2000000;
    case 3000000:
      return B3000000;
    default:
      throw std::invalid_argument("link.baud = " + std::to_string(baud) + ": not a termios baud rate");
  }
}

/// What both links share: one non-blocking descriptor.
class FdLink : public Link {
 public:
  ~FdLink() override { FdLink::close(); }
  void close() override {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  bool is_open() const override { return fd_ >= 0; }
  int fd() const override { return fd_; }

 protected:
  int fd_ = -1;
};

class SerialLink : public FdLink {
 public:
  SerialLink(std::string path, int baud) : path_(std::move(path)), baud_(baud), speed_(baud_constant(baud)) {}

  void open() override {
    close();
    fd_ = ::open(path_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) throw std::runtime_error("serial " + path_ + ": cannot open: " + errno_text());
    termios tio{};
    if (::tcgetattr(fd_, &tio) != 0) {
      const std::string why = errno_text();
      close();
      throw std::runtime_error("serial " + path_ + ": not a terminal: " + why);
    }
    ::cfmakeraw(&tio);
    tio.c_cflag |= CLOCAL | CREAD;
    tio.c_cflag &= ~CRTSCTS;
    tio.c_cc[VMIN] = 0;
    tio.c_cc[VTIME] = 0;
    ::cfsetispeed(&tio, speed_);
    ::cfsetospeed(&tio, speed_);
    if (::tcsetattr(fd_, TCSANOW, &tio) != 0) {
      const std::string why = errno_text();
      close();
      throw std::runtime_error("serial " + path_ + ": cannot set " + std::to_string(baud_) + " baud raw mode: " + why);
    }
  }
  long read(uint8_t* data, size_t size) override {
    if (fd_ < 0) return -1;
    const ssize_t n = ::read(fd_, data, size);
    if (n > 0) return static_cast<long>(n);
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) return 0;
    close();  // EIO (the device went away, a pty's other side closed) or end of file
    return -1;
  }
  bool write(const std::vector<uint8_t>& frame) override {
    if (fd_ < 0) return false;
    const ssize_t n = ::write(fd_, frame.data(), frame.size());
    if (n == static_cast<ssize_t>(frame.size())) return true;
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) close();
    return false;  // a frame cut short is found as garbage by the other side's parser
  }
  bool datagrams() const override { return false; }
  std::string describe() const override { return "serial " + path_ + " at " + std::to_string(baud_) + " baud"; }

 private:
  std::string path_;
  int baud_;
  speed_t speed_;
};

class UdpLink : public FdLink {
 public:
  UdpLink(std::string host, int port) : host_(std::move(host)), port_(port) {}

  void open() override {
    close();
    fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd_ < 0) throw std::runtime_error(describe() + ": cannot make a socket: " + errno_text());
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    if (host_.empty()) {  // listen on PORT
      addr.sin_addr.s_addr = htonl(INADDR_ANY);
      addr.sin_port = htons(static_cast<uint16_t>(port_));
      if (::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
        const std::string why = errno_text();
        close();
        throw std::runtime_error(describe() + ": cannot bind: " + why);
      }
      have_peer_ = false;
    } else {  // send to HOST:PORT
      addrinfo hints{};
      hints.ai_family = AF_INET;
      hints.ai_socktype = SOCK_DGRAM;
      addrinfo* res = nullptr;
      if (::getaddrinfo(host_.c_str(), std::to_string(port_).c_str(), &hints, &res) != 0 || res == nullptr) {
        close();
        throw std::runtime_error(describe() + ": cannot resolve " + host_);
      }
      std::memcpy(&peer_, res->ai_addr, sizeof peer_);
      ::freeaddrinfo(res);
      have_peer_ = true;
    }
  }
  long read(uint8_t* data, size_t size) override {
    if (fd_ < 0) return -1;
    sockaddr_in from{};
    socklen_t len = sizeof from;
    const ssize_t n = ::recvfrom(fd_, data, size, 0, reinterpret_cast<sockaddr*>(&from), &len);
    if (n >= 0) {
      if (host_.empty()) {  // listening: answer whoever spoke last
        peer_ = from;
        have_peer_ = true;
      }
      return static_cast<long>(n);
    }
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR || errno == ECONNREFUSED) return 0;
    close();
    return -1;
  }
  bool write(const std::vector<uint8_t>& frame) override {
    if (fd_ < 0 || !have_peer_) return false;
    const ssize_t n =
        ::sendto(fd_, frame.data(), frame.size(), 0, reinterpret_cast<const sockaddr*>(&peer_), sizeof peer_);
    return n == static_cast<ssize_t>(frame.size());
  }
  bool datagrams() const override { return true; }
  std::string describe() const override {
    return host_.empty() ? "udp listen :" + std::to_string(port_) : "udp " + host_ + ":" + std::to_string(port_);
  }

 private:
  std::string host_;
  int port_;
  sockaddr_in peer_{};
  bool have_peer_ = false;
};

}  // namespace

std::unique_ptr<Link> make_link(const std::string& url, int baud) {
  const std::string udp = "udp://";
  if (url.rfind(udp, 0) == 0) {
    const std::string rest = url.substr(udp.size());
    const auto colon = rest.rfind(':');
    if (colon == std::string::npos) throw std::invalid_argument("link.url = '" + url + "': expected udp://[HOST]:PORT");
    const std::string host = rest.substr(0, colon);
    char* end = nullptr;
    const long port = std::strtol(rest.c_str() + colon + 1, &end, 10);
    if (*end != '\0' || colon + 1 == rest.size() || port < 1 || port > 65535)
      throw std::invalid_argument("link.url = '" + url + "': the port must be 1..65535");
    return std::make_unique<UdpLink>(host, static_cast<int>(port));
  }
  const std::string serial = "serial://";
  const std::string path = url.rfind(serial, 0) == 0 ? url.substr(serial.size()) : url;
  if (path.empty() || path[0] != '/')
    throw std::invalid_argument("link.url = '" + url + "': expected udp://[HOST]:PORT or a serial device path");
  return std::make_unique<SerialLink>(path, baud);
}

}  // namespace wingman::mavlink_bridge
