// SPDX-License-Identifier: MIT
// Bridge without I/O: mode and arm requests only where allowed, at most once a second, and refusals counted once
// per setpoint.
#include <wingman/mavlink/enums.hpp>
#include <wingman/mavlink/parser.hpp>
#include <wingman/mavlink_bridge/bridge.hpp>

#include "test_constants.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace wingman::mavlink_bridge;
namespace mav = wingman::mavlink;

namespace {

using wingman::testing::kMs;

/// The frame of an autopilot message, as the parser hands it on.
template <class Msg>
mav::Frame frame_of(const Msg& m) {
  const auto bytes = mav::encode(m, mav::Sender{1, 1, 0});
  mav::Frame out;
  mav::Parser p;
  p.feed(bytes.data(), bytes.size(), [&](const mav::Frame& f) { out = f; });
  return out;
}

/// COMMAND_LONGs among `frames`.
std::vector<mav::CommandLong> commands(const std::vector<std::vector<uint8_t>>& frames) {
  std::vector<mav::CommandLong> out;
  mav::Parser p;
  for (const auto& f : frames)
    p.feed(f.data(), f.size(), [&](const mav::Frame& fr) {
      mav::CommandLong c;
      if (mav::decode(fr, c)) out.push_back(c);
    });
  return out;
}

/// Runs 3 s: an ArduPilot in LOITER, disarmed; setpoints every 100 ms. Returns the commands the bridge sent.
std::vector<mav::CommandLong> fly(Bridge& bridge) {
  mav::Heartbeat hb;
  hb.autopilot = mav::kMavAutopilotArdupilotmega;
  hb.base_mode = mav::kMavModeFlagCustomModeEnabled;
  hb.custom_mode = mav::kCopterModeLoiter;
  BridgeOutput out;
  wingman::setpoint_t sp{};
  sp.mode = wingman::setpoint_t::MODE_VELOCITY;
  sp.velocity[0] = 1;
  for (int64_t t = 0; t < 3000; t += 5) {
    if (t % 1000 == 0) bridge.on_frame(frame_of(hb), t * kMs, 0, out);
    if (t % 100 == 0) bridge.on_setpoint(sp, t * kMs, out);
    bridge.tick(t * kMs, 0, out);
  }
  return commands(out.frames);
}

}  // namespace

TEST(Bridge, NeverRequestsModeOrArmingUnlessAllowedAndCountsEachSetpointOnce) {
  Bridge bridge(BridgeOptions{}, nullptr);
  for (const auto& c : fly(bridge)) {
    EXPECT_NE(c.command, mav::kMavCmdDoSetMode);
    EXPECT_NE(c.command, mav::kMavCmdComponentArmDisarm);
  }
  // 30 setpoints: each refused once for the mode, once for arming and once for not being engaged.
  EXPECT_EQ(bridge.refusals().count_of("mode_switch_not_allowed"), 30);
  EXPECT_EQ(bridge.refusals().count_of("arm_not_allowed"), 30);
  EXPECT_EQ(bridge.streamer().refusals().count_of("setpoint_not_engaged"), 30);
}

TEST(Bridge, WhenAllowedRequestsGuidedAndArmingAtMostOnceASecond) {
  BridgeOptions o;
  o.allow_mode_switch = true;
  o.allow_arm = true;
  Bridge bridge(o, nullptr);
  int mode = 0, arm = 0;
  for (const auto& c : fly(bridge)) {
    if (c.command == mav::kMavCmdDoSetMode) {
      ++mode;
      EXPECT_FLOAT_EQ(c.param1, mav::kMavModeFlagCustomModeEnabled);
      EXPECT_FLOAT_EQ(c.param2, static_cast<float>(mav::kCopterModeGuided));
    }
    if (c.command == mav::kMavCmdComponentArmDisarm) {
      ++arm;
      EXPECT_FLOAT_EQ(c.param1, 1.0f);
    }
  }
  EXPECT_GE(mode, 2);
  EXPECT_LE(mode, 3) << "at most once a second over 3 s";
  EXPECT_GE(arm, 2);
  EXPECT_LE(arm, 3);
}

