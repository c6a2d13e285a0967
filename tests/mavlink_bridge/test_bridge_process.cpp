// SPDX-License-Identifier: MIT
// wingman-mavlink as a process against a simulated autopilot on a real UDP socket on loopback and real LCM, in a
// private network namespace: own poses stamped through TIMESYNC with a skewed, drifting autopilot clock; the
// setpoint stream's mode gating, rate, hover and stop; bad input counted and survived.
#include "simulated_autopilot.hpp"
#include "test_support.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <pty.h>
#include <lcm/lcm-cpp.hpp>
#include <wingman/own_pose_t.hpp>
#include <wingman/setpoint_t.hpp>
#include <wingman/status_t.hpp>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>

namespace {

using namespace std::chrono_literals;
using namespace wingman::mavlink_bridge::test;
using wingman::own_pose_t;
using wingman::setpoint_t;
using wingman::status_t;

constexpr int kBridgePort = 14540;

/// The bridge process with its config, an LCM client, and the simulated autopilot, stepped together.
class BridgeRig {
 public:
  /// `link_yaml`: the link section ("" = listen on UDP kBridgePort).
  explicit BridgeRig(const std::string& extra_yaml = "", double boot_age_s = 1234.5, double ppm = 200,
                     const std::string& link_yaml = "")
      : autopilot(kBridgePort, boot_age_s, ppm), lcm_(wingman::testing::netns_lcm_url()) {
    if (!lcm_.good()) throw std::runtime_error("LCM not good");
    std::ofstream(dir_.file("bridge.yaml"))
        << (link_yaml.empty() ? "link: {url: 'udp://:" + std::to_string(kBridgePort) + "'}\n" : link_yaml)
        << extra_yaml;
    lcm_.subscribe("OWN_POSE", &BridgeRig::on_pose, this);
    lcm_.subscribe("STATUS_MAVLINK_BRIDGE", &BridgeRig::on_status, this);
    child_ = std::make_unique<wingman::testing::Child>(
        std::vector<std::string>{wingman::testing::bin_path("wingman-mavlink"), "--config", dir_.file("bridge.yaml")});
  }
  ~BridgeRig() {
    if (child_ && child_->running()) child_->signal(SIGTERM);
    if (child_) child_->wait(3s);
  }

  /// Steps the autopilot and handles LCM for `duration`; calls `each(now_ns)` every millisecond or so.
  void run_for(std::chrono::milliseconds duration, const std::function<void(int64_t)>& each = nullptr) {
    const int64_t end = epoch_ns() + duration.count() * 1000000LL;
    for (int64_t now = epoch_ns(); now < end; now = epoch_ns()) {
      autopilot.step(now);
      if (each) each(now);
      lcm_.handleTimeout(1);
    }
  }
  /// run_for() until `done` holds (checked after every step) or `at_most` has passed; returns whether it held.
  bool run_until(const std::function<bool()>& done, std::chrono::milliseconds at_most,
                 const std::function<void(int64_t)>& each = nullptr) {
    const int64_t end = epoch_ns() + at_most.count() * 1000000LL;
    for (int64_t now = epoch_ns(); now < end; now = epoch_ns()) {
      autopilot.step(now);
      if (each) each(now);
      lcm_.handleTimeout(1);
      if (done()) return true;
    }
    return done();
  }
  void publish(const setpoint_t& sp) { lcm_.publish("SETPOINT", &sp); }
  int stop() {
    child_->signal(SIGTERM);
    return child_->wait(5s);
  }
  std::string err() const { return child_->err(); }

  SimulatedAutopilot autopilot;
  std::vector<own_pose_t> poses;
  std::vector<status_t> statuses;

 private:
  void on_pose(const lcm::ReceiveBuffer*, const std::string&, const own_pose_t* p) { poses.push_back(*p); }
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const status_t* s) { statuses.push_back(*s); }
  wingman::testing::TempDir dir_;
  lcm::LCM lcm_;
  std::unique_ptr<wingman::testing::Child> child_;
};

