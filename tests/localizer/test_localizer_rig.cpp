// SPDX-License-Identifier: MIT
// Several cameras, one picture (cameras.rig): the localizer fuses the detections_t of one exposure from every rig
// camera into one tracker frame. A target circling the vehicle keeps one track through every hand-over, a target two
// cameras see is one track, the arrival order of the cameras' messages changes nothing, a silent camera stops nobody.
#include "wingman/localizer/localizer.hpp"

#include "rig_scene.hpp"
#include "sphere_scene.hpp"
#include "test_constants.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <wingman/common/config.hpp>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace {

using wingman::localizer::Localizer;
using wingman::localizer::LocalizerOptions;
using wingman::localizer::LocalizerOutput;
using wingman::localizer::testing::own_pose;
using wingman::localizer::testing::RigScene;

using wingman::testing::kFrameUs;  // 30 frames/s
using wingman::testing::kT0;

wingman::geometry::CameraRig surround4() {
  return wingman::geometry::load_camera_rig(wingman::testing::source_path("config/rigs/surround4.yaml"));
}

LocalizerOptions rig_options(const std::string& path) {
  LocalizerOptions o;
  o.cameras.rig = path;
  return o;
}

/// The target circling the vehicle: 8 m from it, 0.3 m up, one turn in `period_s` starting at bearing `start_rad`
/// (east, counter-clockwise: through north).
Eigen::Vector3d circling(int64_t utime, double period_s = 24.0, double start_rad = 0.2) {
  const double a = start_rad + 2.0 * M_PI * static_cast<double>(utime - kT0) * 1e-6 / period_s;
  return {8.0 * std::cos(a), 8.0 * std::sin(a), 0.3};
}

Eigen::Vector3d position(const wingman::target_t& t) {
  return {t.p_target_in_world[0], t.p_target_in_world[1], t.p_target_in_world[2]};
}

/// Every output's encoded targets_t and windows, in order (for comparing two runs byte for byte).
std::vector<std::vector<uint8_t>> encoded(const std::vector<LocalizerOutput>& outputs) {
  std::vector<std::vector<uint8_t>> out;
  const auto add = [&out](const auto& msg) {
    std::vector<uint8_t> b(static_cast<size_t>(msg.getEncodedSize()));
    msg.encode(b.data(), 0, static_cast<int>(b.size()));
    out.push_back(std::move(b));
  };
  for (const LocalizerOutput& o : outputs) {
    for (const auto& w : o.camera_windows) add(w.windows);
    if (o.targets) add(*o.targets);
  }
  return out;
}

/// Feeds `frames` exposures of the circling target to `loc`, each camera's message in the order `order(k)` gives, own
/// poses first; returns every output. Boxes get 0.5 px of edge noise drawn per camera from its own seeded stream, so
/// the order the messages are made in does not change them.
template <class Order>
std::vector<LocalizerOutput> fly_circle(Localizer& loc, const RigScene& scene, int frames, Order order) {
  std::vector<std::mt19937> rng;
  for (size_t i = 0; i < scene.models.size(); ++i) rng.emplace_back(static_cast<unsigned>(100 + i));
  std::vector<LocalizerOutput> outputs;
  for (int k = 0; k < frames; ++k) {
    const int64_t t = kT0 + kFrameUs * k;
    loc.on_own_pose(own_pose(t));
    std::vector<wingman::detections_t> msgs;
    for (size_t i = 0; i < scene.models.size(); ++i)
      msgs.push_back(scene.detections(i, t, {circling(t)}, &rng[i], 0.5));
    for (const size_t i : order(k)) {
      for (LocalizerOutput& o : loc.add_detections(msgs[i])) outputs.push_back(std::move(o));
    }
  }
  return outputs;
}

std::vector<size_t> in_rig_order(int /*frame*/) { return {0, 1, 2, 3}; }

