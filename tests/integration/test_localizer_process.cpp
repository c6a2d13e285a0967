// SPDX-License-Identifier: MIT
// wingman-localizer as a process, file to file: a scripted flight gives tracked world positions;
// bad and out-of-order inputs are dropped and counted; without own poses it publishes camera-frame targets.
#include "sphere_scene.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <wingman/detections_t.hpp>
#include <wingman/own_pose_t.hpp>
#include <wingman/status_t.hpp>
#include <wingman/targets_t.hpp>

#include <Eigen/Core>

#include <cmath>
#include <limits>

namespace {

using namespace std::chrono_literals;
using wingman::testing::bin_path;
using wingman::testing::LogEvent;
using wingman::testing::make_event;
using wingman::testing::read_log;
using wingman::testing::run;
using wingman::testing::TempDir;

constexpr int64_t kT0 = 1700000000000000;
// The process's built-in pinhole looking east (default extrinsics, identity body pose), the default radius.
const wingman::localizer::testing::SphereScene kScene{};
using wingman::localizer::testing::detections;
using wingman::localizer::testing::own_pose;

/// Target truth: 10 m east, 1 m north, 0.5 m up of the observer, flying north at 1 m/s.
Eigen::Vector3d target_in_world(int64_t utime) {
  const double t = (utime - kT0) * 1e-6;
  return {10.0, 1.0 + 1.0 * t, 0.5};
}

struct LocalizerRun {
  std::vector<wingman::targets_t> targets;
  wingman::status_t last_status;
  std::vector<wingman::status_t> statuses;  ///< every heartbeat, in order (the last one is last_status)
  std::string err;
};

/// `lockstep`: a heartbeat after every handled message (--lockstep), not only at start and end.
LocalizerRun run_localizer(const TempDir& dir, const std::vector<LogEvent>& events, bool lockstep = false) {
  wingman::testing::write_log(dir.file("in.lcmlog"), events);
  std::vector<std::string> args = {bin_path("wingman-localizer"), "--lcm-in",
                                   "file://" + dir.file("in.lcmlog") + "?speed=0", "--lcm-out",
                                   "file://" + dir.file("out.lcmlog") + "?mode=w"};
  if (lockstep) args.push_back("--lockstep");
  const auto r = run(args, 30s);
  LocalizerRun out;
  out.err = r.err;
  if (r.exit_code != 0) throw std::runtime_error("localizer failed: " + r.err);
  for (const auto& e : read_log(dir.file("out.lcmlog"))) {
    if (e.channel == "TARGETS") {
      wingman::targets_t t;
      t.decode(e.data.data(), 0, static_cast<int>(e.data.size()));
      out.targets.push_back(t);
    } else if (e.channel == "STATUS_LOCALIZER") {
      out.last_status.decode(e.data.data(), 0, static_cast<int>(e.data.size()));
      out.statuses.push_back(out.last_status);
    }
  }
  return out;
}

/// 2 s of flight: own poses at 100 Hz, detections at 30 Hz (each after the poses that bracket it).
std::vector<LogEvent> scripted_flight() {
  std::vector<LogEvent> events;
  int64_t seq = 0;
  for (int64_t t = 0; t <= 2000000; t += 10000) {
    events.push_back(make_event("OWN_POSE", own_pose(kT0 + t), t));
    if (t % 33333 < 10000 && t >= 20000) {
      const int64_t exposure = kT0 + t - 15000;  // the detector reports 15 ms after exposure
      events.push_back(make_event("DETECTIONS_CAM0",
                                  detections(exposure, seq++, {kScene.sphere_box(target_in_world(exposure))}), t));
    }
  }
  return events;
}

TEST(LocalizerProcess, ScriptedFlightGivesOneConfirmedTrackAtTheTruePositionPredictedToTheNewestPose) {
  TempDir dir;
  const LocalizerRun r = run_localizer(dir, scripted_flight());
  ASSERT_FALSE(r.targets.empty()) << r.err;
  const wingman::targets_t& last = r.targets.back();
  ASSERT_EQ(last.num_targets, 1);
  const wingman::target_t& t = last.targets[0];
  EXPECT_EQ(t.track_id, 1);
  EXPECT_TRUE(t.world_valid);
  // Lag compensation: predicted past the image's exposure to the newest own pose.
  EXPECT_GT(t.predicted_utime, t.source_utime);
  EXPECT_EQ(last.utime, t.predicted_utime);
  const Eigen::Vector3d truth = target_in_world(t.predicted_utime);
  const Eigen::Vector3d est(t.p_target_in_world[0], t.p_target_in_world[1], t.p_target_in_world[2]);
  EXPECT_LT((est - truth).norm(), 0.10) << "estimate " << est.transpose() << " truth " << truth.transpose();
  EXPECT_NEAR(t.v_target_in_world[1], 1.0, 0.15);
  EXPECT_NEAR(t.range, target_in_world(t.source_utime).norm(), 0.05);
  EXPECT_EQ(r.last_status.drops_total, 0) << r.last_status.last_error;
}

/// scripted_flight() with every detections_t passed through `edit`; `count` (may be null) gets how many there are.
template <class Edit>
std::vector<LogEvent> scripted_flight_with(Edit edit, int* count) {
  std::vector<LogEvent> events;
  for (const LogEvent& e : scripted_flight()) {
    if (e.channel != "DETECTIONS_CAM0") {
      events.push_back(e);
      continue;
    }
    wingman::detections_t d;
    d.decode(e.data.data(), 0, static_cast<int>(e.data.size()));
    edit(d);
    events.push_back(make_event("DETECTIONS_CAM0", d, e.timestamp));
    if (count != nullptr) ++*count;
  }
  return events;
}

TEST(LocalizerProcess, OneTargetsMessagePerDetectionsEmptyUntilConfirmedWithTheSourceFlagCopied) {
  TempDir dir;
  int n_detections = 0;
  const std::vector<LogEvent> events = scripted_flight_with(
      [](wingman::detections_t& d) { d.source = wingman::detections_t::SOURCE_GROUND_TRUTH; }, &n_detections);
  const LocalizerRun r = run_localizer(dir, events);
  ASSERT_EQ(static_cast<int>(r.targets.size()), n_detections) << r.err;
  // tracker.birth_hits = 10 (confidence 1 >= 0.4): the first nine images give empty targets_t, the tenth a confirmed
  // track.
  ASSERT_GE(r.targets.size(), 10u);
  for (int k = 0; k < 9; ++k) EXPECT_EQ(r.targets[k].num_targets, 0) << k;
  ASSERT_EQ(r.targets[9].num_targets, 1);
  for (const auto& t : r.targets) {
    for (const auto& target : t.targets) {
      EXPECT_EQ(target.detection_source, int{wingman::detections_t::SOURCE_GROUND_TRUTH});
    }
  }
}

TEST(LocalizerProcess, BadBoxesAndMessagesAreDroppedAndCountedNeverFatal) {
  TempDir dir;
  std::vector<LogEvent> events = scripted_flight();
  const int64_t t = kT0 + 500000;
  auto nan_box = kScene.sphere_box(target_in_world(t));
  nan_box.cx = std::numeric_limits<float>::quiet_NaN();
  auto outside = kScene.sphere_box(target_in_world(t));
  outside.cx = 5000;
  events.push_back(
      make_event("DETECTIONS_CAM0", detections(kT0 + 1994000, 900, {nan_box}), 2100000));  // invalid message
  events.push_back(make_event("DETECTIONS_CAM0", detections(kT0 + 1995000, 901, {outside}), 2110000));  // box outside
  events.push_back(
      make_event("DETECTIONS_CAM0", detections(kT0 + 1996000, 902, {outside}, 3), 2120000));  // unknown camera
  events.push_back(make_event("DETECTIONS_CAM0", detections(kT0 + 1000000, 903, {outside}), 2130000));  // out of order
  events.push_back({2140000, "OWN_POSE", {0, 1, 2, 3}});                                                // garbage
  const LocalizerRun r = run_localizer(dir, events);
  EXPECT_EQ(r.last_status.state, int{wingman::status_t::STATE_STOPPING});
  EXPECT_EQ(r.last_status.drops_total, 5) << r.last_status.last_error;
}

TEST(LocalizerProcess, BirdsAreNotTrackedButCountedInTheStatusAndABadDroneScoreIsDropped) {
  TempDir dir;
  // A multi-class model's bird (class 2) beside the drone in every image, more confident than the drone.
  wingman::detection_t bird = kScene.sphere_box(Eigen::Vector3d(8.0, -2.0, 1.0));
  bird.class_id = 2;
  bird.confidence = 0.95f;
  bird.drone_score = 0.02f;
  int n_detections = 0;
  std::vector<LogEvent> events = scripted_flight_with(
      [&bird](wingman::detections_t& d) {
        d.detections.push_back(bird);
        d.num_detections = static_cast<int32_t>(d.detections.size());
      },
      &n_detections);
  auto bad_score = kScene.sphere_box(target_in_world(kT0 + 1994000));
  bad_score.drone_score = 1.5f;
  events.push_back(make_event("DETECTIONS_CAM0", detections(kT0 + 1994000, 900, {bad_score}), 2100000));
  const LocalizerRun r = run_localizer(dir, events, /*lockstep=*/true);
  ASSERT_FALSE(r.targets.empty()) << r.err;
  for (const auto& t : r.targets) EXPECT_LE(t.num_targets, 1) << "the bird became a track";
  const wingman::targets_t& last = r.targets.back();
  ASSERT_EQ(last.num_targets, 1);
  EXPECT_EQ(last.targets[0].track_id, 1);
  EXPECT_NEAR(last.targets[0].p_target_in_world[1], target_in_world(last.targets[0].predicted_utime).y(), 0.10);
  // The birds are counted in the detail of the heartbeats while running (the last one says why it stopped), not
  // as drops; the bad message is the one drop, named.
  ASSERT_GE(r.statuses.size(), 2u);
  const wingman::status_t& running = r.statuses[r.statuses.size() - 2];
  EXPECT_EQ(running.state, int{wingman::status_t::STATE_OK}) << running.detail;
  const std::string n = std::to_string(n_detections);
  EXPECT_EQ(running.detail, "non-drone boxes not tracked: " + n + " (bird " + n + ")");
  EXPECT_EQ(r.last_status.drops_total, 1) << r.last_status.last_error;
  EXPECT_NE(r.last_status.last_error.find("detections_t.detections[0].drone_score = 1.5"), std::string::npos)
      << r.last_status.last_error;
}

TEST(LocalizerProcess, BoxesScoredBelowTheConfidenceBarConfirmNothingAndTheStatusSaysWhy) {
  TempDir dir;
  // A model whose scores sit below tracker.confirm_min_confidence (0.4): the drone is seen in every image at 0.3.
  const std::vector<LogEvent> events = scripted_flight_with(
      [](wingman::detections_t& d) {
        for (auto& b : d.detections) b.confidence = b.drone_score = 0.3f;
      },
      nullptr);
  const LocalizerRun r = run_localizer(dir, events, /*lockstep=*/true);
  ASSERT_FALSE(r.targets.empty()) << r.err;
  for (const auto& t : r.targets) EXPECT_EQ(t.num_targets, 0);
  ASSERT_GE(r.statuses.size(), 2u);
  const wingman::status_t& running = r.statuses[r.statuses.size() - 2];
  EXPECT_EQ(running.state, int{wingman::status_t::STATE_OK}) << running.detail;
  EXPECT_EQ(running.detail,
            "1 tentative track(s) with 10 hits held back: mean confidence of the last 15 below "
            "tracker.confirm_min_confidence 0.4");
  EXPECT_EQ(r.last_status.drops_total, 0) << r.last_status.last_error;
}

TEST(LocalizerProcess, WithoutOwnPosesItPublishesCameraFrameTargetsFlaggedAsSuch) {
  TempDir dir;
  std::vector<LogEvent> events;
  const Eigen::Vector3d p(10.0, 1.0, 0.5);
  events.push_back(make_event("DETECTIONS_CAM0", detections(kT0, 0, {kScene.sphere_box(p)}), 0));
  const LocalizerRun r = run_localizer(dir, events);
  ASSERT_EQ(r.targets.size(), 1u);
  ASSERT_EQ(r.targets[0].num_targets, 1);
  const auto& t = r.targets[0].targets[0];
  EXPECT_FALSE(t.world_valid);
  EXPECT_EQ(t.track_id, 0);
  EXPECT_NEAR(t.p_target_in_cam[0], -1.0, 0.01);
  EXPECT_NEAR(t.p_target_in_cam[1], -0.5, 0.01);
  EXPECT_NEAR(t.p_target_in_cam[2], 10.0, 0.05);
  EXPECT_EQ(r.last_status.drops_total, 1);
  EXPECT_NE(r.last_status.last_error.find("no own pose at detections_t.utime"), std::string::npos)
      << r.last_status.last_error;
}

}  // namespace
