// SPDX-License-Identifier: MIT
// Localizer (without LCM): only drones (class 0) are localized and tracked; boxes of the multi-class model's other
// classes are left out and counted per class, never rejected.
#include "wingman/localizer/localizer.hpp"

#include "sphere_scene.hpp"
#include "test_constants.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace {

using wingman::geometry::CameraModel;
using wingman::localizer::Localizer;
using wingman::localizer::LocalizerOptions;
using wingman::localizer::LocalizerOutput;
using wingman::localizer::NonDroneCounts;
using wingman::testing::kT0;

// A pinhole with its principal point at the image centre, looking east; the default radius.
const wingman::localizer::testing::SphereScene kScene{640, 639.5, 359.5, 0.348};
using wingman::localizer::testing::detections;
using wingman::localizer::testing::own_pose;

CameraModel camera() { return CameraModel::pinhole(1280, 720, kScene.f, kScene.f, kScene.cx, kScene.cy); }

constexpr int16_t kAirplane = 1, kBird = 2;

TEST(Localizer, BoxesOfOtherClassesAreNotTrackedAndAreCountedPerClassNotRejected) {
  Localizer loc(LocalizerOptions{}, camera());
  const Eigen::Vector3d p_drone(10.0, 1.0, 0.5), p_bird(8.0, -2.0, 1.0), p_airplane(20.0, 3.0, 2.0);
  LocalizerOutput out;
  for (int k = 0; k < 12; ++k) {  // tracker.birth_hits (10) and more
    const int64_t t = kT0 + 33333 * k;
    loc.on_own_pose(own_pose(t));
    out = loc.on_detections(detections(
        t, 0,
        {kScene.sphere_box(p_bird, kBird), kScene.sphere_box(p_drone), kScene.sphere_box(p_airplane, kAirplane)}));
    EXPECT_TRUE(out.rejections.empty()) << out.rejections.front();
    EXPECT_EQ(out.non_drone.total, 2);
    EXPECT_EQ(out.non_drone.by_class, (std::map<int, int64_t>{{kAirplane, 1}, {kBird, 1}}));
  }
  // One confirmed track, on the drone: the bird and the airplane never became one.
  ASSERT_TRUE(out.targets.has_value());
  ASSERT_EQ(out.targets->num_targets, 1);
  const wingman::target_t& t = out.targets->targets[0];
  const Eigen::Vector3d est(t.p_target_in_world[0], t.p_target_in_world[1], t.p_target_in_world[2]);
  EXPECT_LT((est - p_drone).norm(), 0.05) << est.transpose();  // exact boxes of a still target: no noise
  const NonDroneCounts& total = loc.non_drone_boxes();
  EXPECT_EQ(total.total, 24);
  EXPECT_EQ(total.by_class, (std::map<int, int64_t>{{kAirplane, 12}, {kBird, 12}}));
  EXPECT_EQ(total.summary(), "non-drone boxes not tracked: 24 (airplane 12, bird 12)");
}

TEST(Localizer, OnlyNonDroneBoxesGiveNoTargetEvenInTheCameraFrame) {
  Localizer loc(LocalizerOptions{}, camera());
  // No own pose: camera-frame targets would be published for drones (publish_camera_frame_only), none for a bird.
  const LocalizerOutput no_pose = loc.on_detections(detections(kT0, 0, {kScene.sphere_box({10.0, 0.0, 0.0}, kBird)}));
  ASSERT_TRUE(no_pose.targets.has_value());
  EXPECT_EQ(no_pose.targets->num_targets, 0);
  EXPECT_EQ(no_pose.non_drone.total, 1);
  for (int k = 1; k <= 6; ++k) {
    const int64_t t = kT0 + 33333 * k;
    loc.on_own_pose(own_pose(t));
    const LocalizerOutput out = loc.on_detections(detections(t, 0, {kScene.sphere_box({10.0, 0.0, 0.0}, kBird)}));
    EXPECT_TRUE(out.rejections.empty());
    ASSERT_TRUE(out.targets.has_value());  // output.publish_empty: one targets_t per detections_t
    EXPECT_EQ(out.targets->num_targets, 0) << "frame " << k;
  }
  EXPECT_EQ(loc.non_drone_boxes().summary(), "non-drone boxes not tracked: 7 (bird 7)");
}

