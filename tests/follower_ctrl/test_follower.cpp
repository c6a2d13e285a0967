// SPDX-License-Identifier: MIT
// The follower's hold rules and message handling: one setpoint per driving input, lost-target hold after
// the timeout (message time), own pose missing or stale, the own-pose watchdog, NED, track switches, sources.
#include "wingman/follower_ctrl/follower.hpp"

#include "follower_test_helpers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace {

using Eigen::Vector3d;
using wingman::setpoint_t;
using wingman::follower_ctrl::Follower;
using wingman::follower_ctrl::FollowerOptions;
using wingman::follower_ctrl::FollowerOutput;
using wingman::follower_ctrl::swap_ned_enu;
using namespace wingman::follower_ctrl::test;

Vector3d velocity_of(const setpoint_t& s) { return {s.velocity[0], s.velocity[1], s.velocity[2]}; }

/// Options whose limits do not act, so the controllers' outputs show (the limits have their own tests).
FollowerOptions wide(const std::string& mode) {
  FollowerOptions o;
  o.mode = mode;
  o.limits = wide_limits();
  o.limits.max_yaw_rate_radps = 10;
  return o;
}

TEST(Follower, Pid1dPublishesThePinnedPidSequenceAlongImageRightOnePerDetections) {
  Follower f(wide("pid_1d"));
  // Thesis set-up: camera looking along world +Y, image right = world +X. Errors and times as in
  // Pid.ThesisGainsOverSixStepsWithIrregularDtMatchHandComputedTerms.
  const double t_s[] = {0.0, 0.1, 0.25, 0.3, 0.5, 0.6};
  const float cx[] = {700, 800, 900, 600, 900, 100};
  const double v_x[] = {
      0.0 /* first command after a hold: the measured velocity */, 9.86, 10.58 + 4.0 / 3.0, -9.21, 13.6, -26.28};
  for (int k = 0; k < 6; ++k) {
    const int64_t t = kT0 + static_cast<int64_t>(t_s[k] * 1e6 + 0.5);
    EXPECT_FALSE(f.on_own_pose(own_pose(t, {0, 0, 5}, M_PI / 2)).setpoint.has_value());
    const FollowerOutput out = f.on_detections(detections(t, {box(cx[k])}));
    ASSERT_TRUE(out.setpoint.has_value());
    const setpoint_t& s = *out.setpoint;
    EXPECT_EQ(s.utime, t);
    EXPECT_EQ(s.mode, kVelocity);
    EXPECT_EQ(s.frame, kEnuFrame);
    EXPECT_EQ(s.target_track_id, 0);
    EXPECT_EQ(s.detection_source, kCnnSource);
    EXPECT_VEC_NEAR(velocity_of(s), Vector3d(v_x[k], 0, 0), kTol) << "step " << k;
    EXPECT_TRUE(f.status().flying);
  }
}

TEST(Follower, Pid1dWithoutABoxHoldsOnlyAfterTheTimeoutAndThenRestartsTheLoop) {
  Follower f(wide("pid_1d"));
  f.on_own_pose(own_pose(kT0, {0, 0, 5}, M_PI / 2));
  EXPECT_EQ(f.on_detections(detections(kT0, {})).setpoint->mode, kHold) << "no box yet";
  EXPECT_NE(f.status().detail.find("no box yet"), std::string::npos) << f.status().detail;
  for (int k = 1; k <= 10; ++k) {
    const int64_t t = kT0 + k * 100 * kMs;
    f.on_own_pose(own_pose(t, {0, 0, 5}, M_PI / 2));
    const auto d = k == 1 ? detections(t, {box(800)}) : detections(t, {});
    const setpoint_t s = *f.on_detections(d).setpoint;
    // Box at 0.1 s; without a box the axis command is 0 until 0.6 s, then HOLD.
    EXPECT_EQ(s.mode, k <= 6 ? kVelocity : kHold) << "t = " << k * 0.1;
    if (k > 1 && k <= 6) {
      EXPECT_VEC_NEAR(velocity_of(s), Vector3d::Zero(), kTol);
    }
    if (k == 7) {
      EXPECT_NE(f.status().detail.find("target lost: no box for 0.600 s (hold.timeout_s = 0.5)"), std::string::npos)
          << f.status().detail;
    }
  }
}

