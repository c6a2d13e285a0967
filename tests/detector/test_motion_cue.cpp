// SPDX-License-Identifier: MIT
// The motion cue: a small thing moving against a panning, textured background is found where it is now (not where it
// was), a still scene gives nothing, boxes already found and large blobs are left out, and a gap starts again.
#include <gtest/gtest.h>
#include <wingman/detector/motion_cue.hpp>

#include <opencv2/imgproc.hpp>

#include <cmath>

namespace wingman::detector {
namespace {

constexpr int64_t kFrameUs = 33333;  // 30 Hz

/// A cloudy sky with a treeline: smooth random texture (fixed seed), larger than the frames cut from it.
cv::Mat background() {
  cv::Mat noise(1100, 1800, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::Mat smooth;
  cv::GaussianBlur(noise, smooth, cv::Size(0, 0), 6.0);
  cv::normalize(smooth, smooth, 60, 220, cv::NORM_MINMAX);
  smooth.rowRange(760, 1100).setTo(cv::Scalar(40));  // the treeline: a dark band
  cv::Mat bgr;
  cv::cvtColor(smooth, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

/// Frame k: the background panned by (pan_x, pan_y) px per frame (sub-pixel), with sensor noise (fixed seed), and a
/// dark `dot` px square centred at `dot_at(k)` when dot > 0.
cv::Mat frame(const cv::Mat& bg, int k, double pan_x, double pan_y, int dot, cv::Point2d dot_at) {
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, -250 - pan_x * k, 0, 1, -190 - pan_y * k);
  cv::Mat f;
  cv::warpAffine(bg, f, m, cv::Size(1280, 720), cv::INTER_LINEAR);
  cv::Mat noise(f.size(), CV_16SC3);
  cv::RNG rng(100 + k);
  rng.fill(noise, cv::RNG::NORMAL, 0, 2);
  cv::Mat with_noise;
  f.convertTo(with_noise, CV_16SC3);
  with_noise += noise;
  with_noise.convertTo(f, CV_8UC3);
  if (dot > 0) {
    cv::rectangle(f, cv::Rect(static_cast<int>(dot_at.x) - dot / 2, static_cast<int>(dot_at.y) - dot / 2, dot, dot),
                  cv::Scalar(20, 20, 20), cv::FILLED);
  }
  return f;
}

/// Lag 1: this frame against the two before (the dot below moves 12 px a frame).
MotionOptions lag1() {
  MotionOptions o;
  o.lag_frames = 1;
  return o;
}

cv::Point2d dot_path(int k) { return {400.0 + 12.0 * k, 300.0 + 3.0 * k}; }

TEST(MotionCue, FindsASmallMoverWhereItIsNowWhileTheCameraPans) {
  const cv::Mat bg = background();
  MotionCue cue(lag1());
  for (int k = 0; k < 8; ++k) {
    const auto blobs = cue.find(frame(bg, k, 3.3, -1.2, 10, dot_path(k)), k * kFrameUs, {});
    if (k < 3) {  // two earlier frames to compare with, and a blob near it in the frame before
      EXPECT_TRUE(blobs.empty()) << "frame " << k;
      continue;
    }
    ASSERT_EQ(blobs.size(), 1u) << "frame " << k;
    EXPECT_NEAR(blobs[0].cx, dot_path(k).x, 8.0) << "frame " << k;
    EXPECT_NEAR(blobs[0].cy, dot_path(k).y, 8.0) << "frame " << k;
    EXPECT_GT(blobs[0].difference, 50);
  }
  EXPECT_EQ(cue.stats().compared, 6);
  EXPECT_EQ(cue.stats().windows, 5);
  EXPECT_EQ(cue.stats().restarts, 0);
}

TEST(MotionCue, ASlowFarMoverNeedsALongerLag) {
  // 1.6 px a frame (a drone crossing at 3 m/s 40 m away, 640 px focal length): 0.4 resized pixels, inside the
  // neighbourhood's tolerance from one frame to the next; ten frames apart it has moved 4 resized pixels.
  const cv::Mat bg = background();
  const auto slow = [](int k) { return cv::Point2d(500.0 + 1.6 * k, 300.0); };
  MotionCue one(lag1()), ten(MotionOptions{});  // the default lag, 10
  ASSERT_EQ(MotionOptions{}.lag_frames, 10);
  int found1 = 0, found10 = 0;
  for (int k = 0; k < 40; ++k) {
    const cv::Mat f = frame(bg, k, 1.5, 0.5, 10, slow(k));
    found1 += static_cast<int>(one.find(f, k * kFrameUs, {}).size());
    for (const MotionBlob& b : ten.find(f, k * kFrameUs, {})) {
      ++found10;
      EXPECT_NEAR(b.cx, slow(k).x, 8.0) << "frame " << k;
      EXPECT_NEAR(b.cy, slow(k).y, 8.0) << "frame " << k;
    }
  }
  EXPECT_EQ(found1, 0);
  EXPECT_GE(found10, 15);  // of the 19 frames from frame 21 on (20 before to compare with, one to repeat)
}

TEST(MotionCue, AStillOrPanningSceneWithoutAMoverGivesNothing) {
  const cv::Mat bg = background();
  for (const double pan : {0.0, 1.3, -5.5}) {
    MotionCue cue1(lag1()), cue10(MotionOptions{});
    for (int k = 0; k < 30; ++k) {
      const cv::Mat f = frame(bg, k, pan, 0.7 * pan, 0, {});
      EXPECT_TRUE(cue1.find(f, k * kFrameUs, {}).empty()) << "lag 1, pan " << pan << ", frame " << k;
      EXPECT_TRUE(cue10.find(f, k * kFrameUs, {}).empty()) << "lag 10, pan " << pan << ", frame " << k;
    }
    EXPECT_EQ(cue1.stats().compared, 28);
    EXPECT_EQ(cue10.stats().compared, 10);
  }
}

TEST(MotionCue, BoxesAlreadyFoundLargeBlobsAndTheBorderAreLeftOut) {
  const cv::Mat bg = background();
  // The same mover, once with a box already on it: left out (and found without the box, the control).
  MotionCue cue(lag1()), control(lag1());
  for (int k = 0; k < 6; ++k) {
    Box found;
    found.cx = static_cast<float>(dot_path(k).x);
    found.cy = static_cast<float>(dot_path(k).y);
    found.w = found.h = 20;
    const cv::Mat f = frame(bg, k, 1.0, 0.0, 10, dot_path(k));
    EXPECT_TRUE(cue.find(f, k * kFrameUs, {found}).empty()) << k;
    EXPECT_EQ(control.find(f, k * kFrameUs, {}).size(), k < 3 ? 0u : 1u) << k;
  }
  // A mover of 60 x 60 px (15 resized pixels tall > max_blob_side_px 8): near, the single pass's.
  MotionCue large(lag1());
  for (int k = 0; k < 6; ++k)
    EXPECT_TRUE(large.find(frame(bg, k, 1.0, 0.0, 60, dot_path(k)), k * kFrameUs, {}).empty()) << k;
  // At the left edge (within border_px of the resized frame).
  MotionCue edge(lag1());
  for (int k = 0; k < 6; ++k) {
    EXPECT_TRUE(edge.find(frame(bg, k, 0.0, 0.0, 6, {6.0, 200.0 + 8.0 * k}), k * kFrameUs, {}).empty()) << k;
  }
}

TEST(MotionCue, AGapOrAnotherFrameSizeStartsAgainAndTheSameFramesGiveTheSameBlobs) {
  const cv::Mat bg = background();
  MotionCue cue(lag1());
  std::vector<MotionBlob> first;
  for (int k = 0; k < 4; ++k) first = cue.find(frame(bg, k, 2.0, 0.0, 10, dot_path(k)), k * kFrameUs, {});
  ASSERT_EQ(first.size(), 1u);
  // 0.5 s later: too far from the frames before (max_gap_s 0.25): two new frames are needed.
  EXPECT_TRUE(cue.find(frame(bg, 4, 2.0, 0.0, 10, dot_path(4)), 3 * kFrameUs + 500000, {}).empty());
  EXPECT_EQ(cue.stats().restarts, 1);
  cv::Mat small;
  cv::resize(frame(bg, 5, 2.0, 0.0, 10, dot_path(5)), small, cv::Size(640, 360));
  EXPECT_TRUE(cue.find(small, 3 * kFrameUs + 533333, {}).empty());
  EXPECT_EQ(cue.stats().restarts, 2);
  // Deterministic: another cue on the same frames gives the same blobs, to the bit.
  MotionCue again(lag1());
  std::vector<MotionBlob> second;
  for (int k = 0; k < 4; ++k) second = again.find(frame(bg, k, 2.0, 0.0, 10, dot_path(k)), k * kFrameUs, {});
  ASSERT_EQ(second.size(), 1u);
  EXPECT_EQ(second[0].cx, first[0].cx);
  EXPECT_EQ(second[0].cy, first[0].cy);
  EXPECT_EQ(second[0].difference, first[0].difference);
  // The windows carry the blob and sigma_px.
  MotionCue w(lag1());
  std::vector<Window> windows;
  for (int k = 0; k < 4; ++k) windows = w.windows(frame(bg, k, 2.0, 0.0, 10, dot_path(k)), k * kFrameUs, {});
  ASSERT_EQ(windows.size(), 1u);
  EXPECT_EQ(windows[0].cx, first[0].cx);
  EXPECT_EQ(windows[0].sigma_px, MotionOptions{}.sigma_px);
}

TEST(MotionCue, AFeaturelessSkyStillFindsTheMover) {
  // A flat grey sky with sensor noise: nothing to align on, so the last step (none) stands and the mover is found.
  const cv::Mat sky(1100, 1800, CV_8UC3, cv::Scalar(180, 170, 160));
  MotionCue cue(lag1());
  int found = 0;
  for (int k = 0; k < 8; ++k) {
    for (const MotionBlob& b : cue.find(frame(sky, k, 0.0, 0.0, 10, dot_path(k)), k * kFrameUs, {})) {
      ++found;
      EXPECT_NEAR(b.cx, dot_path(k).x, 8.0) << "frame " << k;
    }
  }
  EXPECT_EQ(found, 5);
  EXPECT_GT(cue.stats().unaligned, 0);
  EXPECT_EQ(cue.stats().restarts, 0);
}

TEST(MotionCue, OptionsNameTheKey) {
  MotionOptions o;
  o.scale = 0.0;
  o.min_difference = 0;
  o.max_windows = 0;
  o.max_shift_fraction = 0.9;
  const auto problems = o.validate();
  ASSERT_EQ(problems.size(), 4u);
  EXPECT_EQ(problems[0].rfind("motion.scale = 0", 0), 0u) << problems[0];
  EXPECT_EQ(problems[1].rfind("motion.min_difference = 0", 0), 0u) << problems[1];
  EXPECT_EQ(problems[2].rfind("motion.max_windows = 0", 0), 0u) << problems[2];
  EXPECT_EQ(problems[3].rfind("motion.max_shift_fraction = 0.9", 0), 0u) << problems[3];
  EXPECT_THROW(MotionCue{o}, std::invalid_argument);
  EXPECT_TRUE(MotionOptions{}.validate().empty());
}

}  // namespace
}  // namespace wingman::detector
