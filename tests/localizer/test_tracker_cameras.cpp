// SPDX-License-Identifier: MIT
// Tracker::update_cameras: one frame of several cameras. A target two cameras see starts one track and counts one hit
// per frame; cameras with nothing change nothing; most_confident keeps the frame's one most confident detection.
#include <gtest/gtest.h>
#include <wingman/localizer/tracker.hpp>

#include "test_constants.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

namespace {

using wingman::localizer::FrameViews;
using wingman::localizer::Tracker;
using wingman::localizer::TrackerOptions;
using wingman::localizer::TrackOutput;
using wingman::localizer::WorldMeasurement;

using wingman::testing::kFrameUs;
using wingman::testing::kT0;

int64_t frame_utime(int k) { return kT0 + kFrameUs * k; }

WorldMeasurement meas(const Eigen::Vector3d& p, int camera, double sigma = 0.2, double confidence = 0.9) {
  WorldMeasurement m;
  m.camera_id = camera;
  m.p_target_in_world = p;
  m.cov_p_in_world = sigma * sigma * Eigen::Matrix3d::Identity();
  m.p_target_in_cam = p;
  m.range = p.norm();
  m.confidence = confidence;
  return m;
}

TEST(TrackerCameras, ATargetTwoCamerasSeeStartsOneTrackAndCountsOneHitPerFrame) {
  Tracker t;  // birth_hits 10
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 0.2);
  const Eigen::Vector3d p(8.0, 3.0, 0.5);
  const auto noisy = [&]() -> Eigen::Vector3d {
    const double x = n(rng), y = n(rng), z = n(rng);
    return p + Eigen::Vector3d(x, y, z);
  };
  for (int k = 0; k < 9; ++k) {
    ASSERT_TRUE(t.update_cameras(frame_utime(k), {{meas(noisy(), 0)}, {meas(noisy(), 1)}}));
    EXPECT_TRUE(t.confirmed(frame_utime(k)).empty()) << "two cameras in one frame are one hit, frame " << k;
  }
  ASSERT_TRUE(t.update_cameras(frame_utime(9), {{meas(noisy(), 0)}, {meas(noisy(), 1)}}));
  const std::vector<TrackOutput> out = t.confirmed(frame_utime(9));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].track_id, 1);
  EXPECT_EQ(out[0].camera_id, 1) << "the camera of the last detection used";
  EXPECT_EQ(t.stats().births, 1) << "camera 1's first detection joined the track camera 0's started";
  EXPECT_EQ(t.stats().associated, 19);
  EXPECT_EQ(t.num_tentative(), 0u);
  // 20 detections of 0.2 m per axis, but the velocity is still nearly free after 0.3 s: a sanity bound.
  EXPECT_LT((out[0].p_target_in_world - p).norm(), 0.5);
}

TEST(TrackerCameras, AFrameOfACameraThatCouldNotSeeTheTrackIsNoMiss) {
  // Frames alternate between a camera that sees the target (east) and one that looks west: with could_see the west
  // camera's frames leave the track's count alone, so 10 hits in the east camera's 10 frames confirm it; without,
  // they are misses, and 10 hits never fall within 15 frames.
  const Eigen::Vector3d p(8.0, 0.0, 0.5);
  const auto east_only = [](const Eigen::Vector3d& q) { return q.x() > 0; };
  const auto west_only = [](const Eigen::Vector3d& q) { return q.x() < 0; };
  for (const bool with_view : {true, false}) {
    Tracker t;  // birth_hits 10 of birth_window 15
    for (int k = 0; k < 40; ++k) {
      const bool east = k % 2 == 0;
      std::vector<std::vector<WorldMeasurement>> frame(1);
      if (east) frame[0].push_back(meas(p, 0));
      FrameViews views;
      if (with_view) views.could_see = east ? std::function<bool(const Eigen::Vector3d&)>(east_only) : west_only;
      ASSERT_TRUE(t.update_cameras(frame_utime(k), frame, nullptr, views));
      if (with_view && k == 18) {
        ASSERT_EQ(t.confirmed(frame_utime(k)).size(), 1u) << "the 10th hit, the east camera's 10th frame";
      } else if (with_view && k < 18) {
        EXPECT_TRUE(t.confirmed(frame_utime(k)).empty()) << k;
      }
    }
    if (with_view) {
      EXPECT_EQ(t.confirmed(frame_utime(39)).size(), 1u);
      EXPECT_EQ(t.stats().out_of_view, 20) << "the west camera's 20 frames";
      EXPECT_EQ(t.stats().births, 1);
    } else {
      EXPECT_TRUE(t.confirmed(frame_utime(39)).empty()) << "every other frame a miss: 8 hits of 15 at most";
      EXPECT_EQ(t.stats().out_of_view, 0);
    }
  }
}