TEST(LocalizerRig, ATargetCirclingTheVehicleKeepsOneTrackThroughEveryHandOver) {
  const RigScene scene(surround4());
  Localizer loc(rig_options(scene.rig.source), scene.rig);
  ASSERT_TRUE(loc.is_rig());
  ASSERT_EQ(loc.cameras().size(), 4u);
  const int frames = 30 * 26;  // one turn in 24 s (2.1 m/s) and a little more: the four hand-overs
  const std::vector<LocalizerOutput> outputs = fly_circle(loc, scene, frames, in_rig_order);
  ASSERT_EQ(static_cast<int>(outputs.size()), frames) << "one output per exposure";
  std::set<int32_t> cameras_used;
  double max_error = 0.0, sum_sq = 0.0;
  int n = 0;
  for (int k = 0; k < frames; ++k) {
    const LocalizerOutput& o = outputs[static_cast<size_t>(k)];
    ASSERT_EQ(o.utime, kT0 + kFrameUs * k);
    EXPECT_TRUE(o.rejections.empty()) << k << ": " << o.rejections.front();
    ASSERT_TRUE(o.targets.has_value());
    if (k < 9) {
      EXPECT_EQ(o.targets->num_targets, 0) << k;  // tracker.birth_hits 10
      continue;
    }
    ASSERT_EQ(o.targets->num_targets, 1) << "frame " << k;
    const wingman::target_t& t = o.targets->targets[0];
    EXPECT_EQ(t.track_id, 1) << "frame " << k;
    EXPECT_TRUE(t.world_valid);
    cameras_used.insert(t.camera_id);
    const double e = (position(t) - circling(t.predicted_utime)).norm();
    max_error = std::max(max_error, e);
    sum_sq += e * e;
    ++n;
  }
  std::printf("circling target: RMS %.4f m, max %.4f m over %d exposures\n", std::sqrt(sum_sq / n), max_error, n);
  EXPECT_EQ(cameras_used, (std::set<int32_t>{0, 1, 2, 3})) << "seen by every camera in turn";
  // 0.5 px of edge noise at 8 m (boxes 56 px wide; measured with libstdc++: RMS 0.030 m, max 0.096 m): twice that.
  EXPECT_LT(std::sqrt(sum_sq / n), 0.06);
  EXPECT_LT(max_error, 0.20);
  EXPECT_EQ(loc.exposure_stats().processed, frames);
  EXPECT_EQ(loc.exposure_stats().incomplete, 0);
  EXPECT_EQ(loc.silent_summary(), "");
  const int f = frames;
  EXPECT_EQ(loc.cameras_summary(), "detections_t per camera: 0 " + std::to_string(f) + ", 1 " + std::to_string(f) +
                                       ", 2 " + std::to_string(f) + ", 3 " + std::to_string(f));
}

TEST(LocalizerRig, TheResultDoesNotDependOnTheOrderTheCamerasMessagesArriveIn) {
  const RigScene scene(surround4());
  const int frames = 30 * 8;  // a third of a turn: two hand-overs
  Localizer in_order(rig_options(scene.rig.source), scene.rig);
  const auto reference = encoded(fly_circle(in_order, scene, frames, in_rig_order));
  for (const unsigned seed : {1u, 2u, 3u}) {
    std::mt19937 shuffle_rng(seed);
    Localizer shuffled(rig_options(scene.rig.source), scene.rig);
    const auto outputs = fly_circle(shuffled, scene, frames, [&](int) {
      std::vector<size_t> order = {0, 1, 2, 3};
      std::shuffle(order.begin(), order.end(), shuffle_rng);
      return order;
    });
    EXPECT_EQ(encoded(outputs), reference) << "seed " << seed;
  }
}

