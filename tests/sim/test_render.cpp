// SPDX-License-Identifier: MIT
// Renderer: rendered pixels against the exact truth boxes across the field of view (pinhole, radtan, fisheye, real
// calibrations, real airframes), occlusion, sensor effects, motion blur, scene, errors.
#include "test_constants.hpp"
#include "test_render_support.hpp"

#include <gtest/gtest.h>
#include <wingman/geometry/calibration.hpp>
#include <wingman/sim/renderer.hpp>

#include <fmt/format.h>
#include <opencv2/core.hpp>

#include <filesystem>
#include <random>

namespace wingman::sim {
namespace {

using test::box_of;
using test::edge_error;
using test::flat_options;
using test::look_at;
using wingman::testing::kPi;

/// A random attitude with roll and pitch within +-max_tilt and any yaw.
Eigen::Matrix3d random_attitude(std::mt19937& rng, double max_tilt) {
  std::uniform_real_distribution<double> tilt(-max_tilt, max_tilt), yaw(-kPi, kPi);
  return (Eigen::AngleAxisd(yaw(rng), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(tilt(rng), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(tilt(rng), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

/// Pixels where a red drone on white covers at least half of the pixel (flat shading: green = 1 - coverage in
/// linear light; sRGB level 187.5 is linear 0.5). Red > 128 tells the drone from the black outside the field of view.
cv::Mat half_covered(const cv::Mat& bgr) {
  cv::Mat mask(bgr.size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
      mask.at<uint8_t>(y, x) = p[1] < 188 && p[2] > 128 ? 255 : 0;
    }
  }
  return mask;
}

/// A drone with no part thinner than 2 cm (so every part covers pixels at the test ranges, even edge-on): opaque
/// 2 cm thick discs for propellers, thick landing gear, all red.
DroneSpec solid_red_drone() {
  DroneSpec spec;
  spec.prop_style = "disc";
  spec.prop_disc_alpha = 1.0;
  spec.prop_thickness_m = 0.02;
  spec.gear_tube_m = 0.02;
  for (auto* c : {&spec.body_colour, &spec.front_arm_colour, &spec.rear_arm_colour, &spec.motor_colour,
                  &spec.prop_colour, &spec.gear_colour}) {
    *c = {1.0, 0.0, 0.0};
  }
  return spec;
}

/// How a pixel test looks at its drones.
struct View {
  double range_m;              ///< camera to drone centre
  bool from_colour = true;     ///< also check the box of the half-covered pixels (needs solid_red_drone())
  double look_down_deg = 0.0;  ///< camera pitch below the horizon
  double max_tilt_rad = 0.6;   ///< drone roll and pitch within +-this
  uint32_t seed = 1;
};

/// Renders `model` at pixel fractions across the image (corners, edges, centre, and two places where it is cut by
/// the border) and checks the truth box against the box of the drone's pixels: from the mask (pixel centres)
/// always, from the colours when view.from_colour. Every edge within 1 px. Places whose drone would reach beyond
/// the renderer's field of view (fisheyes wider than max_half_fov_deg) are left out.
void expect_pixels_match_truth(const geometry::CameraModel& camera, const DroneModel& model, const View& view) {
  const RenderOptions options = flat_options();
  Renderer renderer(camera, options);
  const double down = view.look_down_deg * kPi / 180.0;
  const Eigen::Isometry3d T_cam_to_world = look_at({0, 0, 20}, {0, 30 * std::cos(down), 20 - 30 * std::sin(down)});
  std::mt19937 rng(view.seed);
  const std::vector<Eigen::Vector2d> fractions = {{0.07, 0.1}, {0.5, 0.1},   {0.93, 0.1}, {0.07, 0.5}, {0.5, 0.5},
                                                  {0.93, 0.5}, {0.07, 0.9},  {0.5, 0.9},  {0.93, 0.9}, {0.3, 0.3},
                                                  {0.7, 0.75}, {-0.01, 0.4}, {0.6, 1.01}};
  const double angular_radius = std::asin(model.bounding_radius() / view.range_m);
  double worst = 0.0;
  int tested = 0;
  for (const Eigen::Vector2d& f : fractions) {
    const Eigen::Vector2d uv(f.x() * camera.width(), f.y() * camera.height());
    const Eigen::Vector3d ray = camera.unproject(uv);
    if (std::acos(ray.z()) + angular_radius > options.max_half_fov_deg * kPi / 180.0) continue;
    ++tested;
    DroneInstance drone;
    drone.vehicle_id = 7;
    drone.model = &model;
    drone.T_body_to_world.linear() = random_attitude(rng, view.max_tilt_rad);
    drone.T_body_to_world.translation() = T_cam_to_world * (ray * view.range_m);
    drone.prop_angle_rad = std::uniform_real_distribution<double>(0.0, 2.0 * kPi)(rng);
    const RenderResult result = renderer.render(T_cam_to_world, {drone}, 0, 1);
    ASSERT_EQ(result.boxes.size(), 1u);
    const RenderedBox& truth = result.boxes[0];
    const std::string where = fmt::format(
        "{} at pixel ({:.0f}, {:.0f}), range {} m: truth box cx {:.2f} cy {:.2f} w "
        "{:.2f} h {:.2f}",
        camera.name(), uv.x(), uv.y(), view.range_m, truth.cx, truth.cy, truth.w, truth.h);
    ASSERT_TRUE(truth.visible) << where;
    EXPECT_EQ(truth.vehicle_id, 7);
    EXPECT_NEAR(truth.range_m, view.range_m, 1e-6) << where;
    const RenderedBox from_mask = box_of(result.mask);
    ASSERT_TRUE(from_mask.visible) << where;
    EXPECT_EQ(truth.visible_pixels, cv::countNonZero(result.mask)) << where;
    EXPECT_LE(edge_error(truth, from_mask), 1.0) << where << "; mask box cx " << from_mask.cx << " cy " << from_mask.cy
                                                 << " w " << from_mask.w << " h " << from_mask.h;
    worst = std::max(worst, edge_error(truth, from_mask));
    if (view.from_colour) {
      const RenderedBox from_pixels = box_of(half_covered(result.bgr));
      ASSERT_TRUE(from_pixels.visible) << where;
      EXPECT_LE(edge_error(truth, from_pixels), 1.0)
          << where << "; pixel box cx " << from_pixels.cx << " cy " << from_pixels.cy << " w " << from_pixels.w << " h "
          << from_pixels.h;
      worst = std::max(worst, edge_error(truth, from_pixels));
    }
  }
  EXPECT_GE(tested, 5) << camera.name() << ": too few places within the field of view";
  ::testing::Test::RecordProperty("worst_edge_error_px", fmt::format("{:.3f}", worst));
  ::testing::Test::RecordProperty("places", tested);
}

TEST(RendererPixels, PinholeBoxMatchesPixelsAcrossTheImage) {
  const DroneModel model = DroneModel::procedural(solid_red_drone());
  expect_pixels_match_truth(test::pinhole(), model, View{6.5});
}

TEST(RendererPixels, StrongRadTanBoxMatchesPixelsAcrossTheImage) {
  const DroneModel model = DroneModel::procedural(solid_red_drone());
  expect_pixels_match_truth(test::strong_radtan(), model, View{6.0, true, 0.0, 0.6, 2});
}

TEST(RendererPixels, FisheyeBoxMatchesPixelsAcrossTheImage) {
  const DroneModel model = DroneModel::procedural(solid_red_drone());
  expect_pixels_match_truth(test::fisheye(), model, View{3.6, true, 0.0, 0.6, 3});
}

TEST(RendererPixels, DefaultQuadWithBladesMatchesTheMaskNearby) {
  // Thin blades: seen from 50 degrees above the propeller plane (camera looking down, drone tilted at most 10
  // degrees), their 2 cm chords are 3 px or more at 4 m.
  const DroneModel model = DroneModel::procedural(DroneSpec{});
  expect_pixels_match_truth(test::strong_radtan(), model, View{4.0, false, 70.0, 0.17, 4});
}

TEST(RendererPixels, RealCalibrationBoxMatchesPixels) {
  const std::string missing = test::missing_shared("calibrations/raspicam_v2_1280x720.yaml");
  if (!missing.empty()) GTEST_SKIP() << "real calibrations not available: " << missing << " is absent";
  const geometry::CameraModel camera =
      geometry::load_calibration(test::shared_path("calibrations/raspicam_v2_1280x720.yaml"));
  const DroneModel model = DroneModel::procedural(solid_red_drone());
  expect_pixels_match_truth(camera, model, View{9.0, true, 0.0, 0.6, 5});
}

TEST(RendererPixels, RealFisheyeCalibrationBoxMatchesPixelsWithinItsRenderedField) {
  // The Firefly's lens sees ~110 degrees off-axis at its corners; the renderer covers 80 (max_half_fov_deg).
  const std::string name = "calibrations/vswarm_firefly_s_720x540_camera_info.yaml";
  const std::string missing = test::missing_shared(name);
  if (!missing.empty()) GTEST_SKIP() << "real calibrations not available: " << missing << " is absent";
  const geometry::CameraModel camera = geometry::load_calibration(test::shared_path(name));
  const DroneModel model = DroneModel::procedural(solid_red_drone());
  expect_pixels_match_truth(camera, model, View{0.012 * camera.fx(), true, 0.0, 0.6, 6});
}

TEST(RendererPixels, SharedAirframeMeshesMatchTheirTruthBoxes) {
  const std::string missing = test::missing_shared("meshes");
  if (!missing.empty()) GTEST_SKIP() << "airframe meshes not available: " << missing << " is absent";
  const geometry::CameraModel camera = test::strong_radtan();
  for (const char* name : {"dji_f450.glb", "holybro_x500v2.glb", "tarot_t650.glb", "3dr_iris.glb"}) {
    DroneSpec spec;
    spec.frame = "mesh";
    spec.mesh_path = test::shared_path(std::string("meshes/") + name);
    const DroneModel model = DroneModel::from_spec(spec);
    SCOPED_TRACE(name);
    // Propeller blades are a few millimetres thick: seen from above (as in the blades test) they are pixels wide.
    expect_pixels_match_truth(camera, model, View{3.0, false, 70.0, 0.17, 7});
  }
}

TEST(Renderer, NearerDroneOccludesAndHidesAFartherOne) {
  const geometry::CameraModel camera = test::pinhole();
  Renderer renderer(camera, flat_options());
  const DroneModel model = DroneModel::procedural(DroneSpec{});
  DroneSpec block;  // a drone with a 0.8 m cube for a body: solid enough to hide another
  block.body_size_m = 0.8;
  block.body_height_m = 0.8;
  const DroneModel occluder = DroneModel::procedural(block);
  const Eigen::Isometry3d T_cam_to_world = look_at({0, 0, 10}, {0, 10, 10});
  DroneInstance far, near;
  far.vehicle_id = 1;
  far.model = &model;
  near.model = &occluder;
  near.vehicle_id = 2;
  far.T_body_to_world.translation() = Eigen::Vector3d(0.0, 12.0, 10.0);
  const RenderResult alone = renderer.render(T_cam_to_world, {far}, 0, 1);
  ASSERT_TRUE(alone.boxes[0].visible);
  near.T_body_to_world.translation() = Eigen::Vector3d(0.45, 6.0, 10.0);  // covers part of the far one
  const RenderResult partly = renderer.render(T_cam_to_world, {far, near}, 0, 1);
  EXPECT_TRUE(partly.boxes[0].visible);
  EXPECT_LT(partly.boxes[0].visible_pixels, alone.boxes[0].visible_pixels);
  EXPECT_GT(partly.boxes[0].visible_pixels, 0);
  EXPECT_EQ(partly.boxes[1].vehicle_id, 2);
  // The truth box is the whole drone's, occluded or not.
  EXPECT_NEAR(edge_error(partly.boxes[0], alone.boxes[0]), 0.0, 1e-9);
  near.T_body_to_world.translation() =
      Eigen::Vector3d(0.0, 2.0, 10.0);  // its body, 2 m away, hides the far one completely
  const RenderResult hidden = renderer.render(T_cam_to_world, {far, near}, 0, 1);
  EXPECT_EQ(hidden.boxes[0].visible_pixels, 0);
  EXPECT_FALSE(hidden.boxes[0].visible);
  EXPECT_TRUE(hidden.boxes[1].visible);
}

TEST(Renderer, DroneBehindTheCameraOrOutOfViewIsNotVisible) {
  const geometry::CameraModel camera = test::pinhole();
  Renderer renderer(camera, flat_options());
  const DroneModel model = DroneModel::procedural(DroneSpec{});
  const Eigen::Isometry3d T_cam_to_world = look_at({0, 0, 10}, {0, 10, 10});
  DroneInstance behind, aside;
  behind.model = aside.model = &model;
  behind.T_body_to_world.translation() = Eigen::Vector3d(0.0, -5.0, 10.0);
  aside.T_body_to_world.translation() = Eigen::Vector3d(20.0, 5.0, 10.0);
  const RenderResult result = renderer.render(T_cam_to_world, {behind, aside}, 0, 1);
  for (const RenderedBox& box : result.boxes) {
    EXPECT_FALSE(box.visible);
    EXPECT_EQ(box.visible_pixels, 0);
  }
  EXPECT_EQ(cv::countNonZero(result.mask), 0);
}

TEST(Renderer, SensorNoiseHasTheConfiguredSpread) {
  RenderOptions options = flat_options();
  options.background_colour = {0.5, 0.5, 0.5};
  options.noise_std = 4.0;
  Renderer renderer(test::pinhole(), options);
  const RenderResult a = renderer.render(Eigen::Isometry3d::Identity(), {}, 0, 11);
  cv::Scalar mean, stddev;
  cv::meanStdDev(a.bgr, mean, stddev);
  // sRGB 0.5 is level 127.5; the noise is zero-mean Irwin-Hall (4 bytes) with unit variance, then rounded.
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(mean[c], 127.5, 0.1) << "channel " << c;
    EXPECT_NEAR(stddev[c], std::sqrt(16.0 + 1.0 / 12.0), 0.05) << "channel " << c;
  }
  const RenderResult b = renderer.render(Eigen::Isometry3d::Identity(), {}, 0, 12);
  EXPECT_GT(cv::norm(a.bgr, b.bgr, cv::NORM_L1), 0.0) << "another frame seed draws other noise";
}

TEST(Renderer, ExposureGainScalesLinearLight) {
  RenderOptions options = flat_options();
  options.background_colour = {200, 120, 40};
  Renderer renderer(test::pinhole(), options);
  const cv::Vec3b one = renderer.render(Eigen::Isometry3d::Identity(), {}, 0, 1).bgr.at<cv::Vec3b>(300, 400);
  EXPECT_EQ(one, cv::Vec3b(40, 120, 200));
  options.exposure_gain = 0.5;
  renderer.set_options(options);
  const RenderResult half = renderer.render(Eigen::Isometry3d::Identity(), {}, 0, 1);
  EXPECT_DOUBLE_EQ(half.exposure_gain, 0.5);
  const auto expected = [](double level) {
    const double lin =
        level / 255.0 <= 0.04045 ? level / 255.0 / 12.92 : std::pow((level / 255.0 + 0.055) / 1.055, 2.4);
    const double half_lin = 0.5 * lin;
    const double s = half_lin <= 0.0031308 ? 12.92 * half_lin : 1.055 * std::pow(half_lin, 1.0 / 2.4) - 0.055;
    return static_cast<int>(std::floor(s * 255.0 + 0.5));
  };
  const cv::Vec3b got = half.bgr.at<cv::Vec3b>(300, 400);
  EXPECT_NEAR(got[2], expected(200), 1);
  EXPECT_NEAR(got[1], expected(120), 1);
  EXPECT_NEAR(got[0], expected(40), 1);
  // Exposure jitter: per frame seed, reproducible.
  options.exposure_gain = 1.0;
  options.exposure_jitter = 0.3;
  renderer.set_options(options);
  const double g1 = renderer.render(Eigen::Isometry3d::Identity(), {}, 0, 5).exposure_gain;
  const double g2 = renderer.render(Eigen::Isometry3d::Identity(), {}, 0, 6).exposure_gain;
  EXPECT_NE(g1, g2);
  EXPECT_EQ(g1, renderer.render(Eigen::Isometry3d::Identity(), {}, 0, 5).exposure_gain);
}

TEST(Renderer, MotionBlurSmearsAlongTheMotionOnly) {
  const geometry::CameraModel camera = test::pinhole();
  RenderOptions options = flat_options();
  const DroneModel model = DroneModel::procedural(DroneSpec{});
  const Eigen::Isometry3d T_cam_to_world = look_at({0, 0, 10}, {0, 10, 10});
  DroneInstance drone;
  drone.model = &model;
  drone.T_body_to_world.translation() = Eigen::Vector3d(0.0, 8.0, 10.0);
  drone.v_body_in_world = {10.0, 0.0, 0.0};  // sideways (image x)
  Renderer sharp(camera, options);
  const RenderResult still = sharp.render(T_cam_to_world, {drone}, 0, 1);
  options.motion_blur_exposure_s = 0.02;  // 0.2 m of travel: ~23 px at 8 m
  options.motion_blur_samples = 9;
  Renderer blurred(camera, options);
  const RenderResult moving = blurred.render(T_cam_to_world, {drone}, 0, 1);
  cv::Mat touched_still, touched_moving;
  cv::inRange(still.bgr, cv::Scalar(0, 0, 0), cv::Scalar(254, 254, 254), touched_still);
  cv::inRange(moving.bgr, cv::Scalar(0, 0, 0), cv::Scalar(254, 254, 254), touched_moving);
  const RenderedBox a = box_of(touched_still), b = box_of(touched_moving);
  // The 9 samples span 8/9 of the exposure.
  const double travel_px = camera.fx() * 0.2 / 8.0 * 8.0 / 9.0;
  EXPECT_NEAR(b.w - a.w, travel_px, 2.0);
  EXPECT_NEAR(b.h, a.h, 1.0);
  EXPECT_NEAR(b.cx, a.cx, 1.0);
  // Truth box and mask are those of the middle of the exposure.
  EXPECT_NEAR(edge_error(moving.boxes[0], still.boxes[0]), 0.0, 1e-9);
  EXPECT_EQ(cv::countNonZero(moving.mask != still.mask), 0);

  // A panning camera smears a still drone the same way: 1 rad/s about the optical y axis (image x).
  drone.v_body_in_world = Eigen::Vector3d::Zero();
  CameraMotion pan;
  pan.w_cam_in_cam = Eigen::Vector3d(0.0, 1.0, 0.0);
  const RenderResult panned = blurred.render(T_cam_to_world, {drone}, 0, 1, pan);
  cv::Mat touched_panned;
  cv::inRange(panned.bgr, cv::Scalar(0, 0, 0), cv::Scalar(254, 254, 254), touched_panned);
  const RenderedBox c = box_of(touched_panned);
  EXPECT_NEAR(c.w - a.w, camera.fx() * 1.0 * 0.02 * 8.0 / 9.0, 2.0);
  EXPECT_NEAR(c.h, a.h, 1.0);
}

TEST(Renderer, DefaultSceneLooksLikeDaylight) {
  Renderer renderer(test::pinhole(), RenderOptions{});
  const DroneModel model = DroneModel::procedural(DroneSpec{});
  const Eigen::Isometry3d T_cam_to_world = look_at({0, 0, 15}, {0, 100, 12});  // slightly down: sky and ground
  DroneInstance drone;
  drone.model = &model;
  drone.T_body_to_world.translation() = Eigen::Vector3d(1.0, 10.0, 15.0);
  const RenderResult result = renderer.render(T_cam_to_world, {drone}, 0, 1);
  const cv::Scalar sky = cv::mean(result.bgr.rowRange(0, 60));
  const cv::Scalar ground = cv::mean(result.bgr.rowRange(660, 720));
  EXPECT_GT(sky[0], sky[2] + 20) << "sky is blue (BGR " << sky << ")";
  EXPECT_GT(sky[0], 150);
  EXPECT_GT(ground[1], ground[0] + 10) << "ground is green-brown (BGR " << ground << ")";
  EXPECT_LT(ground[1], sky[1]);
  ASSERT_TRUE(result.boxes[0].visible);
  // The drone stands out from the sky behind it.
  const RenderedBox& box = result.boxes[0];
  const cv::Rect r(static_cast<int>(box.cx - box.w / 2), static_cast<int>(box.cy - box.h / 2), static_cast<int>(box.w),
                   static_cast<int>(box.h));
  cv::Mat drone_pixels = result.mask(r) != 0;
  const cv::Scalar on_drone = cv::mean(result.bgr(r), drone_pixels);
  const cv::Scalar around = cv::mean(result.bgr(r), ~drone_pixels);
  EXPECT_GT(cv::norm(on_drone - around), 60.0) << "drone " << on_drone << " vs background " << around;
}

TEST(Renderer, RejectsBadInputWithClearErrors) {
  RenderOptions bad;
  bad.supersampling = 9;
  bad.cloud_cover = 2.0;
  try {
    Renderer renderer(test::pinhole(), bad);
    FAIL() << "bad options accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("render.supersampling = 9"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("render.cloud_cover = 2"), std::string::npos) << e.what();
  }
  Renderer renderer(test::pinhole(), flat_options());
  DroneInstance no_model;
  no_model.vehicle_id = 3;
  try {
    renderer.render(Eigen::Isometry3d::Identity(), {no_model}, 0, 1);
    FAIL() << "a drone without a model accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("vehicle 3"), std::string::npos) << e.what();
  }
  const DroneModel model = DroneModel::procedural(DroneSpec{});
  DroneInstance d;
  d.model = &model;
  EXPECT_THROW(renderer.render(Eigen::Isometry3d::Identity(), std::vector<DroneInstance>(255, d), 0, 1),
               std::invalid_argument);
}

TEST(Renderer, SetOptionsRebuildsForANewSupersampling) {
  RenderOptions options = flat_options();
  options.supersampling = 1;
  Renderer renderer(test::strong_radtan(), options);
  const cv::Size one = renderer.pinhole_size();
  options.supersampling = 3;
  options.background_colour = {0.0, 0.0, 1.0};
  renderer.set_options(options);
  EXPECT_NEAR(renderer.pinhole_size().width, 3 * one.width, 16);
  const cv::Vec3b centre = renderer.render(Eigen::Isometry3d::Identity(), {}, 0, 1).bgr.at<cv::Vec3b>(360, 640);
  EXPECT_EQ(centre, cv::Vec3b(255, 0, 0));
  // Outside the field of view (beyond max_half_fov_deg) the fisheye's corners are black.
  RenderOptions narrow = flat_options();
  narrow.max_half_fov_deg = 60.0;
  Renderer fish(test::fisheye(), narrow);
  const cv::Mat image = fish.render(Eigen::Isometry3d::Identity(), {}, 0, 1).bgr;
  EXPECT_EQ(image.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
  EXPECT_EQ(image.at<cv::Vec3b>(360, 640), cv::Vec3b(255, 255, 255));
}

}  // namespace
}  // namespace wingman::sim