TEST(Localizer, ANonDroneBoxIsCountedBeforeItsGeometryIsLookedAt) {
  Localizer loc(LocalizerOptions{}, camera());
  loc.on_own_pose(own_pose(kT0));
  wingman::detection_t outside = kScene.sphere_box({10.0, 0.0, 0.0}, 7);  // a class the model card does not name
  outside.cx = 5000.0f;                                                   // outside the image: a drone here is rejected
  const LocalizerOutput out = loc.on_detections(detections(kT0, 0, {outside}));
  EXPECT_TRUE(out.rejections.empty()) << out.rejections.front();
  EXPECT_EQ(loc.non_drone_boxes().summary(), "non-drone boxes not tracked: 1 (class 7 1)");
  // The same box as a drone is a rejection, not a count.
  outside.class_id = 0;
  const LocalizerOutput drone = loc.on_detections(detections(kT0 + 33333, 0, {outside}));
  EXPECT_EQ(drone.rejections.size(), 1u);
  EXPECT_EQ(drone.non_drone.total, 0);
}

TEST(Localizer, DecidedPerTrackADroneThatSomeFramesCallABirdIsConfirmedAndABirdIsNot) {
  // A distant drone: every other frame the model's best class is bird (confidence 0.6) with a drone score of 0.45;
  // a real bird: class bird, drone score 0.05. Per box (the default) the drone has 6 drone boxes in 12 frames, short
  // of the birth rule's 10; per track it has 12 hits with a mean drone score of (0.9 + 0.45) / 2 >= 0.4 (the
  // confirmation bar), and the bird's 0.05 never reaches it.
  const Eigen::Vector3d p_drone(10.0, 1.0, 0.5), p_bird(8.0, -2.0, 1.0);
  for (const std::string decision : {"box", "track"}) {
    LocalizerOptions o;
    o.class_decision = decision;
    Localizer loc(o, camera());
    LocalizerOutput out;
    for (int k = 0; k < 12; ++k) {
      const int64_t t = kT0 + 33333 * k;
      loc.on_own_pose(own_pose(t));
      wingman::detection_t drone = kScene.sphere_box(p_drone);
      if (k % 2 == 1) drone.class_id = kBird, drone.confidence = 0.6f, drone.drone_score = 0.45f;
      out = loc.on_detections(detections(t, 0, {kScene.sphere_box(p_bird, kBird), drone}));
      EXPECT_TRUE(out.rejections.empty()) << out.rejections.front();
    }
    ASSERT_TRUE(out.targets.has_value());
    if (decision == "box") {
      EXPECT_EQ(out.targets->num_targets, 0) << "6 drone boxes in 12 frames: not confirmed";
      EXPECT_EQ(loc.non_drone_boxes().summary(), "non-drone boxes not tracked: 18 (bird 18)");
      continue;
    }
    ASSERT_EQ(out.targets->num_targets, 1) << "the drone, not the bird";
    const wingman::target_t& t = out.targets->targets[0];
    EXPECT_LT(
        (Eigen::Vector3d(t.p_target_in_world[0], t.p_target_in_world[1], t.p_target_in_world[2]) - p_drone).norm(),
        0.05);
    EXPECT_EQ(loc.non_drone_boxes().summary(), "non-drone boxes tracked by their drone score: 18 (bird 18)");
  }
}

TEST(LocalizerOptions, AnUnknownClassDecisionIsNamed) {
  LocalizerOptions o;
  o.class_decision = "frame";
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NE(p[0].find("classes.decision"), std::string::npos) << p[0];
}

TEST(NonDroneCounts, SummaryIsEmptyWithoutNonDroneBoxes) { EXPECT_EQ(NonDroneCounts{}.summary(), ""); }

}  // namespace