TEST(LocalizerRig, CamerasNotTriggeredTogetherKeepOneTrackThroughEveryHandOver) {
  // Real cameras on one vehicle are seldom triggered together: here camera i exposes a quarter frame after camera
  // i - 1 (t_k + i * 8.3 ms), each message dated by its own exposure, own poses at 120 Hz. Every message is then an
  // exposure of its own (one camera), and a track out of that camera's view must not count it as a miss: the birth
  // rule (10 hits of 15 frames) counts the frames of the cameras that could see the track.
  const RigScene scene(surround4());
  LocalizerOptions o = rig_options(scene.rig.source);
  o.windows.publish = true;
  Localizer loc(o, scene.rig);
  constexpr int64_t kStaggerUs = kFrameUs / 4;
  const int frames = 30 * 26;  // one turn in 24 s and a little more: the four hand-overs
  std::vector<std::mt19937> rng;
  for (size_t i = 0; i < 4; ++i) rng.emplace_back(static_cast<unsigned>(100 + i));
  std::vector<LocalizerOutput> outputs;
  for (int k = 0; k < frames; ++k) {
    for (size_t i = 0; i < 4; ++i) {
      const int64_t t = kT0 + kFrameUs * k + kStaggerUs * static_cast<int64_t>(i);
      loc.on_own_pose(own_pose(t));
      for (LocalizerOutput& o : loc.add_detections(scene.detections(i, t, {circling(t)}, &rng[i], 0.5)))
        outputs.push_back(std::move(o));
    }
  }
  // Each message is processed once the other cameras have sent a later one: all but the last three by the end.
  ASSERT_EQ(static_cast<int>(outputs.size()), 4 * frames - 3);
  std::set<int32_t> cameras_used, track_ids;
  double sum_sq = 0.0, max_error = 0.0;
  int n = 0, first_confirmed = -1;
  for (size_t j = 0; j < outputs.size(); ++j) {
    const LocalizerOutput& o = outputs[j];
    if (j > 0) {
      ASSERT_GT(o.utime, outputs[j - 1].utime) << "processed in time order";
    }
    EXPECT_TRUE(o.rejections.empty()) << j << ": " << o.rejections.front();
    // Windows for the exposure's one camera, for its own next exposure (a frame period on).
    const int32_t camera = static_cast<int32_t>(((o.utime - kT0) % kFrameUs) / kStaggerUs);
    ASSERT_EQ(o.camera_windows.size(), 1u) << j;
    EXPECT_EQ(o.camera_windows[0].windows.camera_id, camera) << j;
    if (j >= 4) {
      EXPECT_EQ(o.camera_windows[0].windows.utime_predicted, o.utime + kFrameUs) << j;
    }
    ASSERT_TRUE(o.targets.has_value());
    if (o.targets->num_targets == 0) {
      EXPECT_EQ(first_confirmed, -1) << "output " << j << ": the track was lost after it was confirmed";
      continue;
    }
    if (first_confirmed < 0) first_confirmed = static_cast<int>(j);
    ASSERT_EQ(o.targets->num_targets, 1) << "output " << j;
    const wingman::target_t& t = o.targets->targets[0];
    track_ids.insert(t.track_id);
    cameras_used.insert(t.camera_id);
    const double e = (position(t) - circling(t.predicted_utime)).norm();
    max_error = std::max(max_error, e);
    sum_sq += e * e;
    ++n;
  }
  std::printf("cameras not triggered together: confirmed at output %d (%.2f s), RMS %.4f m, max %.4f m over %d\n",
              first_confirmed,
              static_cast<double>(outputs[static_cast<size_t>(std::max(first_confirmed, 0))].utime - kT0) * 1e-6,
              std::sqrt(sum_sq / std::max(n, 1)), max_error, n);
  ASSERT_GE(first_confirmed, 0) << "never confirmed";
  // One camera sees the target at a time: its 10th hit comes with its 10th frame, 9 frame periods after the first.
  EXPECT_LT(outputs[static_cast<size_t>(first_confirmed)].utime - kT0, 12 * kFrameUs);
  EXPECT_EQ(track_ids, (std::set<int32_t>{1})) << "one track id through every hand-over";
  EXPECT_EQ(cameras_used, (std::set<int32_t>{0, 1, 2, 3}));
  EXPECT_LT(std::sqrt(sum_sq / n), 0.06);  // as with the cameras triggered together
  EXPECT_LT(max_error, 0.20);
}

