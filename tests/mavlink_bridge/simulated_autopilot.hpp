// SPDX-License-Identifier: MIT
// A simulated PX4/ArduPilot on a real UDP socket for wingman-mavlink's process tests: HEARTBEAT, attitude and
// position at a rate, TIMESYNC answers with a skewed and drifting clock, COMMAND_ACKs, and a record of the setpoints
// it receives with their arrival times.
#pragma once

#include <wingman/mavlink/enums.hpp>
#include <wingman/mavlink/parser.hpp>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace wingman::mavlink_bridge::test {

namespace mav = wingman::mavlink;

/// Our epoch clock, nanoseconds.
inline int64_t epoch_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

class SimulatedAutopilot {
 public:
  struct Received {
    int64_t epoch_ns;  ///< when it arrived (our clock)
    mav::SetPositionTargetLocalNed target;
  };

  /// Sends to 127.0.0.1:`bridge_port` from an ephemeral port. Its boot was `boot_age_s` seconds ago; its clock runs
  /// `ppm` fast.
  SimulatedAutopilot(int bridge_port, double boot_age_s, double ppm) : ppm_(ppm) {
    fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd_ < 0) throw std::runtime_error("socket");
    sockaddr_in local{};
    local.sin_family = AF_INET;
    local.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&local), sizeof local) != 0) throw std::runtime_error("bind");
    bridge_.sin_family = AF_INET;
    bridge_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    bridge_.sin_port = htons(static_cast<uint16_t>(bridge_port));
    boot_epoch_ns_ = epoch_ns() - static_cast<int64_t>(boot_age_s * 1e9);
  }
  ~SimulatedAutopilot() { ::close(fd_); }

  /// Its clock: nanoseconds since its boot at our epoch time `t_ns`.
  int64_t boot_ns(int64_t t_ns) const {
    return static_cast<int64_t>(static_cast<double>(t_ns - boot_epoch_ns_) * (1.0 + ppm_ * 1e-6));
  }

  /// Our epoch time (ns) at which its clock read `boot_ns`.
  int64_t epoch_ns_of(int64_t boot_ns) const {
    return boot_epoch_ns_ + static_cast<int64_t>(static_cast<double>(boot_ns) / (1.0 + ppm_ * 1e-6));
  }

  /// PX4 (custom mode OFFBOARD or POSCTL) or ArduPilot (GUIDED or LOITER).
  void set_mode(bool px4, bool engaged, bool armed = true) {
    hb_.autopilot = px4 ? mav::kMavAutopilotPx4 : mav::kMavAutopilotArdupilotmega;
    hb_.type = mav::kMavTypeQuadrotor;
    hb_.base_mode =
        static_cast<uint8_t>(mav::kMavModeFlagCustomModeEnabled | (armed ? mav::kMavModeFlagSafetyArmed : 0));
    hb_.custom_mode = px4 ? mav::px4_custom_mode(engaged ? mav::kPx4MainModeOffboard : mav::kPx4MainModePosctl)
                          : (engaged ? mav::kCopterModeGuided : mav::kCopterModeLoiter);
    hb_.system_status = mav::kMavStateActive;
    last_hb_ns_ = 0;  // announce at once
  }
  /// Talks over `fd` (a serial line: a pty master, not owned) instead of UDP from now on; -1: the line is gone.
  void attach_serial(int fd) {
    serial_fd_ = fd;
    serial_ = true;
  }
  void send_raw(const std::vector<uint8_t>& bytes) {
    if (serial_) {
      if (serial_fd_ >= 0) [[maybe_unused]]
        const ssize_t n = ::write(serial_fd_, bytes.data(), bytes.size());
      return;
    }
    ::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&bridge_), sizeof bridge_);
  }
  template <class Msg>
  void send(const Msg& m) {
    send_raw(mav::encode(m, mav::Sender{1, 1, seq_++}));
  }

  /// One step at our time `now_ns`: answer what arrived, send HEARTBEAT (1 Hz), attitude and position (every
  /// `pose_period_ms`; position flying north at 1 m/s from (0, 0, -5), facing east).
  void step(int64_t now_ns, int pose_period_ms = 20) {
    uint8_t buf[2048];
    for (;;) {
      const int from = serial_ ? serial_fd_ : fd_;
      if (from < 0) break;
      const ssize_t n = serial_ ? ::read(from, buf, sizeof buf) : ::recv(from, buf, sizeof buf, 0);
      if (n <= 0) break;
      parser_.feed(buf, static_cast<size_t>(n), [&](const mav::Frame& f) { on_frame(f, now_ns); });
      if (!serial_) parser_.end_of_datagram([&](const mav::Frame& f) { on_frame(f, now_ns); });
    }
    if (!silent && now_ns - last_hb_ns_ >= 1000000000) {
      send(hb_);
      last_hb_ns_ = now_ns;
    }
    if (!silent && now_ns - last_pose_ns_ >= pose_period_ms * 1000000LL) {
      // Measured measurement_delay_ms before it is sent (an estimator's delay): stamping on arrival would be late.
      const uint32_t ms = static_cast<uint32_t>(boot_ns(now_ns - measurement_delay_ms * 1000000LL) / 1000000);
      const double s = ms * 1e-3;
      mav::AttitudeQuaternion a;
      a.time_boot_ms = ms;
      a.q1 = static_cast<float>(std::cos(M_PI / 4));  // yaw +90 deg about NED down: facing east
      a.q4 = static_cast<float>(std::sin(M_PI / 4));
      send(a);
      mav::LocalPositionNed p;
      p.time_boot_ms = ms;
      p.x = static_cast<float>(std::fmod(s, 100.0));
      p.z = -5;
      p.vx = 1;
      send(p);
      last_pose_ns_ = now_ns;
      pose_times_ms.push_back(ms);
    }
  }

  bool silent = false;                     ///< sends nothing of its own (answers still)
  int measurement_delay_ms = 30;           ///< poses are sent this long after their measurement time
  std::vector<Received> setpoints;         ///< SET_POSITION_TARGET_LOCAL_NED received
  std::vector<mav::CommandLong> commands;  ///< COMMAND_LONG received
  std::vector<uint32_t> pose_times_ms;     ///< time_boot_ms of every pose sent
  int heartbeats_from_bridge = 0;
  int timesync_requests = 0;

 private:
  void on_frame(const mav::Frame& f, int64_t now_ns) {
    switch (f.msgid) {
      case mav::Timesync::kId: {
        mav::Timesync t;
        mav::decode(f, t);
        if (t.tc1 != 0) return;
        ++timesync_requests;
        mav::Timesync r;
        r.tc1 = boot_ns(now_ns);
        r.ts1 = t.ts1;
        r.target_system = f.sysid;
        r.target_component = f.compid;
        send(r);
        return;
      }
      case mav::SetPositionTargetLocalNed::kId: {
        Received r{now_ns, {}};
        mav::decode(f, r.target);
        setpoints.push_back(r);
        return;
      }
      case mav::CommandLong::kId: {
        mav::CommandLong c;
        mav::decode(f, c);
        commands.push_back(c);
        mav::CommandAck ack;
        ack.command = c.command;
        ack.result = mav::kMavResultAccepted;
        send(ack);
        return;
      }
      case mav::Heartbeat::kId:
        ++heartbeats_from_bridge;
        return;
      default:
        return;
    }
  }

  int fd_ = -1;
  bool serial_ = false;
  int serial_fd_ = -1;
  sockaddr_in bridge_{};
  int64_t boot_epoch_ns_ = 0;
  double ppm_ = 0;
  mav::Heartbeat hb_;
  mav::Parser parser_;
  uint8_t seq_ = 0;
  int64_t last_hb_ns_ = 0;
  int64_t last_pose_ns_ = 0;
};

}  // namespace wingman::mavlink_bridge::test
