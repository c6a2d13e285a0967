// SPDX-License-Identifier: MIT
// The setpoint stream's safety rules: mode gating, the PX4 ready stream, hover then stop, re-engaging, clamps, rate.
#include <wingman/geometry/ned_enu.hpp>
#include <wingman/mavlink/enums.hpp>
#include <wingman/mavlink_bridge/offboard_streamer.hpp>
#include <wingman/own_pose_t.hpp>

#include "test_constants.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace wingman::mavlink_bridge;
using wingman::setpoint_t;
namespace mav = wingman::mavlink;

namespace {

using wingman::testing::kMs;

AutopilotState px4(bool offboard, bool armed = true) {
  AutopilotState s;
  s.known = true;
  s.kind = AutopilotKind::kPx4;
  s.custom_mode = mav::px4_custom_mode(offboard ? mav::kPx4MainModeOffboard : mav::kPx4MainModePosctl);
  s.armed = armed;
  s.engaged = offboard;
  return s;
}

AutopilotState ardupilot(bool guided) {
  AutopilotState s;
  s.known = true;
  s.kind = AutopilotKind::kArdupilot;
  s.custom_mode = guided ? mav::kCopterModeGuided : mav::kCopterModeLoiter;
  s.armed = true;
  s.engaged = guided;
  return s;
}

setpoint_t velocity(double ve, double vn, double vu, double yaw_rate = 0, int64_t utime = 1000000) {
  setpoint_t sp{};
  sp.utime = utime;
  sp.mode = setpoint_t::MODE_VELOCITY;
  sp.frame = wingman::own_pose_t::FRAME_ENU;
  sp.velocity[0] = ve;
  sp.velocity[1] = vn;
  sp.velocity[2] = vu;
  sp.yaw_rate = yaw_rate;
  return sp;
}

setpoint_t hold() {
  setpoint_t sp = velocity(0, 0, 0);
  sp.mode = setpoint_t::MODE_HOLD;
  return sp;
}

bool is_zero_velocity(const mav::SetPositionTargetLocalNed& t) {
  return t.vx == 0 && t.vy == 0 && t.vz == 0 && t.yaw_rate == 0 &&
         t.type_mask == (mav::kTypemaskPositionIgnore | mav::kTypemaskAccelerationIgnore | mav::kTypemaskYawIgnore);
}

/// Runs the streamer from `from_ms` to `to_ms` in 1 ms steps, feeding `sp` every `every_ms` (0: never); returns the
/// (time ms, target) pairs sent.
std::vector<std::pair<int64_t, mav::SetPositionTargetLocalNed>> run(OffboardStreamer& s, int64_t from_ms, int64_t to_ms,
                                                                    const setpoint_t* sp, int64_t every_ms) {
  std::vector<std::pair<int64_t, mav::SetPositionTargetLocalNed>> sent;
  for (int64_t t = from_ms; t < to_ms; ++t) {
    bool force = false;
    if (sp && every_ms > 0 && (t - from_ms) % every_ms == 0) {
      setpoint_t now = *sp;  // the follower stamps each setpoint with its own (here: the test's) time
      now.utime = sp->utime + t * kMs;
      s.on_setpoint(now, t * kMs, 0);
      force = true;
    }
    if (auto out = s.tick(t * kMs, force)) sent.emplace_back(t, *out);
  }
  return sent;
}

BridgeOptions options() {
  BridgeOptions o;
  o.stream_rate_hz = 20;
  o.setpoint_timeout_s = 0.5;
  o.hover_s = 1.0;
  o.max_acceleration_mps2 = 100;  // out of the way unless a test is about it
  return o;
}

}  // namespace

TEST(OffboardStreamer, NothingIsSentToAnArduPilotOutsideGuidedAndEveryRefusalIsCounted) {
  std::vector<std::string> logged;
  OffboardStreamer s(options(), [&](const std::string& reason, const std::string&) { logged.push_back(reason); });
  s.on_autopilot(ardupilot(false));
  const setpoint_t sp = velocity(1, 0, 0);
  EXPECT_TRUE(run(s, 0, 2000, &sp, 100).empty());
  EXPECT_EQ(s.refusals().count_of("setpoint_not_engaged"), 20);
  EXPECT_EQ(logged, std::vector<std::string>{"setpoint_not_engaged"}) << "logged once";
  EXPECT_EQ(s.state(), StreamState::kIdle);
}

TEST(OffboardStreamer, Px4GetsZeroVelocityUntilOffboardThenTheFollowersSetpointsInNed) {
  OffboardStreamer s(options(), nullptr);
  s.on_autopilot(px4(false));
  const setpoint_t sp = velocity(1.0, 2.0, 0.5, 0.25);  // east 1, north 2, up 0.5, yaw rate 0.25 (ENU)
  auto before = run(s, 0, 1000, &sp, 100);
  ASSERT_FALSE(before.empty());
  for (const auto& [t, out] : before) EXPECT_TRUE(is_zero_velocity(out)) << "at " << t << " ms";
  EXPECT_EQ(s.state(), StreamState::kReady);
  s.on_autopilot(px4(true));
  auto after = run(s, 1000, 2000, &sp, 100);
  ASSERT_FALSE(after.empty());
  const auto& last = after.back().second;
  EXPECT_FLOAT_EQ(last.vx, 2.0f);          // north
  EXPECT_FLOAT_EQ(last.vy, 1.0f);          // east
  EXPECT_FLOAT_EQ(last.vz, -0.5f);         // down
  EXPECT_FLOAT_EQ(last.yaw_rate, -0.25f);  // clockwise from above
  EXPECT_EQ(s.state(), StreamState::kStreaming);
}