TEST(LocalizerRig, AnExposureIsProcessedWhenItsLastCameraIsInNotBefore) {
  // Lockstep: the simulator waits for the setpoint of frame k (one per targets_t) before it renders frame k + 1.
  const RigScene scene(surround4());
  LocalizerOptions o = rig_options(scene.rig.source);
  o.windows.publish = true;
  Localizer loc(o, scene.rig);
  for (int k = 0; k < 20; ++k) {
    const int64_t t = kT0 + kFrameUs * k;
    loc.on_own_pose(own_pose(t));
    const std::vector<size_t> order = k % 2 == 0 ? std::vector<size_t>{3, 1, 0, 2} : std::vector<size_t>{2, 0, 1, 3};
    for (size_t n = 0; n < order.size(); ++n) {
      const auto out = loc.add_detections(scene.detections(order[n], t, {circling(t)}));
      if (n + 1 < order.size()) {
        EXPECT_TRUE(out.empty()) << "frame " << k << ": published before camera " << order.back();
        continue;
      }
      ASSERT_EQ(out.size(), 1u) << "frame " << k;
      EXPECT_EQ(out[0].utime, t);
      ASSERT_TRUE(out[0].targets.has_value());
      // Windows for every rig camera on its own channel, in rig order.
      ASSERT_EQ(out[0].camera_windows.size(), 4u);
      for (size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(out[0].camera_windows[i].channel, "WINDOWS_CAM" + std::to_string(i));
        EXPECT_EQ(out[0].camera_windows[i].windows.camera_id, static_cast<int32_t>(i));
      }
      EXPECT_FALSE(out[0].windows.has_value()) << "one camera's field";
    }
  }
}

TEST(LocalizerRig, WindowsGoToTheCameraThatWillSeeTheTrackOnly) {
  const RigScene scene(surround4());
  LocalizerOptions o = rig_options(scene.rig.source);
  o.windows.publish = true;
  Localizer loc(o, scene.rig);
  const Eigen::Vector3d p(1.0, 9.0, 0.5);  // north: camera 1's view (yaw 90)
  std::vector<LocalizerOutput> last;
  for (int k = 0; k < 12; ++k) {
    const int64_t t = kT0 + kFrameUs * k;
    loc.on_own_pose(own_pose(t));
    for (size_t i = 0; i < 4; ++i) last = loc.add_detections(scene.detections(i, t, {p}));
  }
  ASSERT_EQ(last.size(), 1u);
  const auto& windows = last[0].camera_windows;
  ASSERT_EQ(windows.size(), 4u);
  for (size_t i = 0; i < 4; ++i) EXPECT_EQ(windows[i].windows.num_windows, i == 1 ? 1 : 0) << "camera " << i;
  const wingman::track_window_t& w = windows[1].windows.windows[0];
  EXPECT_EQ(w.track_id, 1);
  const auto truth = scene.box(1, p);
  ASSERT_TRUE(truth.has_value());
  EXPECT_NEAR(w.cx, truth->cx, 1.0);
  EXPECT_NEAR(w.cy, truth->cy, 1.0);
  EXPECT_NEAR(w.w, truth->w, 1.0);  // ground-truth boxes: the sphere box itself
}

/// A rig file of two cameras looking east and 30 degrees north of east (60 degrees of overlap), written to `dir`.
std::string overlapping_pair(const wingman::testing::TempDir& dir) {
  const std::string path = dir.file("pair.yaml");
  std::ofstream(path) << "cameras:\n"
                         "  - camera: {camera_id: 4, width: 1280, height: 720, focal_px: 640}\n"
                         "    mount: {yaw_deg: 0}\n"
                         "    extrinsics: {p_cam_in_body: [0.1, -0.05, 0.0]}\n"
                         "  - camera: {camera_id: 7, width: 1280, height: 720, focal_px: 640}\n"
                         "    mount: {yaw_deg: 30}\n"
                         "    extrinsics: {p_cam_in_body: [0.1, 0.05, 0.0]}\n";
  return path;
}