/// A scripted formation run: own poses and targets every 100 ms.
struct FormationStep {
  int64_t t;
  std::vector<wingman::target_t> list;
};

TEST(Follower, FormationCoastsOnThePredictionThenHoldsAfterTheTimeoutOfMessageTimeAndNeverKeepsFlying) {
  Follower f(wide("formation"));
  const Vector3d v_target(1.0, 0.0, 0.0);
  for (int k = 0; k <= 12; ++k) {
    const int64_t t = kT0 + k * 100 * kMs;
    f.on_own_pose(own_pose(t, {0.1 * k, -6, 5}, M_PI / 2, v_target));
    std::vector<wingman::target_t> list;
    if (k <= 3) list.push_back(target(1, Vector3d(0.1 * k, 0, 5), v_target, t, t));  // seen until 0.3 s
    const FollowerOutput out = f.on_targets(targets(t, list));
    ASSERT_TRUE(out.setpoint.has_value());
    const setpoint_t& s = *out.setpoint;
    EXPECT_EQ(s.utime, t);
    SCOPED_TRACE(testing::Message() << "t = " << k * 0.1 << " s: " << f.status().detail);
    if (k <= 8) {  // 0.8 - 0.3 = 0.5 s: still within hold.timeout_s
      EXPECT_EQ(s.mode, kVelocity);
      EXPECT_EQ(s.target_track_id, 1);
      EXPECT_TRUE(f.status().flying);
      // On station and moving with the target: the command is the feed-forward, coasting included.
      if (k > 0) {
        EXPECT_VEC_NEAR(velocity_of(s), v_target, 1e-6);
      }
      if (k > 3) {
        EXPECT_NE(f.status().detail.find("coasting on track 1"), std::string::npos);
      }
    } else {
      EXPECT_EQ(s.mode, kHold);
      EXPECT_EQ(s.target_track_id, 0);
      EXPECT_TRUE(velocity_of(s) == Vector3d::Zero()) << velocity_of(s).transpose();
      EXPECT_EQ(s.yaw_rate, 0.0);
      EXPECT_FALSE(f.status().flying);
      EXPECT_NE(f.status().detail.find("target lost: track 1 not seen for"), std::string::npos);
    }
  }
  // Found again: flying again, from the measured velocity (the hold forgot the previous command).
  const int64_t t = kT0 + 1300 * kMs;
  f.on_own_pose(own_pose(t, {1.3, -6, 5}, M_PI / 2, Vector3d(0.25, 0, 0)));
  const setpoint_t s = *f.on_targets(targets(t, {target(1, Vector3d(1.3, 0, 5), v_target, t, t)})).setpoint;
  EXPECT_EQ(s.mode, kVelocity);
  EXPECT_VEC_NEAR(velocity_of(s), Vector3d(0.25, 0, 0), kTol);
}

TEST(Follower, TargetsWithoutWorldFrameOrWithAStaleImageAreNotFollowed) {
  Follower f(wide("formation"));
  f.on_own_pose(own_pose(kT0, {0, -6, 5}));
  auto camera_only = target(1, Vector3d(0, 0, 5), Vector3d::Zero(), kT0, kT0);
  camera_only.world_valid = false;
  EXPECT_EQ(f.on_targets(targets(kT0, {camera_only})).setpoint->mode, kHold);
  const int64_t t = kT0 + 600 * kMs;
  f.on_own_pose(own_pose(t, {0, -6, 5}));
  const auto stale = target(1, Vector3d(0, 0, 5), Vector3d::Zero(), kT0, t);  // image 0.6 s old
  EXPECT_EQ(f.on_targets(targets(t, {stale})).setpoint->mode, kHold);
  EXPECT_NE(f.status().detail.find("no usable target yet"), std::string::npos) << f.status().detail;
}

