// SPDX-License-Identifier: MIT
// Weighted box fusion: hand-computed groups, the rules (one box per view per group, strict IoU threshold, half
// confidence for a box one view found), invariants on seeded random boxes, and the horizontal mirror.
#include <wingman/detector/box_fusion.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

namespace wingman::detector {
namespace {

Box box(float cx, float cy, float w, float h, float confidence, bool refined = false) {
  return Box{cx, cy, w, h, confidence, refined ? Pass::kZoomIn : Pass::kSingle};
}

TEST(FuseBoxes, ClassOfTheMostConfidentMemberAndMeanDroneScore) {
  // View 0 calls it a bird (class 2) at 0.8 with drone score 0.1; view 1 a drone at 0.6 (drone score 0.6); a third box
  // only view 1 found, a helicopter at 0.4 with drone score 0.05. Views 0 and 1 of 2.
  Box bird = box(100, 50, 40, 20, 0.8f), drone = box(102, 50, 40, 20, 0.6f), heli = box(300, 200, 10, 10, 0.4f);
  bird.class_id = 2, bird.drone_score = 0.1f;
  drone.class_id = 0, drone.drone_score = 0.6f;
  heli.class_id = 3, heli.drone_score = 0.05f;
  std::vector<ViewBox> in = {{drone, 1}, {bird, 0}, {heli, 1}};
  std::vector<Box> out;
  fuse_boxes(in, 2, 0.3f, out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].class_id, 2);                 // the more confident member's class
  EXPECT_NEAR(out[0].drone_score, 0.35f, 1e-6);  // (0.1 + 0.6) / 2
  EXPECT_NEAR(out[0].confidence, 0.7f, 1e-6);    // (0.8 + 0.6) / 2
  EXPECT_EQ(out[1].class_id, 3);
  EXPECT_NEAR(out[1].drone_score, 0.025f, 1e-6);  // one view of two: half
  // With per-view minimum sizes (the coarse pass): the 10 px box is below view 0's 20 px, so only view 1 sees it.
  std::vector<ViewBox> again = {{drone, 1}, {bird, 0}, {heli, 1}};
  fuse_boxes(again, std::vector<float>{20.0f, 0.0f}, 0.3f, out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NEAR(out[1].drone_score, 0.05f, 1e-6);
  EXPECT_NEAR(out[1].confidence, 0.4f, 1e-6);
}

TEST(FuseBoxes, HandComputedPairAndASingleViewBox) {
  // View 0: a drone at (100, 50) 40x20, 0.8, and a box elsewhere at 0.5. View 1: the drone at (104, 52) 44x20, 0.6
  // (IoU with the first: 0.71).
  std::vector<ViewBox> in = {
      {box(100, 50, 40, 20, 0.8f), 0}, {box(300, 200, 10, 10, 0.5f), 0}, {box(104, 52, 44, 20, 0.6f, true), 1}};
  std::vector<Box> out;
  fuse_boxes(in, 2, 0.3f, out);
  ASSERT_EQ(out.size(), 2u);
  // Weighted means: cx = (0.8 x 100 + 0.6 x 104) / 1.4 = 101.714, cy = (0.8 x 50 + 0.6 x 52) / 1.4 = 50.857,
  // w = (0.8 x 40 + 0.6 x 44) / 1.4 = 41.714, h = 20; confidence (0.8 + 0.6) / 2 = 0.7.
  EXPECT_NEAR(out[0].cx, 101.7143f, 1e-3);
  EXPECT_NEAR(out[0].cy, 50.8571f, 1e-3);
  EXPECT_NEAR(out[0].w, 41.7143f, 1e-3);
  EXPECT_NEAR(out[0].h, 20.0f, 1e-4);
  EXPECT_NEAR(out[0].confidence, 0.7f, 1e-6);
  EXPECT_EQ(out[0].pass, Pass::kZoomIn);  // one member was refined
  // Found by one view of two: its box, half its confidence.
  EXPECT_FLOAT_EQ(out[1].cx, 300.0f);
  EXPECT_FLOAT_EQ(out[1].w, 10.0f);
  EXPECT_NEAR(out[1].confidence, 0.25f, 1e-6);
  EXPECT_EQ(out[1].pass, Pass::kSingle);
  // The input is left most confident first.
  EXPECT_FLOAT_EQ(in[0].box.confidence, 0.8f);
  EXPECT_FLOAT_EQ(in[1].box.confidence, 0.6f);
  EXPECT_FLOAT_EQ(in[2].box.confidence, 0.5f);
}

TEST(FuseBoxes, TwoBoxesOfOneViewNeverFuse) {
  std::vector<ViewBox> in = {{box(100, 50, 40, 20, 0.8f), 0}, {box(101, 50, 40, 20, 0.7f), 0}};
  std::vector<Box> out;
  fuse_boxes(in, 2, 0.3f, out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NEAR(out[0].confidence, 0.4f, 1e-6);
  EXPECT_NEAR(out[1].confidence, 0.35f, 1e-6);
}

TEST(FuseBoxes, JoinsTheGroupItOverlapsMostAboveTheThreshold) {
  // Two view-0 groups, 10x10 boxes at x 4 and 8; the view-1 box at x 10 overlaps both: [5, 15] against [-1, 9]
  // (40 of 160: IoU 0.25) and against [3, 13] (80 of 120: IoU 0.667). It joins the second.
  std::vector<ViewBox> in = {{box(4, 0, 10, 10, 0.9f), 0}, {box(8, 0, 10, 10, 0.8f), 0}, {box(10, 0, 10, 10, 0.5f), 1}};
  std::vector<Box> out;
  fuse_boxes(in, 2, 0.1f, out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NEAR(out[0].confidence, 0.45f, 1e-6);  // alone
  EXPECT_FLOAT_EQ(out[0].cx, 4.0f);
  EXPECT_NEAR(out[1].confidence, 0.65f, 1e-6);  // (0.8 + 0.5) / 2
  EXPECT_NEAR(out[1].cx, (0.8f * 8 + 0.5f * 10) / 1.3f, 1e-4);
  // The threshold is strict: at IoU 0.667 exactly the two stay apart; just under it they fuse.
  std::vector<ViewBox> apart = {{box(8, 0, 10, 10, 0.8f), 0}, {box(10, 0, 10, 10, 0.5f), 1}};
  fuse_boxes(apart, 2, iou(apart[0].box, apart[1].box), out);
  EXPECT_EQ(out.size(), 2u);
  fuse_boxes(apart, 2, 0.66f, out);
  EXPECT_EQ(out.size(), 1u);
}

TEST(FuseBoxes, OneViewIsTheIdentity) {
  std::vector<ViewBox> in = {{box(10, 10, 4, 4, 0.3f), 0}, {box(50, 10, 4, 4, 0.6f), 0}};
  std::vector<Box> out;
  fuse_boxes(in, 1, 0.3f, out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_FLOAT_EQ(out[0].cx, 50.0f);  // most confident first
  EXPECT_FLOAT_EQ(out[0].confidence, 0.6f);
  EXPECT_FLOAT_EQ(out[1].confidence, 0.3f);
}

TEST(FuseBoxes, SeededRandomBoxesKeepTheirConfidenceMassAndOneBoxPerViewPerGroup) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> pos(0.0f, 200.0f), size(5.0f, 60.0f), conf(0.0f, 1.0f);
  std::uniform_int_distribution<int> view(0, 2);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<ViewBox> in;
    double mass = 0.0;
    for (int k = 0; k < 30; ++k) {
      in.push_back({box(pos(rng), pos(rng), size(rng), size(rng), conf(rng)), view(rng)});
      mass += in.back().box.confidence;
    }
    std::vector<Box> out;
    fuse_boxes(in, 3, 0.3f, out);
    double fused_mass = 0.0;
    for (const Box& b : out) {
      fused_mass += b.confidence;
      EXPECT_LE(b.confidence, 1.0f + 1e-6f);  // at most one box per view: at most the mean of three <= 1
      EXPECT_GE(b.w, 5.0f - 1e-3f);           // a weighted mean of sizes in [5, 60]
      EXPECT_LE(b.w, 60.0f + 1e-3f);
    }
    EXPECT_NEAR(fused_mass * 3.0, mass, 1e-3) << "trial " << trial;
    EXPECT_GE(out.size() * 3, in.size()) << "a group holds at most one box of each of the 3 views";
  }
}

TEST(FuseBoxes, RejectsBadArguments) {
  std::vector<Box> out;
  std::vector<ViewBox> in = {{box(1, 1, 1, 1, 0.5f), 2}};
  EXPECT_THROW(fuse_boxes(in, 2, 0.3f, out), std::invalid_argument);  // view 2 of views 0..1
  in[0].view = 0;
  EXPECT_THROW(fuse_boxes(in, 0, 0.3f, out), std::invalid_argument);
  EXPECT_THROW(fuse_boxes(in, 33, 0.3f, out), std::invalid_argument);
  EXPECT_THROW(fuse_boxes(in, 2, 1.5f, out), std::invalid_argument);
  EXPECT_NO_THROW(fuse_boxes(in, 2, 0.3f, out));
}

TEST(FuseBoxes, PerViewMinimumSizesCountOnlyTheViewsThatSeeABoxThatSize) {
  // Views 0 and 1 see every size, views 2 and 3 (a coarse pass and its mirror) boxes of sqrt(w h) >= 50 only.
  //  - a small drone (20x20) both fine views found at 0.6 and 0.4: (0.6 + 0.4) / 2 = 0.5, the coarse views do not
  //    count (with 4 views throughout it would be 0.25);
  //  - a large one (100x80, sqrt 89.4) only the coarse views found, 0.8 and 0.6: (0.8 + 0.6) / 4 = 0.35;
  //  - a large one all four found at 0.9, 0.7, 0.5, 0.3: 2.4 / 4 = 0.6.
  std::vector<ViewBox> in = {{box(30, 30, 20, 20, 0.6f), 0},    {box(31, 30, 20, 20, 0.4f), 1},
                             {box(300, 200, 100, 80, 0.8f), 2}, {box(302, 200, 100, 80, 0.6f), 3},
                             {box(600, 300, 120, 90, 0.9f), 0}, {box(602, 300, 120, 90, 0.7f), 1},
                             {box(598, 302, 120, 90, 0.5f), 2}, {box(600, 298, 120, 90, 0.3f), 3}};
  std::vector<Box> out;
  fuse_boxes(in, std::vector<float>{0, 0, 50, 50}, 0.3f, out);
  ASSERT_EQ(out.size(), 3u);
  // Groups in the order they started: the 0.9 box, the 0.8 box, the 0.6 box.
  EXPECT_NEAR(out[0].confidence, 0.6f, 1e-6);
  EXPECT_NEAR(out[0].cx, (0.9f * 600 + 0.7f * 602 + 0.5f * 598 + 0.3f * 600) / 2.4f, 1e-3);
  EXPECT_NEAR(out[1].confidence, 0.35f, 1e-6);
  EXPECT_NEAR(out[1].cx, (0.8f * 300 + 0.6f * 302) / 1.4f, 1e-3);
  EXPECT_NEAR(out[2].confidence, 0.5f, 1e-6);
  EXPECT_NEAR(out[2].cx, 30.4f, 1e-4);
  // All zeros is the view-count overload.
  std::vector<Box> plain;
  fuse_boxes(in, std::vector<float>(4, 0.0f), 0.3f, out);
  fuse_boxes(in, 4, 0.3f, plain);
  ASSERT_EQ(out.size(), plain.size());
  for (size_t i = 0; i < out.size(); ++i) {
    EXPECT_FLOAT_EQ(out[i].cx, plain[i].cx);
    EXPECT_FLOAT_EQ(out[i].confidence, plain[i].confidence);
  }
  EXPECT_NEAR(out[2].confidence, 0.25f, 1e-6);
  // A group holding more views than see its size (a fused box below a coarse view's minimum) counts its own views.
  std::vector<ViewBox> shrunk = {{box(30, 30, 40, 40, 0.5f), 0}, {box(30, 30, 60, 60, 0.5f), 2}};
  fuse_boxes(shrunk, std::vector<float>{0, 0, 55, 55}, 0.3f, out);
  ASSERT_EQ(out.size(), 1u);  // 50x50, below 55: one view sees it, two hold it
  EXPECT_NEAR(out[0].confidence, 0.5f, 1e-6);
  for (const float bad : {-1.0f, std::nanf(""), INFINITY})
    EXPECT_THROW(fuse_boxes(in, std::vector<float>{0, 0, bad, 50}, 0.3f, out), std::invalid_argument) << bad;
  EXPECT_THROW(fuse_boxes(in, std::vector<float>{0, 0}, 0.3f, out), std::invalid_argument);  // a box of view 2
}

TEST(MirrorHorizontally, MirrorsTheCentreAndKeepsTheRest) {
  const Box m = mirror_horizontally(box(100, 50, 40, 20, 0.8f, true), 640.0f);
  EXPECT_FLOAT_EQ(m.cx, 540.0f);
  EXPECT_FLOAT_EQ(m.cy, 50.0f);
  EXPECT_FLOAT_EQ(m.w, 40.0f);
  EXPECT_FLOAT_EQ(m.h, 20.0f);
  EXPECT_FLOAT_EQ(m.confidence, 0.8f);
  EXPECT_EQ(m.pass, Pass::kZoomIn);
  // A box flush with the left border ([0, 40]) mirrors to one flush with the right ([600, 640]).
  EXPECT_FLOAT_EQ(mirror_horizontally(box(20, 5, 40, 10, 0.5f), 640.0f).cx, 620.0f);
}

}  // namespace
}  // namespace wingman::detector