TEST(LocalizerRig, ATargetTwoCamerasSeeIsOneTrack) {
  wingman::testing::TempDir dir;
  const RigScene scene(wingman::geometry::load_camera_rig(overlapping_pair(dir)));
  // A CNN's boxes wander: 2 px of edge noise (about 0.3 m along the line of sight at 10 m), each camera its own.
  std::mt19937 rng(7);
  LocalizerOptions o = rig_options(scene.rig.source);
  o.sphere.edge_noise_px = 2.0;  // the covariance says so
  Localizer loc(o, scene.rig);
  std::set<int32_t> ids, cameras;
  int published = 0;
  for (int k = 0; k < 300; ++k) {
    const int64_t t = kT0 + kFrameUs * k;
    const double s = static_cast<double>(t - kT0) * 1e-6;
    const Eigen::Vector3d p(10.0 * std::cos(0.26), 10.0 * std::sin(0.26) + 0.5 * std::sin(s), 0.2);  // in both views
    ASSERT_TRUE(scene.box(0, p) && scene.box(1, p));
    loc.on_own_pose(own_pose(t));
    std::vector<LocalizerOutput> out = loc.add_detections(scene.detections(1, t, {p}, &rng, 2.0));
    EXPECT_TRUE(out.empty());
    out = loc.add_detections(scene.detections(0, t, {p}, &rng, 2.0));
    ASSERT_EQ(out.size(), 1u);
    for (const wingman::target_t& target : out[0].targets->targets) {
      ids.insert(target.track_id);
      cameras.insert(target.camera_id);
      EXPECT_LT((position(target) - p).norm(), 0.5) << k;
      ++published;
    }
  }
  EXPECT_EQ(ids, (std::set<int32_t>{1})) << "one track";
  EXPECT_EQ(cameras, (std::set<int32_t>{7})) << "the last camera in rig order that saw it";
  EXPECT_EQ(published, 300 - 9);  // every frame from the tenth on
}

TEST(LocalizerRig, ASilentCameraStopsNobodyAndIsNamedUntilItSendsAgain) {
  const RigScene scene(surround4());
  Localizer loc(rig_options(scene.rig.source), scene.rig);  // cameras.silent_after_s 0.2
  const Eigen::Vector3d p(9.0, 1.0, 0.5);                   // camera 0's view
  std::vector<int64_t> processed;
  const auto send = [&](size_t camera, int64_t t) {
    for (const LocalizerOutput& o : loc.add_detections(scene.detections(camera, t, {p}))) processed.push_back(o.utime);
  };
  const int64_t t_last_2 = kT0 + kFrameUs * 29;  // camera 2's last message
  for (int k = 0; k < 60; ++k) {
    const int64_t t = kT0 + kFrameUs * k;
    loc.on_own_pose(own_pose(t));
    for (const size_t i : {0, 1, 2, 3})
      if (i != 2 || t <= t_last_2) send(i, t);
    // Until camera 2 has been silent 0.2 s, an exposure waits for it until the others have sent the next one; then
    // it is not waited for.
    const int64_t silent_s = t - t_last_2;
    if (t <= t_last_2) {
      ASSERT_EQ(processed.back(), t) << k;
    } else if (silent_s <= 200000) {
      ASSERT_EQ(processed.back(), t - kFrameUs) << k;
    } else {
      ASSERT_EQ(processed.back(), t) << k;
      EXPECT_NE(loc.silent_summary().find("camera 2 silent for "), std::string::npos) << k;
    }
  }
  ASSERT_EQ(processed.size(), 60u);
  for (size_t k = 1; k < processed.size(); ++k) EXPECT_EQ(processed[k] - processed[k - 1], kFrameUs);
  EXPECT_EQ(loc.silent_summary(), "camera 2 silent for 1.0 s");  // 30 frames of 1/30 s
  EXPECT_EQ(loc.exposure_stats().incomplete, 30);
  EXPECT_EQ(loc.exposure_stats().late, 0);
  // It sends again: waited for again.
  const int64_t t = kT0 + kFrameUs * 60;
  loc.on_own_pose(own_pose(t));
  send(2, t);
  EXPECT_EQ(loc.silent_summary(), "");
  for (const size_t i : {0, 1}) send(i, t);
  EXPECT_EQ(processed.back(), t - kFrameUs);
  send(3, t);
  EXPECT_EQ(processed.back(), t);
  EXPECT_EQ(loc.exposure_stats().incomplete, 30);
}