TEST(Follower, HoldsWithoutAnOwnPoseAndWithAStaleOne) {
  Follower f(wide("formation"));
  const setpoint_t first =
      *f.on_targets(targets(kT0, {target(1, Vector3d(0, 0, 5), Vector3d::Zero(), kT0, kT0)})).setpoint;
  EXPECT_EQ(first.mode, kHold);
  EXPECT_EQ(first.utime, kT0);
  EXPECT_EQ(f.status().detail, "holding: no own pose yet");

  f.on_own_pose(own_pose(kT0 + 100 * kMs, {0, -6, 5}));
  const int64_t t = kT0 + 700 * kMs;  // the own pose is 0.6 s old
  const setpoint_t stale = *f.on_targets(targets(t, {target(1, Vector3d(0, 0, 5), Vector3d::Zero(), t, t)})).setpoint;
  EXPECT_EQ(stale.mode, kHold);
  EXPECT_NE(f.status().detail.find("own pose stale: newest is 0.600 s older than the input"), std::string::npos)
      << f.status().detail;
  EXPECT_NEAR(stale.position[1], -6.0, kTol) << "a hold carries the place to hold: the own position";
}

TEST(Follower, OwnPosesHoldOncePerPoseWhenTheDrivingInputStops) {
  Follower f(wide("formation"));
  int holds = 0;
  int64_t first_hold = 0;
  for (int k = 0; k <= 200; ++k) {  // own poses every 10 ms for 2 s
    const int64_t t = kT0 + k * 10 * kMs;
    const FollowerOutput out = f.on_own_pose(own_pose(t, {0, -6, 5}));
    if (out.setpoint) {
      EXPECT_EQ(out.setpoint->mode, kHold);
      EXPECT_EQ(out.setpoint->utime, t);
      if (holds++ == 0) first_hold = t;
    }
    if (k % 10 == 0 && k <= 50) {  // targets every 100 ms until 0.5 s
      f.on_targets(targets(t, {target(1, Vector3d(0, 0, 5), Vector3d::Zero(), t, t)}));
      EXPECT_TRUE(f.status().flying) << f.status().detail;
    }
  }
  // Last targets at 0.5 s: the first pose more than 0.5 s later is at 1.01 s; then every pose to 2.0 s.
  EXPECT_EQ(first_hold, kT0 + 1010 * kMs);
  EXPECT_EQ(holds, 100);
  EXPECT_FALSE(f.status().flying);
  EXPECT_NE(f.status().detail.find("no targets_t on TARGETS for 1.500 s of own-pose time"), std::string::npos)
      << f.status().detail;
}

TEST(Follower, OwnPosesHoldWhenNoDrivingInputHasEverArrived) {
  Follower f(wide("pid_1d"));
  for (int k = 0; k <= 60; ++k) {
    const int64_t t = kT0 + k * 10 * kMs;
    const FollowerOutput out = f.on_own_pose(own_pose(t, {0, 0, 5}));
    EXPECT_EQ(out.setpoint.has_value(), k >= 51) << "t = " << k * 0.01;
  }
  EXPECT_NE(f.status().detail.find("no detections_t on DETECTIONS_CAM0"), std::string::npos) << f.status().detail;
}

