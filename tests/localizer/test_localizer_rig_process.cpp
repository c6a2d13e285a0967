// SPDX-License-Identifier: MIT
// wingman-localizer with a camera rig (--set cameras.rig=config/rigs/surround4.yaml), file to file (no network): it
// subscribes every rig camera's detections channel, publishes one targets_t per exposure, says per camera how many
// messages came and names a silent camera; a message from a camera not in the rig is dropped and counted.
#include "rig_scene.hpp"
#include "sphere_scene.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <wingman/detections_t.hpp>
#include <wingman/own_pose_t.hpp>
#include <wingman/status_t.hpp>
#include <wingman/targets_t.hpp>
#include <wingman/track_windows_t.hpp>

#include <Eigen/Core>

#include <cmath>
#include <fstream>
#include <map>
#include <string>
#include <vector>

namespace {

using namespace std::chrono_literals;
using wingman::localizer::testing::own_pose;
using wingman::localizer::testing::RigScene;
using wingman::testing::bin_path;
using wingman::testing::LogEvent;
using wingman::testing::make_event;
using wingman::testing::read_log;
using wingman::testing::run;
using wingman::testing::source_path;
using wingman::testing::TempDir;

constexpr int64_t kT0 = 1700000000000000;
constexpr int64_t kFrameUs = 33333;

/// The target circles the vehicle at 8 m, one turn in 12 s (4.2 m/s): every camera sees it in turn.
Eigen::Vector3d circling(int64_t utime) {
  const double a = 0.2 + 2.0 * M_PI * static_cast<double>(utime - kT0) * 1e-6 / 12.0;
  return {8.0 * std::cos(a), 8.0 * std::sin(a), 0.3};
}

struct RigRun {
  std::vector<wingman::targets_t> targets;
  std::map<std::string, int> windows;  ///< track_windows_t per channel
  std::vector<wingman::status_t> statuses;
  std::string err;
};

RigRun run_rig(const TempDir& dir, const std::vector<LogEvent>& events, const std::vector<std::string>& extra = {}) {
  wingman::testing::write_log(dir.file("in.lcmlog"), events);
  std::vector<std::string> args = {bin_path("wingman-localizer"),
                                   "--lcm-in",
                                   "file://" + dir.file("in.lcmlog") + "?speed=0",
                                   "--lcm-out",
                                   "file://" + dir.file("out.lcmlog") + "?mode=w",
                                   "--lockstep",
                                   "--set",
                                   "cameras.rig=" + source_path("config/rigs/surround4.yaml")};
  args.insert(args.end(), extra.begin(), extra.end());
  const auto r = run(args, 30s);
  if (r.exit_code != 0) throw std::runtime_error("localizer failed: " + r.err);
  RigRun out;
  out.err = r.err;
  for (const auto& e : read_log(dir.file("out.lcmlog"))) {
    if (e.channel == "TARGETS") {
      wingman::targets_t t;
      t.decode(e.data.data(), 0, static_cast<int>(e.data.size()));
      out.targets.push_back(t);
    } else if (e.channel == "STATUS_LOCALIZER") {
      wingman::status_t s;
      s.decode(e.data.data(), 0, static_cast<int>(e.data.size()));
      out.statuses.push_back(s);
    } else if (e.channel.rfind("WINDOWS_CAM", 0) == 0) {
      ++out.windows[e.channel];
    }
  }
  return out;
}

/// 12 s: own poses at 100 Hz; each exposure's four detections_t 15-30 ms after it, in an order that changes from frame
/// to frame. Camera `stop_camera` sends nothing after `stop_after_s` (-1: never stops).
std::vector<LogEvent> rig_flight(int* exposures, int stop_camera = -1, double stop_after_s = 0.0) {
  const RigScene scene(wingman::geometry::load_camera_rig(source_path("config/rigs/surround4.yaml")));
  std::vector<LogEvent> events;
  int frame = 0;
  for (int64_t t = 0; t <= 12000000; t += 10000) {
    events.push_back(make_event("OWN_POSE", own_pose(kT0 + t), t));
    if (t % kFrameUs < 10000 && t >= 40000) {
      const int64_t exposure = kT0 + t - 30000;
      const size_t first = static_cast<size_t>(frame % 4);
      for (size_t n = 0; n < 4; ++n) {
        const size_t i = (first + n * (frame % 2 == 0 ? 1 : 3)) % 4;
        if (static_cast<int>(i) == stop_camera && exposure - kT0 > static_cast<int64_t>(stop_after_s * 1e6)) continue;
        wingman::detections_t d = scene.detections(i, exposure, {circling(exposure)});
        d.seq = frame;
        events.push_back(make_event("DETECTIONS_CAM" + std::to_string(i), d, t + static_cast<int64_t>(n)));
      }
      ++frame;
    }
  }
  *exposures = frame;
  return events;
}

TEST(LocalizerRigProcess, EveryRigCameraIsHeardOneTargetsPerExposureOneTrackAround) {
  TempDir dir;
  int exposures = 0;
  const RigRun r = run_rig(dir, rig_flight(&exposures), {"--set", "windows.publish=true"});
  ASSERT_EQ(static_cast<int>(r.targets.size()), exposures) << r.err;
  std::map<int32_t, int> by_camera;
  for (size_t k = 10; k < r.targets.size(); ++k) {
    ASSERT_EQ(r.targets[k].num_targets, 1) << k;
    const wingman::target_t& t = r.targets[k].targets[0];
    EXPECT_EQ(t.track_id, 1) << k;
    ++by_camera[t.camera_id];
    const Eigen::Vector3d p(t.p_target_in_world[0], t.p_target_in_world[1], t.p_target_in_world[2]);
    EXPECT_LT((p - circling(t.predicted_utime)).norm(), 0.3) << k;
  }
  EXPECT_EQ(by_camera.size(), 4u) << "every camera in turn";
  for (int i = 0; i < 4; ++i) EXPECT_EQ(r.windows.at("WINDOWS_CAM" + std::to_string(i)), exposures) << i;
  ASSERT_GE(r.statuses.size(), 2u);
  const wingman::status_t& running = r.statuses[r.statuses.size() - 2];
  EXPECT_EQ(running.state, int{wingman::status_t::STATE_OK}) << running.detail;
  const std::string n = std::to_string(exposures);
  EXPECT_EQ(running.detail, "detections_t per camera: 0 " + n + ", 1 " + n + ", 2 " + n + ", 3 " + n);
  EXPECT_EQ(r.statuses.back().drops_total, 0) << r.statuses.back().last_error;
}

TEST(LocalizerRigProcess, ASilentCameraIsNamedAndAStrangerIsDroppedAndCounted) {
  TempDir dir;
  int exposures = 0;
  // Camera 1 (north) stops at 6 s, when the target has passed it (it is back in view at 13 s).
  std::vector<LogEvent> events = rig_flight(&exposures, 1, 6.0);
  wingman::detections_t stranger{};
  stranger.utime = kT0 + 11900000;
  stranger.camera_id = 6;
  stranger.image_width = 1280;
  stranger.image_height = 720;
  events.push_back(make_event("DETECTIONS_CAM0", stranger, 12100000));
  const RigRun r = run_rig(dir, events);
  ASSERT_EQ(static_cast<int>(r.targets.size()), exposures) << "camera 1's silence stops nobody";
  for (size_t k = 10; k < r.targets.size(); ++k) ASSERT_EQ(r.targets[k].num_targets, 1) << k;
  ASSERT_GE(r.statuses.size(), 2u);
  const wingman::status_t& running = r.statuses[r.statuses.size() - 2];
  EXPECT_EQ(running.state, int{wingman::status_t::STATE_DEGRADED}) << running.detail;
  const std::string n = std::to_string(exposures), half = std::to_string(exposures / 2);
  EXPECT_EQ(running.detail, "camera 1 silent for 6.0 s; detections_t per camera: 0 " + n + ", 1 " + half + ", 2 " + n +
                                ", 3 " + n + " (" + std::to_string(exposures - exposures / 2) + " of " + n +
                                " exposures without every camera)");
  EXPECT_EQ(r.statuses.back().drops_total, 1) << r.statuses.back().last_error;
  EXPECT_NE(r.statuses.back().last_error.find("detections_t.camera_id = 6: not a camera of the rig"), std::string::npos)
      << r.statuses.back().last_error;
}

TEST(LocalizerRigProcess, ABadRigFileIsOneErrorAtStartNamingTheKeyAndTheFile) {
  TempDir dir;
  const std::string bad = dir.file("rig.yaml");
  std::ofstream(bad) << "cameras:\n  - camera: {camera_id: 0, focal_px: 0}\n";
  const auto r = run({bin_path("wingman-localizer"), "--set", "cameras.rig=" + bad}, 10s);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
  EXPECT_NE(r.err.find("cameras.rig = '" + bad + "'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("focal_px"), std::string::npos) << r.err;
}

}  // namespace
