// SPDX-License-Identifier: MIT
// Tracker-driven windows (issue 31): a track predicted into the next image, against the exact sphere box of where the
// target will be, and the Localizer publishing them.
#include "wingman/localizer/localizer.hpp"
#include "wingman/localizer/track_windows.hpp"

#include "sphere_scene.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>

#include <cmath>
#include <vector>

namespace {

using wingman::geometry::CameraModel;
using wingman::localizer::BoxRelation;
using wingman::localizer::CameraAtExposure;
using wingman::localizer::Localizer;
using wingman::localizer::LocalizerOptions;
using wingman::localizer::predict_track_window;
using wingman::localizer::TrackOutput;

constexpr int64_t kT0 = 1700000000000000;
// The camera's principal point (639.5, 359.5) in calibration pixels is (640, 360) in PixelBox coordinates, where
// windows are: kScene draws the expected boxes there.
const wingman::localizer::testing::SphereScene kScene{640, 640, 360, 0.348};
using wingman::localizer::testing::detections;
using wingman::localizer::testing::own_pose;

CameraModel camera() { return CameraModel::pinhole(1280, 720, 640, 640, 639.5, 359.5); }

/// The scene's camera (at the origin looking east, ENU; camera x = -north, y = -up, z = east).
CameraAtExposure scene_camera() {
  CameraAtExposure cam;
  cam.R_cam_to_world << 0, 0, 1,  //
      -1, 0, 0,                   //
      0, -1, 0;
  return cam;
}

TrackOutput track_at(const Eigen::Vector3d& p, const Eigen::Vector3d& v, double sigma_m) {
  TrackOutput t;
  t.track_id = 3;
  t.confirmed = true;
  t.p_target_in_world = p;
  t.v_target_in_world = v;
  t.cov_p = sigma_m * sigma_m * Eigen::Matrix3d::Identity();
  t.confidence = 0.8;
  return t;
}

TEST(TrackWindows, AWindowIsTheSphereBoxWithItsImageVelocityAndPixelSigma) {
  const Eigen::Vector3d p(20.0, 2.0, -1.0), v(0.0, -1.0, 0.5);  // 20 m east; moving south (right) and up
  const auto w = predict_track_window(track_at(p, v, 0.2), 0.348, camera(), scene_camera(), BoxRelation::sphere());
  ASSERT_TRUE(w.has_value());
  const wingman::detection_t box = kScene.sphere_box(p);
  EXPECT_NEAR(w->cx, box.cx, 1e-3);
  EXPECT_NEAR(w->cy, box.cy, 1e-3);
  EXPECT_NEAR(w->w, box.w, 1e-3);
  EXPECT_NEAR(w->h, box.h, 1e-3);
  // The centre 0.1 s later, as a plain finite difference of the exact boxes.
  const wingman::detection_t later = kScene.sphere_box(p + 0.1 * v);
  EXPECT_NEAR(w->vx, (later.cx - box.cx) / 0.1, 0.5);
  EXPECT_NEAR(w->vy, (later.cy - box.cy) / 0.1, 0.5);
  EXPECT_GT(w->vx, 25.0);   // right
  EXPECT_LT(w->vy, -12.0);  // up
  // 0.2 m per axis at about 20 m: about f x 0.2 / 20 = 6.4 px (a little more off-axis).
  EXPECT_NEAR(w->sigma_px, 6.4, 0.3);
  EXPECT_NEAR(w->range_m, p.norm(), 1e-5);
  EXPECT_EQ(w->track_id, 3);
  EXPECT_TRUE(w->confirmed);
  EXPECT_FLOAT_EQ(w->confidence, 0.8f);
}

TEST(TrackWindows, TheCameraMotionMovesTheWindowTheOtherWay) {
  const Eigen::Vector3d p(20.0, 0.0, 0.0);
  CameraAtExposure cam = scene_camera();
  cam.v_cam_in_world = Eigen::Vector3d(0.0, 1.0, 0.0);  // the camera moves north (left in its image)
  const auto w =
      predict_track_window(track_at(p, Eigen::Vector3d::Zero(), 0.1), 0.348, camera(), cam, BoxRelation::sphere());
  ASSERT_TRUE(w.has_value());
  EXPECT_NEAR(w->vx, 640.0 * 1.0 / 20.0, 0.5);  // the target drifts right
}

TEST(TrackWindows, TheBoxRelationShrinksTheBoxToTheModelsAndTheSizeScaleGrowsIt) {
  const Eigen::Vector3d p(15.0, 0.0, 0.0);
  const auto sphere = predict_track_window(track_at(p, Eigen::Vector3d::Zero(), 0.1), 0.348, camera(), scene_camera(),
                                           BoxRelation::sphere());
  const BoxRelation shipped = BoxRelation::load("builtin:wingman-small");
  const auto model =
      predict_track_window(track_at(p, Eigen::Vector3d::Zero(), 0.1), 0.348, camera(), scene_camera(), shipped);
  ASSERT_TRUE(sphere && model);
  const auto s = shipped.at(model->w, model->h, 1280);  // the model box's own ratios reproduce it
  EXPECT_NEAR(model->w, sphere->w * s.width_ratio, 0.02 * sphere->w);
  EXPECT_NEAR(model->h, sphere->h * s.height_ratio, 0.02 * sphere->h);
  EXPECT_LT(model->w, 0.95 * sphere->w);
  TrackOutput bigger = track_at(p, Eigen::Vector3d::Zero(), 0.1);
  bigger.size_scale = 1.5;  // an estimated size: the same range, a larger target
  const auto grown = predict_track_window(bigger, 0.348, camera(), scene_camera(), BoxRelation::sphere());
  ASSERT_TRUE(grown);
  EXPECT_NEAR(grown->w, 1.5 * sphere->w, 0.01 * sphere->w);
}

TEST(TrackWindows, NoWindowBehindTheCameraOrOutsideTheImage) {
  const auto behind = predict_track_window(track_at({-10.0, 0.0, 0.0}, Eigen::Vector3d::Zero(), 0.1), 0.348, camera(),
                                           scene_camera(), BoxRelation::sphere());
  EXPECT_FALSE(behind.has_value());
  const auto aside = predict_track_window(track_at({5.0, 20.0, 0.0}, Eigen::Vector3d::Zero(), 0.1), 0.348, camera(),
                                          scene_camera(), BoxRelation::sphere());  // 76 degrees left: outside 90
  EXPECT_FALSE(aside.has_value());
}

TEST(TrackWindows, TheLocalizerPublishesEveryTrackAtTheNextExposureOnlyWhenAsked) {
  LocalizerOptions options;
  options.windows.publish = true;
  Localizer loc(options, camera());
  Localizer silent(LocalizerOptions{}, camera());
  const Eigen::Vector3d v(0.0, -3.0, 0.0);  // 3 m/s south: right in the image
  wingman::localizer::LocalizerOutput out;
  for (int k = 0; k < 12; ++k) {
    const int64_t t = kT0 + 33333 * k;
    const Eigen::Vector3d p = Eigen::Vector3d(12.0, 1.0, 0.5) + 0.033333 * k * v;
    loc.on_own_pose(own_pose(t));
    silent.on_own_pose(own_pose(t));
    out = loc.on_detections(detections(t, k, {kScene.sphere_box(p)}));
    EXPECT_FALSE(silent.on_detections(detections(t, k, {kScene.sphere_box(p)})).windows.has_value());
    ASSERT_TRUE(out.windows.has_value());
    ASSERT_EQ(out.windows->num_windows, 1);
    EXPECT_EQ(out.windows->windows[0].confirmed, k >= 9) << k;  // tracker.birth_hits 10
    EXPECT_EQ(out.windows->windows[0].track_id, k >= 9 ? 1 : 0) << k;
    EXPECT_EQ(out.windows->utime, t);
    EXPECT_EQ(out.windows->utime_predicted, k == 0 ? t : t + 33333);  // one frame interval on
  }
  // The last window: where the target will be one frame later, within a pixel or two (the filter's lag).
  const Eigen::Vector3d next = Eigen::Vector3d(12.0, 1.0, 0.5) + 0.033333 * 12 * v;
  const wingman::detection_t expected = kScene.sphere_box(next);
  const wingman::track_window_t& w = out.windows->windows[0];
  EXPECT_NEAR(w.cx, expected.cx, 2.0);
  EXPECT_NEAR(w.cy, expected.cy, 1.0);
  EXPECT_NEAR(w.w, expected.w, 0.5);  // ground-truth boxes: the sphere relation
  EXPECT_EQ(out.windows->camera_id, 0);
  EXPECT_EQ(out.windows->image_width, 1280);
}

TEST(TrackWindows, OptionsAreValidated) {
  LocalizerOptions o;
  o.windows.channel = "";
  o.windows.max_windows = 0;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 2u);
  EXPECT_NE(p[0].find("windows.channel"), std::string::npos);
  EXPECT_NE(p[1].find("windows.max_windows"), std::string::npos);
}

}  // namespace