TEST(Follower, NedOwnPoseAndNedTargetsFlyTheSameAsEnuWithNedSetpoints) {
  auto opts = wide("formation");
  opts.limits.max_yaw_rate_radps = 0.2;  // let the yaw limit act too
  Follower enu(opts), ned(opts);
  const double yaw_enu = 0.5;
  for (int k = 0; k < 4; ++k) {
    const int64_t t = kT0 + k * 100 * kMs;
    const Vector3d p_own(1.0 + 0.05 * k, -6.5, 4.0), v_own(0.2, 0.1, -0.1);
    const Vector3d p_target(0.1 * k, 0.0, 5.0), v_target(1.0, 0.5, 0.2);
    enu.on_own_pose(own_pose(t, p_own, yaw_enu, v_own, kEnuFrame));
    ned.on_own_pose(own_pose(t, swap_ned_enu(p_own), M_PI / 2 - yaw_enu, swap_ned_enu(v_own), kNedFrame));
    const setpoint_t a = *enu.on_targets(targets(t, {target(3, p_target, v_target, t, t)}, kEnuFrame)).setpoint;
    const setpoint_t b =
        *ned.on_targets(targets(t, {target(3, swap_ned_enu(p_target), swap_ned_enu(v_target), t, t)}, kNedFrame))
             .setpoint;
    SCOPED_TRACE(testing::Message() << "step " << k);
    EXPECT_EQ(a.frame, kEnuFrame);
    EXPECT_EQ(b.frame, kNedFrame);
    EXPECT_EQ(a.mode, kVelocity);
    EXPECT_EQ(b.mode, kVelocity);
    EXPECT_VEC_NEAR(velocity_of(b), swap_ned_enu(velocity_of(a)), 1e-9);
    EXPECT_NEAR(b.yaw_rate, -a.yaw_rate, 1e-9);
    EXPECT_NEAR(b.yaw, M_PI / 2 - a.yaw, 1e-9);
    if (k > 0) {
      EXPECT_GT(velocity_of(a).norm(), 0.5) << "the scenario must actually fly";
      EXPECT_NEAR(a.yaw_rate, 0.2, kTol) << "target far to the left of the camera: limited turn";
    }
  }
}

TEST(Follower, KeepsTheFollowedTrackWhileReportedThenSwitchesWithAFreshPid) {
  auto opts = wide("formation");
  opts.formation.kd = 1.0;
  opts.formation.reselect_after_s = 0.0;  // switch as soon as the followed track has gone
  Follower f(opts);
  auto step = [&](int k, std::vector<wingman::target_t> list) {
    const int64_t t = kT0 + k * 100 * kMs;
    f.on_own_pose(own_pose(t, {0, -6, 5}));
    for (auto& x : list) x.source_utime = x.predicted_utime = t;
    return *f.on_targets(targets(t, list)).setpoint;
  };
  const auto one = target(1, Vector3d(0, 0, 5), Vector3d::Zero(), 0, 0, 0.5f);
  const auto two = target(2, Vector3d(4, 0, 5), Vector3d::Zero(), 0, 0, 0.9f);
  EXPECT_EQ(step(0, {one}).target_track_id, 1);
  EXPECT_EQ(step(1, {two, one}).target_track_id, 1) << "more confident, but the followed track is kept";
  const setpoint_t s = step(2, {two});
  EXPECT_EQ(s.target_track_id, 2);
  // 4 m east of the formation point; without the PID reset D would add 1 * (4 - 0) / 0.1 = 40 m/s.
  EXPECT_VEC_NEAR(velocity_of(s), Vector3d(4, 0, 0), kTol);
}