setpoint_t velocity_east(int64_t utime, double speed) {
  setpoint_t sp{};
  sp.utime = utime;
  sp.mode = setpoint_t::MODE_VELOCITY;
  sp.frame = own_pose_t::FRAME_ENU;
  sp.velocity[0] = speed;
  return sp;
}

bool zero_velocity(const wingman::mavlink::SetPositionTargetLocalNed& t) {
  return t.vx == 0 && t.vy == 0 && t.vz == 0 && t.yaw_rate == 0;
}

const wingman::channel_stats_t* channel(const status_t& s, const std::string& name) {
  for (const auto& c : s.channels)
    if (c.channel == name) return &c;
  return nullptr;
}

}  // namespace

TEST(MavlinkBridgeProcess, OwnPosesCarryTheAutopilotsMeasurementTimeThroughTimesync) {
  // The autopilot booted 1234.5 s ago and its clock runs 200 ppm fast.
  BridgeRig rig("", 1234.5, 200);
  rig.autopilot.set_mode(/*px4=*/true, /*engaged=*/false);
  rig.run_for(4000ms);
  ASSERT_GT(rig.poses.size(), 100u) << rig.err();
  EXPECT_GT(rig.autopilot.timesync_requests, 4);
  EXPECT_GT(rig.autopilot.heartbeats_from_bridge, 2);
  // Every pose's utime is the epoch time at which the autopilot's clock read its time_boot_ms (ms resolution, plus
  // the offset's error: half the asymmetry of loopback round trips of a few ms).
  double worst_us = 0;
  for (const auto& p : rig.poses) {
    const double north = p.p_body_in_world[1];
    // The pose was sent with time_boot_ms = ms and x (north) = fmod(ms / 1000, 100): find its ms back from it.
    const int64_t ms = static_cast<int64_t>(std::llround(north * 1000.0));
    const int64_t expect_us =
        rig.autopilot.epoch_ns_of((ms + (rig.autopilot.pose_times_ms.front() / 100000) * 100000) * 1000000LL) / 1000;
    worst_us = std::max(worst_us, std::abs(static_cast<double>(p.utime - expect_us)));
    EXPECT_EQ(p.frame, int8_t{own_pose_t::FRAME_ENU});
    EXPECT_NEAR(p.p_body_in_world[0], 0.0, 1e-6);  // east
    EXPECT_NEAR(p.p_body_in_world[2], 5.0, 1e-6);  // up
    EXPECT_NEAR(p.v_body_in_world[1], 1.0, 1e-6);  // flying north
  }
  // The autopilot sends each pose 30 ms after measuring it: stamping on arrival would be 30 ms late.
  std::printf("own pose utime against the autopilot's measurement time: worst %.0f us over %zu poses\n", worst_us,
              rig.poses.size());
  EXPECT_LT(worst_us, 5000.0) << "own pose time against the autopilot's measurement time";
  ASSERT_FALSE(rig.statuses.empty());
  // OK but for the follower's missing setpoints (no follower runs here).
  const status_t& last = rig.statuses.back();
  EXPECT_NE(last.state, int8_t{status_t::STATE_ERROR}) << last.detail;
  EXPECT_EQ(last.detail.find("stale input: no message yet on MAVLINK"), std::string::npos) << last.detail;
  EXPECT_NE(last.detail.find("px4 POSCTL armed"), std::string::npos) << last.detail;
  EXPECT_NE(last.detail.find("time offset"), std::string::npos) << last.detail;
  // It asked for the message rates it needs.
  int interval_requests = 0;
  for (const auto& c : rig.autopilot.commands)
    interval_requests += c.command == wingman::mavlink::kMavCmdSetMessageInterval;
  EXPECT_EQ(interval_requests, 2) << "ATTITUDE_QUATERNION and LOCAL_POSITION_NED, each acknowledged once";
  EXPECT_EQ(rig.stop(), 0);
}

