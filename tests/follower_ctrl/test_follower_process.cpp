// SPDX-License-Identifier: MIT
// wingman-follower-ctrl as a process, file to file: one setpoint per driving input, the own-pose watchdog's
// holds, the status it reports, and malformed messages dropped and counted without stopping it.
#include "follower_test_helpers.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <wingman/setpoint_t.hpp>
#include <wingman/status_t.hpp>

#include <cmath>
#include <fstream>
#include <limits>

namespace {

using namespace std::chrono_literals;
using namespace wingman::follower_ctrl::test;
using wingman::setpoint_t;
using wingman::status_t;
using wingman::testing::bin_path;
using wingman::testing::LogEvent;
using wingman::testing::make_event;
using wingman::testing::read_log;
using wingman::testing::TempDir;

struct ProcessRun {
  std::vector<setpoint_t> setpoints;
  std::vector<status_t> statuses;  // one per handled message (--lockstep), then the final STOPPING one
  std::string err;
};

ProcessRun run_follower(const TempDir& dir, const std::vector<LogEvent>& events, const std::string& config_yaml = "") {
  wingman::testing::write_log(dir.file("in.lcmlog"), events);
  std::vector<std::string> argv = {bin_path("wingman-follower-ctrl"),
                                   "--lockstep",
                                   "--lcm-in",
                                   "file://" + dir.file("in.lcmlog") + "?speed=0",
                                   "--lcm-out",
                                   "file://" + dir.file("out.lcmlog") + "?mode=w"};
  if (!config_yaml.empty()) {
    std::ofstream(dir.file("follower.yaml")) << config_yaml;
    argv.insert(argv.end(), {"--config", dir.file("follower.yaml")});
  }
  const auto r = wingman::testing::run(argv, 60s);
  if (r.exit_code != 0) throw std::runtime_error("follower failed (" + std::to_string(r.exit_code) + "): " + r.err);
  ProcessRun out;
  out.err = r.err;
  for (const auto& e : read_log(dir.file("out.lcmlog"))) {
    if (e.channel == "SETPOINT") {
      setpoint_t s;
      if (s.decode(e.data.data(), 0, static_cast<int>(e.data.size())) < 0) throw std::runtime_error("bad setpoint");
      out.setpoints.push_back(s);
    } else if (e.channel == "STATUS_FOLLOWER_CTRL") {
      status_t s;
      if (s.decode(e.data.data(), 0, static_cast<int>(e.data.size())) < 0) throw std::runtime_error("bad status");
      out.statuses.push_back(s);
    }
  }
  return out;
}

const wingman::channel_stats_t* channel(const status_t& s, const std::string& name) {
  for (const auto& c : s.channels)
    if (c.channel == name) return &c;
  return nullptr;
}

TEST(FollowerProcess, FormationFollowsOnEveryTargetsThenTheOwnPoseWatchdogHoldsAndBadMessagesAreCounted) {
  // Own poses at 100 Hz for 2 s, flying north at 1 m/s 6 m behind a target that does the same;
  // targets every 100 ms until 0.95 s (ground-truth boxes), then the localizer "stops".
  const Eigen::Vector3d v(0.0, 1.0, 0.0);
  std::vector<LogEvent> events;
  int targets_sent = 0;
  for (int k = 0; k <= 200; ++k) {
    const int64_t t = kT0 + k * 10 * kMs;
    const double ts = k * 0.01;
    events.push_back(make_event("OWN_POSE", own_pose(t, {0, -6 + ts, 5}, M_PI / 2, v), t - kT0));
    if (k % 10 == 5 && k < 100) {
      const auto tg = target(5, Eigen::Vector3d(0, ts, 5), v, t - 30 * kMs, t, 0.9f, kGroundTruthSource);
      events.push_back(make_event("TARGETS", targets(t, {tg}), t - kT0 + 1));
      ++targets_sent;
    }
    if (k == 50) {
      events.push_back({t - kT0 + 2, "TARGETS", {0, 1, 2, 3}});  // not a targets_t
      auto nan_target = target(5, Eigen::Vector3d(0, ts, 5), v, t, t);
      nan_target.p_target_in_world[0] = std::numeric_limits<double>::quiet_NaN();
      events.push_back(make_event("TARGETS", targets(t + 1, {nan_target}), t - kT0 + 3));  // fails validation
    }
  }
  TempDir dir;
  const ProcessRun r = run_follower(dir, events);
  ASSERT_EQ(targets_sent, 10);

  std::vector<setpoint_t> velocity, hold;
  for (const auto& s : r.setpoints) (s.mode == kVelocity ? velocity : hold).push_back(s);
  ASSERT_EQ(velocity.size(), 10u) << "one per valid targets_t";
  for (size_t i = 0; i < velocity.size(); ++i) {
    const setpoint_t& s = velocity[i];
    EXPECT_EQ(s.utime, kT0 + (50 + 100 * static_cast<int64_t>(i)) * kMs);
    EXPECT_EQ(s.target_track_id, 5);
    EXPECT_EQ(s.detection_source, kGroundTruthSource);
    EXPECT_EQ(s.frame, kEnuFrame);
    EXPECT_NEAR(s.velocity[0], 0.0, 1e-9);
    EXPECT_NEAR(s.velocity[1], 1.0, 1e-9) << "on station: the target's velocity";
    EXPECT_NEAR(s.velocity[2], 0.0, 1e-9);
    EXPECT_NEAR(s.yaw_rate, 0.0, 1e-9) << "the camera already looks at the target";
  }
  // Last targets at 0.95 s: every own pose after 1.45 s holds, with its own utime.
  ASSERT_EQ(hold.size(), 55u);
  for (size_t i = 0; i < hold.size(); ++i) EXPECT_EQ(hold[i].utime, kT0 + (1460 + 10 * static_cast<int64_t>(i)) * kMs);
  EXPECT_EQ(hold.front().detection_source, kGroundTruthSource);

  ASSERT_GE(r.statuses.size(), 2u);
  bool saw_following = false;
  for (const auto& s : r.statuses)
    saw_following |= s.state == kOk && s.detail == "following track 5 on ground-truth boxes";
  EXPECT_TRUE(saw_following);
  const status_t& before_end = r.statuses[r.statuses.size() - 2];
  EXPECT_EQ(before_end.state, kDegraded);
  EXPECT_EQ(before_end.detail, "holding: no targets_t on TARGETS for 1.050 s of own-pose time (hold.timeout_s = 0.5)");
  const status_t& last = r.statuses.back();
  EXPECT_EQ(last.state, kStopping);
  EXPECT_EQ(last.drops_total, 2) << last.last_error;
  ASSERT_NE(channel(last, "TARGETS"), nullptr);
  EXPECT_EQ(channel(last, "TARGETS")->count, 12);
  EXPECT_EQ(channel(last, "TARGETS")->drops, 2);
  EXPECT_EQ(channel(last, "OWN_POSE")->count, 201);
  EXPECT_EQ(channel(last, "SETPOINT")->count, 65);
}

TEST(FollowerProcess, Pid1dFromAConfigFileMovesTowardsImageRightWithinTheDefaultLimits) {
  // The thesis's set-up: camera looking north, the leader right of the image centre (e = +0.3).
  std::vector<LogEvent> events;
  for (int k = 0; k < 20; ++k) {
    const int64_t t = kT0 + k * 100 * kMs;
    events.push_back(make_event("OWN_POSE", own_pose(t, {0, 0, 5}, M_PI / 2), k * 100000));
    auto d = detections(t, {box(800.0f)});
    d.seq = k;
    if (k == 7) d.detections[0].w = -1;  // fails validation: dropped and counted, no setpoint
    events.push_back(make_event("DETECTIONS_CAM0", d, k * 100000 + 1));
  }
  TempDir dir;
  const ProcessRun r = run_follower(dir, events, "controller:\n  mode: pid_1d\n");
  ASSERT_EQ(r.setpoints.size(), 19u) << r.err;
  // Default limits: the command ramps at 2 m/s^2 from the measured 0 m/s (0.2 m/s per 0.1 s) towards
  // P + I = 7.8 + 0.2 m/s and stops at the 3 m/s speed limit; k = 7 is missing (dropped).
  for (size_t i = 0; i < r.setpoints.size(); ++i) {
    const setpoint_t& s = r.setpoints[i];
    const int k = static_cast<int>(i) + (i >= 7 ? 1 : 0);
    SCOPED_TRACE(testing::Message() << "detections " << k);
    EXPECT_EQ(s.utime, kT0 + k * 100 * kMs);
    EXPECT_EQ(s.mode, kVelocity);
    const double expected = i < 7 ? 0.2 * k : std::min(0.2 * 6 + 0.2 * 2 + 0.2 * (k - 8), 3.0);
    EXPECT_NEAR(s.velocity[0], expected, 1e-9);
    EXPECT_NEAR(s.velocity[1], 0.0, 1e-9);
    EXPECT_EQ(s.detection_source, kCnnSource);
  }
  const status_t& last = r.statuses.back();
  EXPECT_EQ(last.drops_total, 1);
  EXPECT_NE(last.last_error.find("channel DETECTIONS_CAM0: detections_t.detections[0].w x h = -1 x 30"),
            std::string::npos)
      << last.last_error;
  EXPECT_EQ(last.last_processed_seq, 19);
}

}  // namespace