TEST(Follower, AfterTheFollowedTrackHasGoneAnotherIsTakenOnlyAfterAWait) {
  auto opts = wide("formation");
  opts.formation.reselect_after_s = 2.0;
  const auto leader = target(1, Vector3d(0, 0, 5), Vector3d::Zero(), 0, 0, 0.5f);
  const auto bird = target(2, Vector3d(8, 3, 5), Vector3d::Zero(), 0, 0, 0.9f);
  // Every 100 ms of message time; the follower on station, the targets still.
  struct Flight {
    Follower f;
    setpoint_t step(int k, std::vector<wingman::target_t> list) {
      const int64_t t = kT0 + k * 100 * kMs;
      f.on_own_pose(own_pose(t, {0, -6, 5}));
      for (auto& x : list) x.source_utime = x.predicted_utime = t;
      return *f.on_targets(targets(t, list)).setpoint;
    }
  };

  // The leader followed for 3 s (images 0 .. 3 s), then gone; a more confident track is there: the wait is 2 s.
  Flight a{Follower(opts)};
  for (int k = 0; k <= 30; ++k) ASSERT_EQ(a.step(k, {leader}).target_track_id, 1);
  for (int k = 31; k <= 49; ++k) {  // 0.1 .. 1.9 s after the leader's last image
    const setpoint_t s = a.step(k, {bird});
    SCOPED_TRACE(testing::Message() << "t = " << k * 0.1 << " s: " << a.f.status().detail);
    EXPECT_NE(a.f.status().detail.find("not switching to track 2 for 2.000 s after track 1's last image (as long as "
                                       "it was followed, at most formation.reselect_after_s = 2)"),
              std::string::npos);
    if (k <= 35) {  // hold.timeout_s 0.5: coasting on the leader
      EXPECT_EQ(s.mode, kVelocity);
      EXPECT_EQ(s.target_track_id, 1);
      EXPECT_NE(a.f.status().detail.find("coasting on track 1"), std::string::npos);
    } else {
      EXPECT_EQ(s.mode, kHold);
      EXPECT_EQ(s.target_track_id, 0);
      EXPECT_NE(a.f.status().detail.find("target lost: track 1 not seen for"), std::string::npos);
    }
  }
  // 2 s after the leader's last image: the other track is followed, and kept.
  EXPECT_EQ(a.step(50, {bird}).target_track_id, 2);
  EXPECT_EQ(a.step(51, {bird, leader}).target_track_id, 2) << "now track 2 is the followed one";

  // The followed track coming back within the wait is taken back at once.
  Flight b{Follower(opts)};
  for (int k = 0; k <= 30; ++k) b.step(k, {leader});
  EXPECT_EQ(b.step(40, {bird}).mode, kHold);  // 1 s without the leader
  const setpoint_t back = b.step(45, {bird, leader});
  EXPECT_EQ(back.mode, kVelocity);
  EXPECT_EQ(back.target_track_id, 1);
  EXPECT_NE(b.f.status().detail.find("following track 1"), std::string::npos) << b.f.status().detail;

  // A track followed for 0.4 s only (a false one at the start) is waited for 0.4 s.
  Flight c{Follower(opts)};
  for (int k = 0; k <= 4; ++k) ASSERT_EQ(c.step(k, {bird}).target_track_id, 2);
  EXPECT_EQ(c.step(5, {leader}).target_track_id, 2);  // 0.1 s: coasting on the bird
  EXPECT_NE(c.f.status().detail.find("not switching to track 1 for 0.400 s"), std::string::npos) << c.f.status().detail;
  EXPECT_EQ(c.step(8, {leader}).target_track_id, 1);  // 0.4 s after the bird's last image
}

TEST(Follower, AtTheStartTheFirstTrackIsTakenWithoutWaiting) {
  Follower f(wide("formation"));  // reselect_after_s 10 by default
  f.on_own_pose(own_pose(kT0, {0, -6, 5}));
  EXPECT_EQ(
      f.on_targets(targets(kT0, {target(5, Vector3d(0, 0, 5), Vector3d::Zero(), kT0, kT0)})).setpoint->target_track_id,
      5);
}

TEST(Follower, SelectionPolicyPicksTheFirstTrack) {
  const auto far_confident = target(7, Vector3d(0, 20, 5), Vector3d::Zero(), kT0, kT0, 0.95f);
  const auto near_unsure = target(8, Vector3d(0, 0, 5), Vector3d::Zero(), kT0, kT0, 0.6f);
  for (const std::string policy : {"most_confident", "nearest"}) {
    auto opts = wide("formation");
    opts.formation.select = policy;
    Follower f(opts);
    f.on_own_pose(own_pose(kT0, {0, -6, 5}));
    EXPECT_EQ(f.on_targets(targets(kT0, {far_confident, near_unsure})).setpoint->target_track_id,
              policy == "nearest" ? 8 : 7)
        << policy;
  }
}