TEST(LocalizerRig, ACameraThatNeverSentIsSilentAfterTheStatedTimeFromTheFirstMessage) {
  const RigScene scene(surround4());
  LocalizerOptions o = rig_options(scene.rig.source);
  o.cameras.silent_after_s = 0.5;
  Localizer loc(o, scene.rig);
  for (int k = 0; k < 20; ++k) {
    const int64_t t = kT0 + kFrameUs * k;
    loc.on_own_pose(own_pose(t));
    for (const size_t i : {0, 1, 2}) (void)loc.add_detections(scene.detections(i, t, {}));
  }
  EXPECT_EQ(loc.silent_summary(), "camera 3 silent for 0.6 s (no message yet)");
  EXPECT_EQ(loc.exposure_stats().processed, 20);
}

TEST(LocalizerRig, ALateMessageIsDroppedNamingItsCameraAndThePendingExposuresAreBounded) {
  const RigScene scene(surround4());
  LocalizerOptions o = rig_options(scene.rig.source);
  o.cameras.max_pending = 3;
  o.cameras.silent_after_s = 10.0;
  Localizer loc(o, scene.rig);
  // Cameras 1-3 are one exposure behind camera 0 ... until camera 0 is three ahead: the oldest goes without them.
  std::vector<int64_t> processed;
  for (int k = 0; k < 6; ++k) {
    const int64_t t = kT0 + kFrameUs * k;
    loc.on_own_pose(own_pose(t));
    for (const LocalizerOutput& out : loc.add_detections(scene.detections(0, t, {}))) processed.push_back(out.utime);
  }
  EXPECT_EQ(processed, (std::vector<int64_t>{kT0, kT0 + kFrameUs, kT0 + 2 * kFrameUs}));
  EXPECT_EQ(loc.exposure_stats().overflowed, 3);
  try {
    (void)loc.add_detections(scene.detections(1, kT0 + kFrameUs, {}));
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(
        std::string(e.what()).find("detections_t.utime = " + std::to_string(kT0 + kFrameUs) + ": camera 1 is late"),
        std::string::npos)
        << e.what();
  }
  EXPECT_EQ(loc.exposure_stats().late, 1);
}