TEST(MavlinkBridgeProcess, StreamsOnlyInOffboardSteadilyThenHoversAndStopsWhenTheFollowerStops) {
  BridgeRig rig("stream: {rate_hz: 20, setpoint_timeout_s: 0.5, hover_s: 1.0}\n");
  rig.autopilot.set_mode(true, false);
  int64_t last_sp_ns = 0;
  auto follower = [&](int64_t now) {  // SETPOINT at 10 Hz, stamped with the newest own pose's time
    if (now - last_sp_ns < 100000000 || rig.poses.empty()) return;
    rig.publish(velocity_east(rig.poses.back().utime, 1.0));
    last_sp_ns = now;
  };
  rig.run_for(2000ms, follower);
  // POSCTL: only zero velocity (PX4 needs a stream before OFFBOARD can be engaged), never the follower's.
  ASSERT_FALSE(rig.autopilot.setpoints.empty()) << rig.err();
  for (const auto& r : rig.autopilot.setpoints) ASSERT_TRUE(zero_velocity(r.target));
  // The pilot engages OFFBOARD.
  rig.autopilot.set_mode(true, true);
  const size_t before = rig.autopilot.setpoints.size();
  rig.run_for(2000ms, follower);
  std::vector<SimulatedAutopilot::Received> engaged(rig.autopilot.setpoints.begin() + static_cast<long>(before),
                                                    rig.autopilot.setpoints.end());
  ASSERT_GT(engaged.size(), 20u);
  int followed = 0;
  int64_t worst_gap_ns = 0;
  for (size_t i = 1; i < engaged.size(); ++i) {
    worst_gap_ns = std::max(worst_gap_ns, engaged[i].epoch_ns - engaged[i - 1].epoch_ns);
    if (engaged[i].target.vy > 0.99f) ++followed;  // east 1 m/s
  }
  EXPECT_GT(followed, 20);
  EXPECT_LT(worst_gap_ns, 200000000) << "the stream keeps its 20 Hz (autopilots drop offboard below 2 Hz)";
  // The follower stops publishing: 0.5 s later a hover of 1 s, then nothing.
  const int64_t stopped_ns = epoch_ns();
  const size_t at_stop = rig.autopilot.setpoints.size();
  rig.run_for(3500ms);
  int hover = 0;
  int64_t last_ns = 0;
  for (size_t i = at_stop; i < rig.autopilot.setpoints.size(); ++i) {
    const auto& r = rig.autopilot.setpoints[i];
    if (zero_velocity(r.target)) ++hover;
    last_ns = r.epoch_ns;
  }
  EXPECT_GE(hover, 15);
  EXPECT_LT(last_ns - stopped_ns, 2000000000) << "nothing after the hover (0.5 s timeout + 1 s hover + margin)";
  const status_t& last = rig.statuses.back();
  EXPECT_NE(last.detail.find("stream stopped"), std::string::npos) << last.detail;
  EXPECT_NE(last.detail.find("setpoint_stream_stopped 1"), std::string::npos) << last.detail;
  EXPECT_EQ(rig.stop(), 0);
}

TEST(MavlinkBridgeProcess, NeverSwitchesModeOrArmsUnlessAllowedAndStreamsOnlyInGuided) {
  BridgeRig rig;
  rig.autopilot.set_mode(/*px4=*/false, /*engaged=*/false, /*armed=*/false);
  int64_t last_sp_ns = 0;
  auto follower = [&](int64_t now) {
    if (now - last_sp_ns < 100000000 || rig.poses.empty()) return;
    rig.publish(velocity_east(rig.poses.back().utime, 1.0));
    last_sp_ns = now;
  };
  rig.run_for(2000ms, follower);
  // The refusals are counted when the setpoints arrive (about 1 s in); the heartbeat that reports them may come up to
  // one status period later: wait for it (at most 3 s more) instead of reading a heartbeat from before them.
  const char* refusals[] = {"setpoint_not_engaged", "mode_switch_not_allowed", "arm_not_allowed"};
  const auto reported = [&] {
    if (rig.statuses.empty()) return false;
    const std::string& d = rig.statuses.back().detail;
    return std::all_of(std::begin(refusals), std::end(refusals),
                       [&](const char* r) { return d.find(r) != std::string::npos; });
  };
  rig.run_until(reported, 3000ms, follower);
  EXPECT_TRUE(rig.autopilot.setpoints.empty()) << "ArduPilot in LOITER: nothing streamed";
  for (const auto& c : rig.autopilot.commands) {
    EXPECT_NE(c.command, wingman::mavlink::kMavCmdDoSetMode);
    EXPECT_NE(c.command, wingman::mavlink::kMavCmdComponentArmDisarm);
  }
  const std::string detail = rig.statuses.back().detail;
  for (const char* r : refusals) EXPECT_NE(detail.find(r), std::string::npos) << r << " in " << detail;
  rig.autopilot.set_mode(false, true, true);
  rig.run_for(1000ms, follower);
  ASSERT_FALSE(rig.autopilot.setpoints.empty());
  EXPECT_NEAR(rig.autopilot.setpoints.back().target.vy, 1.0f, 1e-6);
  EXPECT_EQ(rig.stop(), 0);
}

