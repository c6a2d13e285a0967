// SPDX-License-Identifier: MIT
// The serial link on a pseudo-terminal pair (the autopilot's side is the pty master): frames both ways, and a line
// that disappears (the master closes) and comes back (a new pty behind the same device path, as udev's
// /dev/serial/by-id links do).
#include "test_support.hpp"

#include <wingman/mavlink/enums.hpp>
#include <wingman/mavlink/parser.hpp>
#include <wingman/mavlink_bridge/link.hpp>

#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>

using namespace wingman::mavlink_bridge;
namespace mav = wingman::mavlink;

namespace {

/// A pty pair; the slave's path is linked from `link_path`.
struct Pty {
  int master = -1;
  std::string slave_path;
  explicit Pty(const std::string& link_path) {
    int slave = -1;
    char name[256];
    if (::openpty(&master, &slave, name, nullptr, nullptr) != 0) throw std::runtime_error("openpty failed");
    ::close(slave);  // the link opens it by path
    slave_path = name;
    std::filesystem::remove(link_path);
    std::filesystem::create_symlink(slave_path, link_path);
  }
  ~Pty() {
    if (master >= 0) ::close(master);
  }
};

/// Reads from `link` into `parser` until `frames` frames arrived or 2 s passed.
int read_frames(Link& link, mav::Parser& parser, int frames) {
  int n = 0;
  uint8_t buf[512];
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (n < frames && std::chrono::steady_clock::now() < until) {
    pollfd p{link.fd(), POLLIN, 0};
    ::poll(&p, 1, 20);
    const long got = link.read(buf, sizeof buf);
    if (got < 0) return -1;
    parser.feed(buf, static_cast<size_t>(got), [&](const mav::Frame&) { ++n; });
  }
  return n;
}

std::vector<uint8_t> heartbeat(uint8_t seq) {
  mav::Heartbeat hb;
  hb.autopilot = mav::kMavAutopilotPx4;
  return mav::encode(hb, mav::Sender{1, 1, seq});
}

}  // namespace

TEST(SerialLink, FramesBothWaysThenTheLineDisappearsAndComesBack) {
  wingman::testing::TempDir dir;
  const std::string device = dir.file("ttyAUTOPILOT");
  auto pty = std::make_unique<Pty>(device);
  auto link = make_link(device, 921600);
  EXPECT_FALSE(link->datagrams());
  link->open();
  mav::Parser parser;
  // Autopilot -> us, in two pieces.
  const auto f = heartbeat(1);
  ASSERT_EQ(::write(pty->master, f.data(), 5), 5);
  ASSERT_EQ(::write(pty->master, f.data() + 5, f.size() - 5), static_cast<ssize_t>(f.size() - 5));
  EXPECT_EQ(read_frames(*link, parser, 1), 1);
  // Us -> autopilot.
  ASSERT_TRUE(link->write(heartbeat(2)));
  uint8_t buf[64];
  pollfd p{pty->master, POLLIN, 0};
  ASSERT_EQ(::poll(&p, 1, 2000), 1);
  EXPECT_EQ(::read(pty->master, buf, sizeof buf), static_cast<ssize_t>(heartbeat(2).size()));
  // The line disappears: the link reports it lost and closes.
  pty.reset();
  uint8_t b[16];
  long r = 0;
  for (int i = 0; i < 100 && (r = link->read(b, sizeof b)) == 0; ++i) ::usleep(10000);
  EXPECT_EQ(r, -1);
  EXPECT_FALSE(link->is_open());
  std::filesystem::remove(device);
  EXPECT_THROW(link->open(), std::runtime_error);
  // It comes back under the same path.
  pty = std::make_unique<Pty>(device);
  link->open();
  parser.end_of_datagram([](const mav::Frame&) {});
  const auto g = heartbeat(3);
  ASSERT_EQ(::write(pty->master, g.data(), g.size()), static_cast<ssize_t>(g.size()));
  EXPECT_EQ(read_frames(*link, parser, 1), 1);
  EXPECT_EQ(parser.stats().frames, 2);
}

TEST(UdpLink, MalformedUrlsAreRefused) {
  EXPECT_THROW(make_link("udp://nohost", 0), std::invalid_argument);
  EXPECT_THROW(make_link("udp://:0", 0), std::invalid_argument);
  EXPECT_THROW(make_link("ttyACM0", 115200), std::invalid_argument);
  EXPECT_TRUE(make_link("udp://:14540", 0)->datagrams());
  EXPECT_EQ(make_link("serial:///dev/ttyACM0", 57600)->describe(), "serial /dev/ttyACM0 at 57600 baud");
}
