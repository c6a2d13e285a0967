// SPDX-License-Identifier: MIT
// The follower's localizer watchdog: holds while the localizer reports STOPPING/ERROR or its heartbeats (and targets)
// stop for longer than localizer.heartbeat_timeout_s of message time; resumes when they return.
#include "wingman/follower_ctrl/follower.hpp"

#include "follower_test_helpers.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

namespace {

using Eigen::Vector3d;
using wingman::status_t;
using wingman::follower_ctrl::Follower;
using wingman::follower_ctrl::FollowerOptions;
using wingman::follower_ctrl::FollowerOutput;
using namespace wingman::follower_ctrl::test;

constexpr int8_t kError = wingman::status_t::STATE_ERROR;

FollowerOptions formation() {
  FollowerOptions o;
  o.limits = wide_limits();
  return o;
}

/// A localizer heartbeat. Its utime is wall-clock time, far from the message time: the follower must not use it.
status_t heartbeat(int8_t state, const std::string& detail = "") {
  status_t s{};
  s.utime = 42;
  s.process = "localizer";
  s.state = state;
  s.detail = detail;
  return s;
}

wingman::targets_t one_target(int64_t t) { return targets(t, {target(1, Vector3d(0, 0, 5), Vector3d::Zero(), t, t)}); }

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(FollowerLocalizerWatchdog, StoppingOrErrorHoldsAtTheNextInputAndTheNextHeartbeatResumes) {
  Follower f(formation());
  f.on_localizer_status(heartbeat(kOk));
  int64_t t = kT0;
  auto step = [&](int k) {
    t = kT0 + k * 100 * kMs;
    const FollowerOutput pose_out = f.on_own_pose(own_pose(t, {0, -6, 5}));
    const FollowerOutput target_out = f.on_targets(one_target(t));
    return std::make_pair(pose_out, target_out);
  };
  for (int k = 0; k < 5; ++k) {
    const auto [pose_out, target_out] = step(k);
    EXPECT_FALSE(pose_out.setpoint.has_value());
    EXPECT_EQ(target_out.setpoint->mode, kVelocity) << f.status().detail;
  }
  f.on_localizer_status(heartbeat(kStopping, "signal 15"));
  for (int k = 5; k < 8; ++k) {
    const auto [pose_out, target_out] = step(k);
    ASSERT_TRUE(pose_out.setpoint.has_value());  // every own pose holds too
    EXPECT_EQ(pose_out.setpoint->mode, kHold);
    EXPECT_EQ(pose_out.setpoint->utime, t);
    EXPECT_EQ(target_out.setpoint->mode, kHold);
    EXPECT_EQ(f.status().detail, "holding: localizer 'localizer' reports STOPPING (signal 15)");
  }
  f.on_localizer_status(heartbeat(kError));
  step(8);
  EXPECT_EQ(f.status().detail, "holding: localizer 'localizer' reports ERROR");
  // A restarted localizer's first heartbeat: flying again with the next targets.
  f.on_localizer_status(heartbeat(wingman::status_t::STATE_STARTING));
  const auto [pose_out, target_out] = step(9);
  EXPECT_FALSE(pose_out.setpoint.has_value());
  EXPECT_EQ(target_out.setpoint->mode, kVelocity) << f.status().detail;
  EXPECT_TRUE(f.status().flying);
}

TEST(FollowerLocalizerWatchdog, NoHeartbeatForLongerThanTheTimeoutOfMessageTimeHoldsUntilOneArrives) {
  FollowerOptions o = formation();
  o.hold_timeout_s = 10.0;  // the targets timeout out of the way: only the heartbeat watchdog acts
  o.localizer_heartbeat_timeout_s = 1.0;
  Follower f(o);
  f.on_own_pose(own_pose(kT0, {0, -6, 5}));
  EXPECT_EQ(f.on_targets(one_target(kT0)).setpoint->mode, kVelocity);
  f.on_localizer_status(heartbeat(kOk));  // at message time kT0
  int holds = 0;
  int64_t first_hold = 0;
  for (int k = 1; k <= 200; ++k) {  // own poses every 10 ms for 2 s; no targets, no heartbeat
    const int64_t t = kT0 + k * 10 * kMs;
    const FollowerOutput out = f.on_own_pose(own_pose(t, {0, -6, 5}));
    if (out.setpoint) {
      EXPECT_EQ(out.setpoint->mode, kHold);
      if (holds++ == 0) first_hold = t;
    }
  }
  EXPECT_EQ(first_hold, kT0 + 1010 * kMs);  // the first own pose more than 1.0 s after the heartbeat
  EXPECT_EQ(holds, 100);
  EXPECT_EQ(f.status().detail,
            "holding: no heartbeat from localizer 'localizer' for 2.000 s of message time "
            "(localizer.heartbeat_timeout_s = 1)");
  // Targets while the heartbeat is missing hold too.
  const int64_t t1 = kT0 + 2010 * kMs;
  f.on_own_pose(own_pose(t1, {0, -6, 5}));
  EXPECT_EQ(f.on_targets(one_target(t1)).setpoint->mode, kHold);
  // The heartbeat returns: dated by the newest message time, the watchdog lets the follower fly.
  f.on_localizer_status(heartbeat(kOk));
  const int64_t t2 = kT0 + 2020 * kMs;
  EXPECT_FALSE(f.on_own_pose(own_pose(t2, {0, -6, 5})).setpoint.has_value());
  EXPECT_EQ(f.on_targets(one_target(t2)).setpoint->mode, kVelocity) << f.status().detail;
}

TEST(FollowerLocalizerWatchdog, TargetsCountAsSignsOfLifeSoSparseHeartbeatsInAFastSimulationDoNotHold) {
  FollowerOptions o = formation();
  o.localizer_heartbeat_timeout_s = 1.0;
  Follower f(o);
  f.on_localizer_status(heartbeat(kOk));
  for (int k = 0; k <= 50; ++k) {  // 5 s of message time, one heartbeat only
    const int64_t t = kT0 + k * 100 * kMs;
    EXPECT_FALSE(f.on_own_pose(own_pose(t, {0, -6, 5})).setpoint.has_value());
    EXPECT_EQ(f.on_targets(one_target(t)).setpoint->mode, kVelocity) << f.status().detail;
  }
}

TEST(FollowerLocalizerWatchdog, AHeartbeatBeforeAnyMessageIsDatedByTheFirstMessage) {
  FollowerOptions o = formation();
  o.hold_timeout_s = 10.0;
  o.localizer_heartbeat_timeout_s = 1.0;
  Follower f(o);
  f.on_localizer_status(heartbeat(kOk));
  EXPECT_FALSE(f.on_own_pose(own_pose(kT0 + 5000 * kMs, {0, -6, 5})).setpoint.has_value());
  EXPECT_FALSE(f.on_own_pose(own_pose(kT0 + 6000 * kMs, {0, -6, 5})).setpoint.has_value());
  EXPECT_TRUE(f.on_own_pose(own_pose(kT0 + 6010 * kMs, {0, -6, 5})).setpoint.has_value());
}

TEST(FollowerLocalizerWatchdog, NotArmedWithoutHeartbeatsSwitchedOffByAnEmptyInstanceAndIgnoredInPid1d) {
  {  // no heartbeat ever: the targets rules alone
    Follower f(formation());
    for (int k = 0; k <= 100; ++k) {
      const int64_t t = kT0 + k * 100 * kMs;
      f.on_own_pose(own_pose(t, {0, -6, 5}));
      EXPECT_EQ(f.on_targets(one_target(t)).setpoint->mode, kVelocity);
    }
  }
  {  // localizer.instance "": heartbeats are ignored
    FollowerOptions o = formation();
    o.localizer_instance = "";
    Follower f(o);
    f.on_localizer_status(heartbeat(kStopping));
    f.on_own_pose(own_pose(kT0, {0, -6, 5}));
    EXPECT_EQ(f.on_targets(one_target(kT0)).setpoint->mode, kVelocity);
  }
  {  // pid_1d has no localizer
    FollowerOptions o = formation();
    o.mode = "pid_1d";
    Follower f(o);
    f.on_localizer_status(heartbeat(kStopping));
    f.on_own_pose(own_pose(kT0, {0, 0, 5}));
    EXPECT_EQ(f.on_detections(detections(kT0, {box(500)})).setpoint->mode, kVelocity) << f.status().detail;
  }
}

TEST(FollowerLocalizerWatchdog, ATimeoutThatIsNotPositiveIsRefusedNamingTheKey) {
  FollowerOptions o;
  o.localizer_heartbeat_timeout_s = 0.0;
  const auto problems = o.validate();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_TRUE(contains(problems[0], "localizer.heartbeat_timeout_s")) << problems[0];
}

}  // namespace
