// SPDX-License-Identifier: MIT
// The byte link to the autopilot: a serial port (termios) or a UDP socket.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace wingman::mavlink_bridge {

/// A link to the autopilot. Not thread-safe. Every call returns at once (non-blocking descriptors).
class Link {
 public:
  virtual ~Link() = default;
  /// Opens (or reopens) the link. Throws std::runtime_error naming the device or address and the reason.
  virtual void open() = 0;
  virtual void close() = 0;
  virtual bool is_open() const = 0;
  /// Reads what is waiting, at most `size` bytes (one datagram for UDP). Returns the bytes read, 0 when nothing is
  /// waiting, -1 when the link was lost (then it is closed; open() again later).
  virtual long read(uint8_t* data, size_t size) = 0;
  /// Writes one frame. False when it could not be written now (no peer yet, buffer full, link lost).
  virtual bool write(const std::vector<uint8_t>& frame) = 0;
  /// True for UDP: every read() is one whole datagram (frames never span two).
  virtual bool datagrams() const = 0;
  /// The descriptor to poll for reading, -1 when closed.
  virtual int fd() const = 0;
  /// What it is, for logs: "serial /dev/ttyACM0 at 921600 baud", "udp listen :14540".
  virtual std::string describe() const = 0;
};

/// The link named by `url`: "udp://:PORT" (listen on all addresses; frames go to whoever sent the last datagram),
/// "udp://HOST:PORT" (send there from an ephemeral port, take datagrams from anyone), or a serial device path
/// ("/dev/ttyACM0", or "serial:///dev/ttyACM0") at `baud`. Throws std::invalid_argument for a malformed URL or a baud
/// rate termios does not have. Not opened yet.
std::unique_ptr<Link> make_link(const std::string& url, int baud);

}  // namespace wingman::mavlink_bridge