TEST(Localizer, CnnBoxesGoThroughTheBoxRelationGroundTruthBoxesAreTheSpheres) {
  // The same exact sphere box: as ground truth it gives the true range; as the shipped model's box (SOURCE_CNN) it
  // stands for a larger sphere box (the model's boxes are smaller than the sphere's), so the target is nearer.
  const Eigen::Vector3d p(10.0, 1.0, 0.5);
  const auto camera_range = [&](int8_t source, const std::string& model_id) {
    LocalizerOptions o;
    o.tracker.birth_hits = 1;
    Localizer loc(o, camera());
    loc.on_own_pose(own_pose(kT0));
    wingman::detections_t d = detections(kT0, 0, {kScene.sphere_box(p)});
    d.source = source;
    d.model_id = model_id;
    const LocalizerOutput out = loc.on_detections(d);
    EXPECT_TRUE(out.targets && out.targets->num_targets == 1);
    return out.targets ? out.targets->targets[0].range : 0.0;
  };
  EXPECT_NEAR(camera_range(wingman::detections_t::SOURCE_GROUND_TRUTH, ""), p.norm(), 0.01);  // float boxes
  const double cnn = camera_range(wingman::detections_t::SOURCE_CNN, "");
  EXPECT_LT(cnn, 0.95 * p.norm());
  EXPECT_GT(cnn, 0.5 * p.norm());
}

TEST(Localizer, AWindowsBoxGoesThroughTheWindowGridOtherBoxesThroughTheMainGrid) {
  // A relation whose boxes are 0.7 of the sphere's in the main grid and 0.9 in the window grid: the same box stands
  // for a sphere box 1 / 0.7 as large from the single pass, 1 / 0.9 from a window, so its range is 0.9 / 0.7 as far.
  const std::string path = ::testing::TempDir() + "window_grid.boxes.yaml";
  {
    std::ofstream f(path);
    f << "box_relation:\n  size_edges: [0.001, 1.0]\n  aspect_edges: [0.01, 100]\n  width_ratio: [0.7]\n"
         "  height_ratio: [0.7]\n  range_sigma_rel: [0.1]\n  window:\n    size_edges: [1, 2000]\n"
         "    aspect_edges: [0.01, 100]\n    width_ratio: [0.9]\n    height_ratio: [0.9]\n    range_sigma_rel: [0.2]\n";
  }
  const Eigen::Vector3d p(10.0, 1.0, 0.5);
  const auto range_of = [&](int8_t pass_kind) {
    LocalizerOptions o;
    o.sphere.box_relation = path;
    o.tracker.birth_hits = 1;
    Localizer loc(o, camera());
    loc.on_own_pose(own_pose(kT0));
    wingman::detections_t d = detections(kT0, 0, {kScene.sphere_box(p)});
    d.source = wingman::detections_t::SOURCE_CNN;
    d.detections[0].pass_kind = pass_kind;
    const LocalizerOutput out = loc.on_detections(d);
    EXPECT_TRUE(out.targets && out.targets->num_targets == 1);
    return out.targets ? out.targets->targets[0].range : 0.0;
  };
  const double single = range_of(wingman::detection_t::PASS_SINGLE);
  const double zoom_in = range_of(wingman::detection_t::PASS_ZOOM_IN);
  const double window = range_of(wingman::detection_t::PASS_WINDOW);
  EXPECT_NEAR(single, 0.7 * p.norm(), 0.01);
  EXPECT_NEAR(zoom_in, single, 1e-9);  // a zoom-in box: the main grid
  EXPECT_NEAR(window / single, 0.9 / 0.7, 0.002);
  std::remove(path.c_str());
}

TEST(Localizer, DetectionsOfAModelTheBoxRelationWasNotMeasuredForAreDroppedNamingBoth) {
  Localizer loc(LocalizerOptions{}, camera());
  wingman::detections_t d = detections(kT0, 0, {kScene.sphere_box({10.0, 1.0, 0.5})});
  d.source = wingman::detections_t::SOURCE_CNN;
  d.model_id = "sha256:ffffffffffffffff";
  try {
    loc.on_detections(d);
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("detections_t.model_id = 'sha256:ffffffffffffffff'"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("builtin:wingman-small"), std::string::npos);
  }
}