TEST(Follower, DetectionSourceIsCopiedFromTheDataBehindTheSetpoint) {
  Follower f(wide("formation"));
  f.on_own_pose(own_pose(kT0, {0, -6, 5}));
  auto gt = target(1, Vector3d(0, 0, 5), Vector3d::Zero(), kT0, kT0, 0.9f, kGroundTruthSource);
  EXPECT_EQ(f.on_targets(targets(kT0, {gt})).setpoint->detection_source, kGroundTruthSource);
  EXPECT_NE(f.status().detail.find("ground-truth boxes"), std::string::npos) << f.status().detail;
  const int64_t t = kT0 + 1000 * kMs;
  f.on_own_pose(own_pose(t, {0, -6, 5}));
  const setpoint_t hold = *f.on_targets(targets(t, {})).setpoint;
  EXPECT_EQ(hold.mode, kHold);
  EXPECT_EQ(hold.detection_source, kGroundTruthSource) << "a hold carries the newest source";

  Follower p(wide("pid_1d"));
  p.on_own_pose(own_pose(kT0, {0, 0, 5}, M_PI / 2));
  EXPECT_EQ(p.on_detections(detections(kT0, {box(600)}, 1000, kGroundTruthSource)).setpoint->detection_source,
            kGroundTruthSource);
}

TEST(Follower, UnusableInputsThrowNamingTheFieldAndBadBoxesAreReported) {
  Follower f(wide("formation"));
  f.on_own_pose(own_pose(kT0 + 10 * kMs, {0, -6, 5}));
  try {
    f.on_own_pose(own_pose(kT0 + 10 * kMs, {0, -6, 5}));
    ADD_FAILURE() << "duplicate own pose accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("own_pose_t.utime = 1700000000010000: not after the previous own pose"),
              std::string::npos)
        << e.what();
  }
  f.on_targets(targets(kT0 + 20 * kMs, {}));
  try {
    f.on_targets(targets(kT0 + 15 * kMs, {}));
    ADD_FAILURE() << "out-of-order targets accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("targets_t.utime = 1700000000015000: before the previous targets_t"),
              std::string::npos)
        << e.what();
  }
  auto odd = target(1, Vector3d(0, 0, 5), Vector3d::Zero(), kT0, kT0);
  odd.detection_source = 5;
  try {
    f.on_targets(targets(kT0 + 30 * kMs, {odd}));
    ADD_FAILURE() << "unknown detection_source accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("targets_t.targets[0].detection_source = 5"), std::string::npos) << e.what();
  }
  EXPECT_THROW(f.on_detections(detections(kT0 + 40 * kMs, {})), std::logic_error);

  Follower p(wide("pid_1d"));
  p.on_own_pose(own_pose(kT0, {0, 0, 5}, M_PI / 2));
  const FollowerOutput out = p.on_detections(detections(kT0, {box(1200, 0.99f), box(600)}));
  ASSERT_EQ(out.rejections.size(), 1u);
  EXPECT_EQ(out.rejections[0], "detections_t.detections[0].cx = 1200: outside the image [0, 1000]");
  EXPECT_EQ(out.setpoint->mode, kVelocity) << "the box inside the image is followed";
}

TEST(Follower, InvalidOptionsAreRefusedWithEveryProblem) {
  FollowerOptions o;
  o.mode = "hover";
  o.hold_timeout_s = 0;
  try {
    Follower f(o);
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("controller.mode = 'hover': must be formation or pid_1d"), std::string::npos) << what;
    EXPECT_NE(what.find("hold.timeout_s = 0: must be a finite number > 0"), std::string::npos) << what;
  }
}

}  // namespace