TEST(LocalizerRig, WhenTimeGoesBackForEveryInputTheRigRestartsWithinTheResyncTime) {
  // A restarted source: own poses and every camera jump 100 s back. Refused (out of order) for time.resync_after_s of
  // their own time, then the own pose re-anchors the clock, and the rig starts again: new tracks, one per exposure.
  const RigScene scene(surround4());
  Localizer loc(rig_options(scene.rig.source), scene.rig);
  const Eigen::Vector3d p(9.0, 1.0, 0.5);
  const int64_t back = kT0 - 100000000;
  int refused = 0;
  std::vector<LocalizerOutput> outputs;
  for (int k = 0; k < 120; ++k) {
    const int64_t t = k < 30 ? kT0 + kFrameUs * k : back + kFrameUs * k;
    try {
      loc.on_own_pose(own_pose(t));
    } catch (const std::invalid_argument&) {
      ++refused;
    }
    for (size_t i = 0; i < 4; ++i) {
      try {
        for (LocalizerOutput& o : loc.add_detections(scene.detections(i, t, {p}))) outputs.push_back(std::move(o));
      } catch (const std::invalid_argument&) {
        ++refused;
      }
    }
  }
  EXPECT_GT(refused, 0);
  ASSERT_GT(outputs.size(), 60u);
  EXPECT_EQ(outputs.back().utime, back + kFrameUs * 119) << "one output per exposure again";
  for (size_t k = outputs.size() - 40; k < outputs.size(); ++k) {
    EXPECT_EQ(outputs[k].utime - outputs[k - 1].utime, kFrameUs);
    ASSERT_EQ(outputs[k].targets->num_targets, 1) << k;
    EXPECT_EQ(outputs[k].targets->targets[0].track_id, 1) << "a new tracker";
  }
  bool noted = false;
  for (const std::string& n : loc.take_notes()) noted = noted || n.find("the tracker restarts") != std::string::npos;
  EXPECT_TRUE(noted);
}

TEST(LocalizerRig, AMessageOfACameraNotInTheRigOrOfAnotherSizeIsDroppedNamingTheField) {
  const RigScene scene(surround4());
  Localizer loc(rig_options(scene.rig.source), scene.rig);
  loc.on_own_pose(own_pose(kT0));
  wingman::detections_t stranger = scene.detections(0, kT0, {});
  stranger.camera_id = 5;
  try {
    (void)loc.add_detections(stranger);
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "detections_t.camera_id = 5: not a camera of the rig " + scene.rig.source + " (cameras.rig: 0, 1, 2, 3)");
  }
  wingman::detections_t small = scene.detections(2, kT0, {});
  small.image_width = 640;
  small.image_height = 360;
  EXPECT_THROW((void)loc.add_detections(small), std::invalid_argument);
  EXPECT_EQ(loc.cameras()[2].messages, 0);
  EXPECT_THROW((void)loc.on_detections(scene.detections(0, kT0, {})), std::logic_error) << "a rig takes add_detections";
  // camera.scale_to_image applies to every rig camera.
  LocalizerOptions scaled = rig_options(scene.rig.source);
  scaled.camera.scale_to_image = true;
  Localizer loc2(scaled, scene.rig);
  EXPECT_NO_THROW((void)loc2.add_detections(small));
  EXPECT_EQ(loc2.cameras()[2].camera.width(), 640);
}

TEST(LocalizerRig, ABoxThatCannotBeLocalizedIsDroppedOnItsCamerasChannel) {
  const RigScene scene(surround4());
  Localizer loc(rig_options(scene.rig.source), scene.rig);
  loc.on_own_pose(own_pose(kT0));
  std::vector<LocalizerOutput> out;
  for (size_t i = 0; i < 4; ++i) {
    wingman::detections_t d = scene.detections(i, kT0, {});
    if (i == 2) d.detections.push_back(wingman::detection_t{}), d.num_detections = 1;  // w = h = 0
    out = loc.add_detections(d);
  }
  ASSERT_EQ(out.size(), 1u);
  ASSERT_EQ(out[0].rejections.size(), 1u);
  EXPECT_EQ(out[0].rejections[0].rfind("camera 2: detections_t.detections[0]: ", 0), 0u) << out[0].rejections[0];
  EXPECT_EQ(out[0].rejection_channels, (std::vector<std::string>{"DETECTIONS_CAM2"}));
}