TEST(OffboardStreamer, TheStreamIsSteadyAtItsRateBetweenSparseSetpoints) {
  OffboardStreamer s(options(), nullptr);
  s.on_autopilot(px4(true));
  const setpoint_t sp = velocity(1, 0, 0);
  const auto sent = run(s, 0, 3000, &sp, 300);  // setpoints at 3.3 Hz, stream at 20 Hz
  ASSERT_GT(sent.size(), 50u);
  int64_t worst_gap = 0;
  for (size_t i = 1; i < sent.size(); ++i) worst_gap = std::max(worst_gap, sent[i].first - sent[i - 1].first);
  EXPECT_LE(worst_gap, 50) << "at 20 Hz the gap is 50 ms at most (setpoints are sent at once besides)";
}

TEST(OffboardStreamer, AHoldHoversForHoverSecondsThenStopsUntilThePilotReengages) {
  OffboardStreamer s(options(), nullptr);
  s.on_autopilot(px4(true));
  const setpoint_t sp = velocity(1, 0, 0);
  run(s, 0, 1000, &sp, 100);
  const setpoint_t h = hold();
  const auto sent = run(s, 1000, 4000, &h, 100);
  ASSERT_FALSE(sent.empty());
  for (const auto& [t, out] : sent) EXPECT_TRUE(is_zero_velocity(out)) << "at " << t << " ms";
  EXPECT_LE(sent.back().first, 1000 + 1000 + 1) << "the hover lasts stream.hover_s";
  EXPECT_GE(sent.back().first, 1000 + 1000 - 60);
  EXPECT_EQ(s.state(), StreamState::kStopped);
  EXPECT_EQ(s.refusals().count_of("follower_hold"), 1);
  // Setpoints again, still in OFFBOARD: nothing until the pilot leaves and re-engages OFFBOARD.
  EXPECT_TRUE(run(s, 4000, 5000, &sp, 100).empty());
  s.on_autopilot(px4(false));
  s.on_autopilot(px4(true));
  EXPECT_FALSE(run(s, 5000, 5200, &sp, 100).empty());
  EXPECT_EQ(s.state(), StreamState::kStreaming);
}

TEST(OffboardStreamer, ALostSetpointStreamHoversThenStops) {
  OffboardStreamer s(options(), nullptr);
  s.on_autopilot(ardupilot(true));
  const setpoint_t sp = velocity(1, 0, 0);
  run(s, 0, 1000, &sp, 100);
  const auto sent = run(s, 1000, 4000, nullptr, 0);  // the follower stops publishing
  // Its last setpoint goes on until setpoint_timeout_s (0.5 s after the last, at 900 ms), then the hover to 2.4 s.
  int hover = 0;
  for (const auto& [t, out] : sent) {
    if (t <= 1400) {
      EXPECT_FLOAT_EQ(out.vy, 1.0f) << t;
    } else {
      EXPECT_TRUE(is_zero_velocity(out)) << t;
      ++hover;
    }
  }
  EXPECT_GE(hover, 19);
  EXPECT_LE(sent.back().first, 2402);
  EXPECT_EQ(s.state(), StreamState::kStopped);
  EXPECT_EQ(s.refusals().count_of("setpoint_stream_stopped"), 1);
}

TEST(OffboardStreamer, LeavingTheModeStopsAtOnce) {
  OffboardStreamer s(options(), nullptr);
  s.on_autopilot(px4(true));
  const setpoint_t sp = velocity(1, 0, 0);
  run(s, 0, 500, &sp, 100);
  s.on_autopilot(px4(false));
  // PX4 not in OFFBOARD with live setpoints: the ready stream (zero velocity) only.
  for (const auto& [t, out] : run(s, 500, 1500, &sp, 100)) EXPECT_TRUE(is_zero_velocity(out)) << t;
  EXPECT_EQ(s.refusals().count_of("mode_left"), 1);
  AutopilotState lost;  // HEARTBEAT timeout
  s.on_autopilot(lost);
  EXPECT_TRUE(run(s, 1500, 2500, &sp, 100).empty());
}