TEST(TrackerCameras, TwoConfirmedTracksAgreeOnlyWhenTheirStatesDo) {
  // agree(): one target followed twice (merge_chi2), which the Localizer's occlusion rule leaves alone. Two drones
  // 3 m apart are confirmed; then the second flies onto the first at 1 m/s and stays there (merges kept off): their
  // tracks come to agree; a third drone 20 m away agrees with neither.
  TrackerOptions o;
  o.merge_after_s = 100.0;  // no merge within the test
  Tracker t(o);
  const Eigen::Vector3d a(8.0, 0.0, 0.5), far(8.0, 20.0, 0.5);
  const auto b = [&](int k) {  // 3 m north of a until frame 15, then onto it in 3 s (1 m/s)
    const double along = std::clamp((k - 15) / 90.0, 0.0, 1.0);
    return Eigen::Vector3d(a + Eigen::Vector3d(0.0, 3.0 * (1.0 - along), 0.0));
  };
  std::vector<int32_t> ids;  // the tracks on a and b once both are confirmed (frame 12), and the far one's
  const auto nearest = [&](const std::vector<TrackOutput>& out, const Eigen::Vector3d& p) {
    int32_t id = 0;
    double best = 1e9;
    for (const TrackOutput& x : out)
      if ((x.p_target_in_world - p).norm() < best) best = (x.p_target_in_world - p).norm(), id = x.track_id;
    return id;
  };
  for (int k = 0; k < 200; ++k) {
    const int64_t u = frame_utime(k);
    ASSERT_TRUE(t.update_cameras(u, {{meas(a, 0, 0.1), meas(b(k), 0, 0.1), meas(far, 0, 0.1)}}));
    if (k == 12) {
      const std::vector<TrackOutput> out = t.confirmed(u);
      ASSERT_EQ(out.size(), 3u);
      ids = {nearest(out, a), nearest(out, b(k)), nearest(out, far)};
      EXPECT_FALSE(t.agree(ids[0], ids[1])) << "3 m apart";
    }
  }
  EXPECT_TRUE(t.agree(ids[0], ids[1])) << "one drone followed twice for 3 s";
  EXPECT_FALSE(t.agree(ids[0], ids[2]));
  EXPECT_FALSE(t.agree(ids[0], ids[0])) << "a track with itself";
  EXPECT_FALSE(t.agree(ids[0], 99)) << "an unknown id";
}

TEST(TrackerCameras, ATrackOneCameraLosesAndTheNextTakesLivesOn) {
  TrackerOptions o;
  o.birth_hits = 3;
  o.birth_window = 5;
  o.death_timeout_s = 0.2;
  Tracker t(o);
  // Camera 0 sees it for 10 frames, then camera 1 for 20: each frame is a hit for the one track.
  for (int k = 0; k < 30; ++k) {
    const Eigen::Vector3d p(8.0, 0.1 * k, 0.0);
    std::vector<std::vector<WorldMeasurement>> frame(2);
    frame[k < 10 ? 0 : 1].push_back(meas(p, k < 10 ? 0 : 1));
    ASSERT_TRUE(t.update_cameras(frame_utime(k), frame));
  }
  const std::vector<TrackOutput> out = t.confirmed(frame_utime(29));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].track_id, 1);
  EXPECT_EQ(out[0].camera_id, 1);
  EXPECT_EQ(t.stats().births, 1);
}

TEST(TrackerCameras, CamerasWithNothingChangeNothing) {
  Tracker one, three;
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 0.3);
  for (int k = 0; k < 40; ++k) {
    const double x = n(rng), y = n(rng), z = n(rng);
    const Eigen::Vector3d p(10.0 + 0.05 * k + x, 2.0 + y, 1.0 + z);
    ASSERT_TRUE(one.update(frame_utime(k), {meas(p, 0, 0.3)}));
    ASSERT_TRUE(three.update_cameras(frame_utime(k), {{}, {meas(p, 0, 0.3)}, {}}));
  }
  const auto a = one.confirmed(frame_utime(40)), b = three.confirmed(frame_utime(40));
  ASSERT_EQ(a.size(), 1u);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(a[0].p_target_in_world, b[0].p_target_in_world);  // bit for bit
  EXPECT_EQ(a[0].cov_p, b[0].cov_p);
  std::string why;
  EXPECT_FALSE(three.update_cameras(frame_utime(39), {{}, {}, {}}, &why));
  EXPECT_NE(why.find("is not after the previous frame's"), std::string::npos) << why;
}

TEST(TrackerCameras, MostConfidentKeepsTheFramesOneMostConfidentDetection) {
  TrackerOptions o;
  o.mode = "most_confident";
  o.birth_hits = 1;
  o.birth_window = 1;
  Tracker t(o);
  ASSERT_TRUE(t.update_cameras(frame_utime(0), {{meas({5, 0, 0}, 0, 0.2, 0.5)}, {meas({0, 9, 0}, 1, 0.2, 0.8)}}));
  const auto out = t.confirmed(frame_utime(0));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].camera_id, 1);
  EXPECT_EQ(t.stats().measurements_rejected, 1);
}

}  // namespace