TEST(MavlinkBridgeProcess, SetpointToLinkLatency) {
  // From publishing a SETPOINT on LCM to the simulated autopilot receiving its SET_POSITION_TARGET_LOCAL_NED over UDP:
  // LCM multicast on loopback, the bridge, UDP on loopback. Each setpoint carries its own speed to be matched.
  BridgeRig rig;
  rig.autopilot.set_mode(true, true);
  rig.run_for(1500ms);  // time sync and own poses first
  ASSERT_FALSE(rig.poses.empty()) << rig.err();
  std::map<int, int64_t> published_ns;  // speed in mm/s -> when it was published
  int k = 0;
  int64_t last_ns = 0;
  rig.run_for(4000ms, [&](int64_t now) {
    if (now - last_ns < 20000000 || k >= 150) return;  // 50 Hz, 150 setpoints
    ++k;
    published_ns[k] = epoch_ns();
    rig.publish(velocity_east(rig.poses.back().utime, k * 1e-3));
    last_ns = now;
  });
  std::vector<double> latency_ms;
  std::map<int, bool> seen;
  for (const auto& r : rig.autopilot.setpoints) {
    const int mm = static_cast<int>(std::lround(r.target.vy * 1000.0));
    auto it = published_ns.find(mm);
    if (it == published_ns.end() || seen[mm]) continue;  // the stream repeats a setpoint: its first arrival counts
    seen[mm] = true;
    latency_ms.push_back((r.epoch_ns - it->second) * 1e-6);
  }
  ASSERT_GT(latency_ms.size(), 140u);
  std::sort(latency_ms.begin(), latency_ms.end());
  const double p50 = latency_ms[latency_ms.size() / 2];
  const double p99 = latency_ms[static_cast<size_t>(0.99 * static_cast<double>(latency_ms.size() - 1))];
  std::printf(
      "SETPOINT -> SET_POSITION_TARGET_LOCAL_NED at the autopilot: %zu setpoints, p50 %.3f ms, p99 %.3f ms, "
      "max %.3f ms\n",
      latency_ms.size(), p50, p99, latency_ms.back());
  // The bridge's own share: its status latency is the SETPOINT handler's run time, the frame's UDP write included.
  const status_t& st = rig.statuses.back();
  std::printf("bridge SETPOINT handler incl. the UDP write (status, last 256): p50 %.3f ms, p99 %.3f ms, max %.3f ms\n",
              st.latency_p50_ms, st.latency_p99_ms, st.latency_max_ms);
  // The target is 2 ms p99 for the bridge alone; this measures LCM + bridge + UDP on a shared 2-core machine
  // and its bound is loose so a loaded CI machine passes; the figures are printed.
  EXPECT_LT(p99, 20.0);
  EXPECT_EQ(rig.stop(), 0);
}