TEST(LocalizerRig, WithoutAnOwnPoseEachCamerasBoxesAreCameraFrameTargetsNamingTheCamera) {
  const RigScene scene(surround4());
  Localizer loc(rig_options(scene.rig.source), scene.rig);
  const Eigen::Vector3d north(0.0, 10.0, 0.0), south(0.0, -6.0, 0.0);  // cameras 1 and 3
  std::vector<LocalizerOutput> out;
  for (size_t i = 0; i < 4; ++i) out = loc.add_detections(scene.detections(i, kT0, {north, south}));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(out[0].camera_frame_only);
  ASSERT_TRUE(out[0].targets.has_value());
  ASSERT_EQ(out[0].targets->num_targets, 2);
  const wingman::target_t& a = out[0].targets->targets[0];
  const wingman::target_t& b = out[0].targets->targets[1];
  EXPECT_EQ(a.camera_id, 1);
  EXPECT_EQ(b.camera_id, 3);
  EXPECT_FALSE(a.world_valid);
  EXPECT_EQ(a.track_id, 0);
  EXPECT_NEAR(a.p_target_in_cam[2], 10.0 - 0.1, 0.05);  // the camera sits 0.1 m out along its axis
  EXPECT_NEAR(b.p_target_in_cam[2], 6.0 - 0.1, 0.05);
}

TEST(LocalizerRig, ARigOfTheDefaultCameraGivesWhatTheOneCameraGives) {
  wingman::testing::TempDir dir;
  const std::string path = dir.file("one.yaml");
  std::ofstream(path) << "cameras:\n  - camera: {camera_id: 0}\n";
  const RigScene scene(wingman::geometry::load_camera_rig(path));
  Localizer rig(rig_options(path), scene.rig);
  Localizer one(LocalizerOptions{}, scene.models[0]);
  std::mt19937 rng(3);
  for (int k = 0; k < 40; ++k) {
    const int64_t t = kT0 + kFrameUs * k;
    rig.on_own_pose(own_pose(t));
    one.on_own_pose(own_pose(t));
    const wingman::detections_t d = scene.detections(0, t, {{12.0, 0.1 * k, 1.0}}, &rng, 1.0);
    const std::vector<LocalizerOutput> a = rig.add_detections(d);
    const LocalizerOutput b = one.on_detections(d);
    ASSERT_EQ(a.size(), 1u);
    EXPECT_EQ(encoded(a), encoded({b})) << k;
  }
}

TEST(LocalizerRig, TheKeysAreValidatedAndABadRigFileIsOneErrorNamingTheKeyAndTheFile) {
  LocalizerOptions o;
  EXPECT_TRUE(o.validate().empty()) << "the defaults: one camera";
  o.cameras.silent_after_s = 0.0;
  o.cameras.max_pending = 0;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 2u);
  EXPECT_NE(p[0].find("cameras.silent_after_s = 0"), std::string::npos) << p[0];
  EXPECT_NE(p[1].find("cameras.max_pending = 0"), std::string::npos) << p[1];

  wingman::testing::TempDir dir;
  const std::string bad = dir.file("bad.yaml");
  std::ofstream(bad) << "cameras:\n  - camera: {camera_id: 1, focal_px: -3}\n  - camera: {camera_id: 1}\n";
  std::string all;
  try {
    (void)wingman::common::load_options_from_string<LocalizerOptions>("cameras: {rig: " + bad + "}\n",
                                                                      "localizer.yaml");
  } catch (const wingman::common::ConfigError& e) {
    all = e.what();
  }
  EXPECT_NE(all.find("cameras.rig = '" + bad + "'"), std::string::npos) << all;
  EXPECT_NE(all.find("camera.focal_px"), std::string::npos) << all;
  EXPECT_NE(all.find("camera_id"), std::string::npos) << all;
  EXPECT_THROW((void)Localizer::from_options(rig_options(dir.file("missing.yaml"))), wingman::common::ConfigError);
  EXPECT_TRUE(rig_options(wingman::testing::source_path("config/rigs/surround4.yaml")).validate().empty());
  try {
    Localizer loc(o, surround4());
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cameras.max_pending = 0"), std::string::npos) << e.what();
  }
}

}  // namespace