TEST(Bridge, OdometryCovarianceAndTheAutopilotsUnixClockAreReported) {
  Bridge bridge(BridgeOptions{}, nullptr);
  BridgeOutput out;
  mav::Heartbeat hb;
  hb.autopilot = mav::kMavAutopilotPx4;
  bridge.on_frame(frame_of(hb), 0, 0, out);
  const int64_t wall_ns = 1796428800LL * 1000000000LL;
  mav::SystemTime st;
  st.time_unix_usec = static_cast<uint64_t>(wall_ns / 1000 + 2500000);  // 2.5 s ahead of ours
  bridge.on_frame(frame_of(st), 0, wall_ns, out);
  EXPECT_NEAR(bridge.autopilot_unix_minus_ours_s(), 2.5, 1e-6);
  mav::Odometry o;
  o.time_usec = 2000000000000000;  // Unix time: stamped as it is, no TIMESYNC needed
  o.frame_id = mav::kMavFrameLocalNed;
  o.child_frame_id = mav::kMavFrameBodyFrd;
  o.pose_covariance[0] = o.pose_covariance[6] = o.pose_covariance[11] = 0.01f;
  bridge.on_frame(frame_of(o), 0, wall_ns, out);
  ASSERT_EQ(out.poses.size(), 1u);
  EXPECT_EQ(out.poses[0].utime, 2000000000000000);
  EXPECT_NEAR(bridge.position_std_m(), 0.1, 1e-6);
  EXPECT_NE(bridge.detail().find("position std 0.100 m"), std::string::npos) << bridge.detail();
  EXPECT_NE(bridge.detail().find("autopilot Unix clock +2.500 s from ours"), std::string::npos) << bridge.detail();
}

TEST(Bridge, APoseBeforeTheClockIsKnownIsHeldAndPublishedWithItsOwnTimeOnceASampleIsUsed) {
  Bridge bridge(BridgeOptions{}, nullptr);
  BridgeOutput out;
  mav::Heartbeat hb;
  hb.autopilot = mav::kMavAutopilotPx4;
  bridge.on_frame(frame_of(hb), 0, 0, out);
  const int64_t wall0_ns = 1796428800LL * 1000000000LL;
  auto timesync_requests = [](const BridgeOutput& o) {
    std::vector<int64_t> ts1;
    mav::Parser p;
    for (const auto& f : o.frames)
      p.feed(f.data(), f.size(), [&](const mav::Frame& fr) {
        mav::Timesync t;
        if (mav::decode(fr, t) && t.tc1 == 0) ts1.push_back(t.ts1);
      });
    return ts1;
  };
  // While no sample is used, requests every 100 ms (not time.timesync_period_s, 0.5 s).
  for (int64_t t = 0; t <= 300; t += 10) bridge.tick(t * kMs, wall0_ns + t * 1000000, out);
  EXPECT_EQ(timesync_requests(out).size(), 4u) << "at 0, 100, 200 and 300 ms";

  // A pose measured at 5 s of the autopilot's boot clock, before any TIMESYNC answer: held, not published.
  mav::Odometry o;
  o.time_usec = 5000000;
  o.frame_id = mav::kMavFrameLocalNed;
  o.child_frame_id = mav::kMavFrameBodyFrd;
  o.x = 1;
  o.q = {1, 0, 0, 0};
  o.pose_covariance[0] = NAN;
  o.velocity_covariance[0] = NAN;
  bridge.on_frame(frame_of(o), 300 * kMs, wall0_ns + 300000000, out);
  EXPECT_TRUE(out.poses.empty());
  EXPECT_EQ(bridge.refusals().count_of("pose_before_timesync"), 1);

  // The autopilot's boot is at wall0 - 10 s: its clock reads 10.3 s when asked at wall0 + 300 ms.
  const int64_t boot_offset_ns = 10LL * 1000000000LL;
  mav::Timesync late;  // answered 80 ms later: longer than time.timesync_max_rtt_s (50 ms), not used
  late.ts1 = wall0_ns + 300000000;
  late.tc1 = late.ts1 + 40000000 - wall0_ns + boot_offset_ns;
  bridge.on_frame(frame_of(late), 380 * kMs, wall0_ns + 380000000, out);
  EXPECT_TRUE(out.poses.empty());
  EXPECT_FALSE(bridge.time_sync().synced());
  mav::Timesync good;  // a 2 ms round trip
  good.ts1 = wall0_ns + 400000000;
  good.tc1 = good.ts1 + 1000000 - wall0_ns + boot_offset_ns;
  bridge.on_frame(frame_of(good), 402 * kMs, wall0_ns + 402000000, out);
  ASSERT_EQ(out.poses.size(), 1u) << "the held pose, once the clock is known";
  EXPECT_EQ(out.poses[0].utime, wall0_ns / 1000 - 10000000 + 5000000) << "its measurement time, on our clock";
  EXPECT_EQ(bridge.poses_published(), 1);

  // A second answer publishes nothing more; synced, the requests go at time.timesync_period_s.
  bridge.on_frame(frame_of(good), 403 * kMs, wall0_ns + 403000000, out);
  EXPECT_EQ(out.poses.size(), 1u);
  out.frames.clear();
  for (int64_t t = 410; t <= 1400; t += 10) bridge.tick(t * kMs, wall0_ns + t * 1000000, out);
  EXPECT_EQ(timesync_requests(out).size(), 2u) << "at 0.8 and 1.3 s";
}