TEST(MavlinkBridgeProcess, ASerialLineThatDisappearsAndComesBackIsReopened) {
  // The autopilot on a serial line: a pty pair whose slave the bridge opens through a device link, as udev's
  // /dev/serial/by-id names are; the line goes away (a USB autopilot rebooting) and comes back behind the same name.
  wingman::testing::TempDir dir;
  const std::string device = dir.file("ttyAUTOPILOT");
  auto open_line = [&](int* master) {
    int slave = -1;
    char name[256];
    if (::openpty(master, &slave, name, nullptr, nullptr) != 0) throw std::runtime_error("openpty failed");
    ::close(slave);
    ::fcntl(*master, F_SETFL, ::fcntl(*master, F_GETFL) | O_NONBLOCK);
    ::fcntl(*master, F_SETFD, FD_CLOEXEC);  // the bridge, started from this process, must not hold the line open
    std::filesystem::remove(device);
    std::filesystem::create_symlink(name, device);
  };
  int master = -1;
  open_line(&master);
  BridgeRig rig("", 1234.5, 200, "link: {url: '" + device + "', baud: 921600, reopen_period_s: 0.2}\n");
  rig.autopilot.attach_serial(master);
  rig.autopilot.set_mode(true, false);
  rig.run_for(2000ms);
  const size_t first = rig.poses.size();
  ASSERT_GT(first, 20u) << rig.err();
  // The line disappears for a second.
  ::close(master);
  rig.autopilot.attach_serial(-1);
  std::filesystem::remove(device);
  rig.run_for(1000ms);
  const size_t during = rig.poses.size();
  EXPECT_LT(during - first, 10u) << "no poses while the line is gone";
  // It comes back under the same name.
  open_line(&master);
  rig.autopilot.attach_serial(master);
  rig.autopilot.set_mode(true, false);
  rig.run_for(2500ms);
  EXPECT_GT(rig.poses.size(), during + 20) << "own poses again after the bridge reopened the line; " << rig.err();
  const status_t& last = rig.statuses.back();
  const auto* link = channel(last, "MAVLINK");
  ASSERT_NE(link, nullptr);
  EXPECT_GE(link->drops, 1) << "the lost line is counted; " << last.detail;
  EXPECT_EQ(rig.stop(), 0);
  EXPECT_NE(rig.err().find("link lost"), std::string::npos) << rig.err();
  ::close(master);
}

TEST(MavlinkBridgeProcess, BadInputIsCountedAndSurvived) {
  BridgeRig rig;
  rig.autopilot.set_mode(true, false);
  rig.run_for(1500ms);
  const size_t poses_before = rig.poses.size();
  ASSERT_GT(poses_before, 20u) << rig.err();
  namespace mav = wingman::mavlink;
  // Garbage, a bad checksum, a frame cut off by its datagram's end, a signed frame, an unknown message.
  rig.autopilot.send_raw({0x00, 0x11, 0xFD, 0x22, 0xFE, 0x33});
  mav::Heartbeat hb;
  auto bad = mav::encode(hb, mav::Sender{1, 1, 0});
  bad[11] ^= 0xFF;
  rig.autopilot.send_raw(bad);
  auto cut = mav::encode(hb, mav::Sender{1, 1, 0});
  cut.resize(cut.size() - 4);
  rig.autopilot.send_raw(cut);
  auto signed_frame = mav::encode(hb, mav::Sender{1, 1, 0});
  signed_frame[2] = mav::kIncompatFlagSigned;  // (checksum now wrong as well: dropped either way)
  rig.autopilot.send_raw(signed_frame);
  rig.autopilot.send_raw({0xFD, 2, 0, 0, 0, 1, 1, 0x99, 0x99, 0x00, 1, 2, 0x12, 0x34});
  // A flood: 20000 attitude frames as fast as the socket takes them.
  mav::AttitudeQuaternion att;
  att.time_boot_ms = 1;
  for (int i = 0; i < 20000; ++i) rig.autopilot.send(att);
  rig.run_for(2500ms);
  EXPECT_GT(rig.poses.size(), poses_before + 50) << "own poses go on after the bad input";
  const status_t& last = rig.statuses.back();
  const auto* link = channel(last, "MAVLINK");
  ASSERT_NE(link, nullptr);
  EXPECT_GE(link->drops, 2) << "bad checksum and cut-off frame at least; " << last.detail;
  EXPECT_NE(last.detail.find("bad crc"), std::string::npos);
  EXPECT_EQ(last.detail.find("on MAVLINK"), std::string::npos) << "the link is not stale: " << last.detail;
  EXPECT_EQ(rig.stop(), 0);
}