TEST(OffboardStreamer, SpeedsAccelerationAndTheAltitudeBandAreClamped) {
  BridgeOptions o = options();
  o.max_horizontal_speed_mps = 3;
  o.max_vertical_speed_mps = 1;
  o.max_acceleration_mps2 = 2;
  o.min_altitude_m = 2;
  OffboardStreamer s(o, nullptr);
  s.on_autopilot(px4(true));
  s.on_altitude(10);
  const setpoint_t fast = velocity(8, 6, -4);  // 10 m/s horizontal, 4 m/s down
  const auto sent = run(s, 0, 3000, &fast, 50);
  ASSERT_GT(sent.size(), 10u);
  double prev_h = 0;
  int64_t prev_t = -50;
  for (const auto& [t, out] : sent) {
    const double h = std::hypot(out.vx, out.vy);
    EXPECT_LE(h, 3.0 + 1e-5);
    EXPECT_LE(std::abs(out.vz), 1.0 + 1e-5);
    EXPECT_LE(std::abs(h - prev_h), 2.0 * (t - prev_t) * 1e-3 + 1e-4) << "acceleration at " << t;
    prev_h = h;
    prev_t = t;
  }
  EXPECT_NEAR(std::hypot(sent.back().second.vx, sent.back().second.vy), 3.0, 1e-5);
  EXPECT_NEAR(sent.back().second.vy / sent.back().second.vx, 8.0 / 6.0, 1e-5) << "direction kept (east/north)";
  EXPECT_FLOAT_EQ(sent.back().second.vz, 1.0f) << "down 1 m/s at most";
  // At the bottom of the band: no further down.
  s.on_altitude(1.5);
  const auto low = run(s, 3000, 3500, &fast, 50);
  EXPECT_FLOAT_EQ(low.back().second.vz, 0.0f);
  for (const char* r : {"speed_clamped", "acceleration_clamped", "altitude_clamped"})
    EXPECT_GT(s.refusals().count_of(r), 0) << r;
}

TEST(OffboardStreamer, TheAccelerationClampCountsTheSetpointsMessageTimeNotTheirArrival) {
  BridgeOptions o = options();
  o.max_acceleration_mps2 = 3;
  OffboardStreamer s(o, nullptr);
  s.on_autopilot(ardupilot(true));
  s.on_altitude(10);
  // A burst: ten setpoints 100 ms apart in the follower's time arrive within 10 ms (a stalled link, a simulation
  // faster than real time). Each may move the command by 3 m/s^2 x 0.1 s (the first, after no follower setpoint,
  // by one stream period, 50 ms).
  std::vector<double> east;
  for (int i = 0; i < 10; ++i) {
    s.on_setpoint(velocity(5, 0, 0, 0, 1000000 + i * 100000), 1000 * kMs + i * kMs, 0);
    auto out = s.tick(1000 * kMs + i * kMs, true);
    ASSERT_TRUE(out.has_value()) << i;
    east.push_back(out->vy);  // NED: east is y
  }
  EXPECT_NEAR(east[0], 0.15, 1e-5);
  for (size_t i = 1; i < east.size(); ++i) EXPECT_NEAR(east[i] - east[i - 1], 0.3, 1e-5) << i;
  // The same setpoint sent again (the stream's rate) moves it no further, however long after it arrived.
  auto again = s.tick(1100 * kMs);
  ASSERT_TRUE(again.has_value());
  EXPECT_FLOAT_EQ(again->vy, static_cast<float>(east.back()));
}

TEST(OffboardStreamer, PositionSetpointsAreConvertedAndKeptInTheAltitudeBand) {
  BridgeOptions o = options();
  o.max_altitude_m = 20;
  OffboardStreamer s(o, nullptr);
  s.on_autopilot(ardupilot(true));
  setpoint_t sp{};
  sp.utime = 1000000;
  sp.mode = setpoint_t::MODE_POSITION;
  sp.frame = wingman::own_pose_t::FRAME_ENU;
  sp.position[0] = 3;   // east
  sp.position[1] = 4;   // north
  sp.position[2] = 30;  // up, above the band
  sp.yaw = 0;           // facing east (ENU)
  const auto sent = run(s, 0, 200, &sp, 100);
  ASSERT_FALSE(sent.empty());
  const auto& t = sent.back().second;
  EXPECT_FLOAT_EQ(t.x, 4);
  EXPECT_FLOAT_EQ(t.y, 3);
  EXPECT_FLOAT_EQ(t.z, -20);
  EXPECT_NEAR(t.yaw, M_PI / 2, 1e-6) << "east is +90 deg from north";
  EXPECT_EQ(t.type_mask, mav::kTypemaskVelocityIgnore | mav::kTypemaskAccelerationIgnore | mav::kTypemaskYawRateIgnore);
  EXPECT_GT(s.refusals().count_of("altitude_clamped"), 0);
}

TEST(OffboardStreamer, SetpointsOlderThanTheOwnPoseOrInAnUnknownFrameAreRefused) {
  OffboardStreamer s(options(), nullptr);
  s.on_autopilot(px4(true));
  setpoint_t old = velocity(1, 0, 0, 0, 1000000);
  s.on_setpoint(old, 0, 1000000 + 600000);  // 0.6 s older than the newest pose (max 0.5 s)
  setpoint_t bad = velocity(1, 0, 0);
  bad.frame = 7;
  s.on_setpoint(bad, 0, 0);
  EXPECT_FALSE(s.tick(1000).has_value());
  EXPECT_EQ(s.refusals().count_of("setpoint_too_old"), 1);
  EXPECT_EQ(s.refusals().count_of("setpoint_bad_frame"), 1);
}
