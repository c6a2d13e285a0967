// SPDX-License-Identifier: MIT
// wingman-mavlink's cost from a SETPOINT's bytes to the SET_POSITION_TARGET_LOCAL_NED frame written to UDP, as its
// handler does it: decode and validate the setpoint_t, the stream's rules and clamps, the MAVLink encoding, and the
// write (sendto on loopback), with and without the write side by side. Per-setpoint p50 and p99 as counters.
// Numbers: docs/benchmarks.md. The LCM receive before the handler (kernel, LCM's thread) is not in it; the process
// test MavlinkBridgeProcess.SetpointToLinkLatency measures the whole path.
#include <arpa/inet.h>
#include <benchmark/benchmark.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>
#include <wingman/common/message_validation.hpp>
#include <wingman/mavlink/enums.hpp>
#include <wingman/mavlink/parser.hpp>
#include <wingman/mavlink_bridge/bridge.hpp>
#include <wingman/mavlink_bridge/link.hpp>

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <vector>

namespace {

using namespace wingman;
using namespace wingman::mavlink_bridge;
using Clock = std::chrono::steady_clock;

/// A UDP socket on loopback that receives the bridge's frames (drained outside the timed part).
class Sink {
 public:
  Sink() {
    fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    if (fd_ < 0 || ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
        ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len) != 0)
      throw std::runtime_error("bench_mavlink_bridge: cannot bind a UDP socket on loopback");
    port_ = ntohs(a.sin_port);
  }
  ~Sink() { ::close(fd_); }
  int port() const { return port_; }
  int drain() {
    uint8_t buf[512];
    int n = 0;
    while (::recv(fd_, buf, sizeof buf, 0) > 0) ++n;
    return n;
  }

 private:
  int fd_ = -1;
  int port_ = 0;
};

/// The bridge streaming to a PX4 in OFFBOARD (its HEARTBEAT handled), the follower's setpoint as LCM bytes.
struct Rig {
  BridgeOptions options;
  Bridge bridge{options, nullptr};
  std::vector<uint8_t> bytes;
  int64_t mono_us = 1000000;
  Rig() {
    mavlink::Heartbeat hb;
    hb.autopilot = mavlink::kMavAutopilotPx4;
    hb.type = mavlink::kMavTypeQuadrotor;
    hb.base_mode = mavlink::kMavModeFlagCustomModeEnabled | mavlink::kMavModeFlagSafetyArmed;
    hb.custom_mode = mavlink::px4_custom_mode(mavlink::kPx4MainModeOffboard);
    const auto frame = mavlink::encode(hb, mavlink::Sender{1, 1, 0});
    mavlink::Parser parser;
    BridgeOutput out;
    parser.feed(frame.data(), frame.size(), [&](const mavlink::Frame& f) { bridge.on_frame(f, mono_us, 0, out); });
    bridge.tick(mono_us, 0, out);
    setpoint_t sp{};
    sp.utime = 1767225600000000;
    sp.mode = setpoint_t::MODE_VELOCITY;
    sp.frame = own_pose_t::FRAME_ENU;
    sp.velocity[0] = 1.0;
    sp.velocity[1] = 0.5;
    bytes.resize(static_cast<size_t>(sp.getEncodedSize()));
    sp.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  }
  /// One setpoint 33 ms after the previous one: decoded, validated, streamed. Returns the frames to write.
  BridgeOutput handle() {
    setpoint_t sp;
    if (sp.decode(bytes.data(), 0, static_cast<int>(bytes.size())) < 0) throw std::runtime_error("decode");
    if (!common::validate_message(sp).empty()) throw std::runtime_error("validate");
    mono_us += 33333;
    sp.utime += mono_us;  // the follower's clock advances with ours
    BridgeOutput out;
    bridge.on_setpoint(sp, mono_us, out);
    return out;
  }
};

void report(benchmark::State& state, std::vector<double>& us) {
  std::sort(us.begin(), us.end());
  if (us.empty()) return;
  state.counters["p50_us"] = us[us.size() / 2];
  state.counters["p99_us"] = us[std::min(us.size() - 1, us.size() * 99 / 100)];
}

void BM_SetpointToFrame(benchmark::State& state) {
  Rig rig;
  std::vector<double> us;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    BridgeOutput out = rig.handle();
    const auto t1 = Clock::now();
    if (out.frames.size() != 1) state.SkipWithError("expected one frame per setpoint");
    benchmark::DoNotOptimize(out);
    us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
  }
  report(state, us);
}
BENCHMARK(BM_SetpointToFrame);

void BM_SetpointToUdpWrite(benchmark::State& state) {
  Rig rig;
  Sink sink;
  auto link = make_link("udp://127.0.0.1:" + std::to_string(sink.port()), 0);
  link->open();
  std::vector<double> us;
  int64_t failures = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    BridgeOutput out = rig.handle();
    for (const auto& f : out.frames)
      if (!link->write(f)) ++failures;
    const auto t1 = Clock::now();
    us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    state.PauseTiming();
    sink.drain();
    state.ResumeTiming();
  }
  if (failures > 0) state.SkipWithError("UDP writes failed");
  report(state, us);
}
BENCHMARK(BM_SetpointToUdpWrite);

}  // namespace

BENCHMARK_MAIN();
