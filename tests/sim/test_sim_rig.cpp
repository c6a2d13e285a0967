// SPDX-License-Identifier: MIT
// Several cameras on the camera vehicle (cameras.rig), rendered for real: the cameras of a rig file and their
// channels, a drone straight to the left seen by the left camera only (image, truth boxes, ground-truth
// detections), a rig's first camera giving the single camera's images byte for byte, renderers sharing one GL
// context drawing what one with its own draws, and a bad rig file as one configuration error.
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <wingman/common/config.hpp>
#include <wingman/sim/renderer.hpp>
#include <wingman/sim/scenario.hpp>
#include <wingman/sim/sim_cameras.hpp>
#include <wingman/sim/simulator.hpp>
#include <wingman/sim/truth_detections.hpp>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <fstream>
#include <memory>

namespace {

using wingman::sim::Renderer;
using wingman::sim::RenderOptions;
using wingman::sim::SimCameraOutput;
using wingman::sim::SimFrame;
using wingman::sim::SimOptions;
using wingman::sim::Simulator;
using wingman::testing::source_path;
using wingman::testing::TempDir;

/// The camera vehicle at (0, 0, 5) facing north (yaw 90: body +y, its left, points west), a leader hovering
/// 8 m straight to its left (west), level with it.
const std::string kLeftScenario = R"(name: left
description: "a drone straight to the left of the camera vehicle"
start_utime: 1767225600000000
duration_s: 1
seed: 7
vehicles:
  - name: camera
    id: 0
    initial: {position: [0, 0, 5], yaw_deg: 90}
  - name: leader
    id: 1
    initial: {position: [-8, 0, 5], yaw_deg: 0}
    motion: {type: hover}
)";

wingman::sim::Scenario write_and_load(const TempDir& dir, const std::string& name, const std::string& text) {
  const std::string path = dir.file(name);
  std::ofstream(path) << text;
  return wingman::sim::load_scenario(path);
}

/// The renderers of `cameras`, the first with its own context and the others sharing it (as wingman-sim makes them).
std::vector<std::unique_ptr<Renderer>> make_renderers(const std::vector<SimCameraOutput>& cameras,
                                                      const RenderOptions& options) {
  std::vector<std::unique_ptr<Renderer>> out;
  for (const auto& c : cameras) {
    out.push_back(out.empty() ? std::make_unique<Renderer>(c.camera.model, options)
                              : std::make_unique<Renderer>(c.camera.model, options, *out.front()));
  }
  return out;
}

std::vector<Renderer*> pointers(const std::vector<std::unique_ptr<Renderer>>& renderers) {
  std::vector<Renderer*> out;
  for (const auto& r : renderers) out.push_back(r.get());
  return out;
}

std::vector<wingman::sim::SimCamera> models(const std::vector<SimCameraOutput>& cameras) {
  std::vector<wingman::sim::SimCamera> out;
  for (const auto& c : cameras) out.push_back(c.camera);
  return out;
}

bool same_pixels(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

TEST(SimRig, WithoutARigTheSingleCameraOfTheKeysWithARigItsCamerasAndChannels) {
  SimOptions o;
  const auto single = wingman::sim::sim_cameras(o);
  ASSERT_EQ(single.size(), 1u);
  EXPECT_EQ(single[0].image_channel, "IMAGE_CAM0");
  EXPECT_EQ(single[0].detections_channel, "DETECTIONS_CAM0");
  EXPECT_EQ(single[0].camera.camera_id, 0);
  EXPECT_EQ(single[0].camera.model.width(), 1280);

  o.camera_rig = source_path("config/rigs/surround4.yaml");
  o.camera.rate_hz = 15;
  o.image_channel = "IGNORED_WITH_A_RIG";
  const auto rig = wingman::sim::sim_cameras(o);
  ASSERT_EQ(rig.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(rig[i].camera.camera_id, i);
    EXPECT_EQ(rig[i].image_channel, "IMAGE_CAM" + std::to_string(i));
    EXPECT_EQ(rig[i].detections_channel, "DETECTIONS_CAM" + std::to_string(i));
    EXPECT_EQ(rig[i].camera.rate_hz, 15.0);  // camera.rate_hz stays the frame rate of every camera
    EXPECT_EQ(rig[i].camera.model.width(), 1280);
    EXPECT_EQ(rig[i].camera.model.height(), 720);
  }
  // Camera 1 looks along body +y (left): its optical axis (z) is body +y.
  EXPECT_LT((rig[1].camera.mount.R_cam_to_body * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitY()).norm(), 1e-9);
}

TEST(SimRig, ADroneStraightToTheLeftIsInTheLeftCamerasImageBoxesAndDetectionsOnly) {
  TempDir dir;
  SimOptions o;
  o.camera_rig = source_path("config/rigs/surround4.yaml");
  const auto cameras = wingman::sim::sim_cameras(o);
  // Pixel-exact options: a white background, flat shading, no noise: any pixel that is not white is the drone.
  RenderOptions ro;
  ro.background = "uniform";
  ro.background_colour = {1.0, 1.0, 1.0};
  ro.shading = "flat";
  ro.noise_std = 0.0;
  ro.shot_noise = 0.0;
  ro.supersampling = 1;
  auto renderers = make_renderers(cameras, ro);
  Simulator sim(write_and_load(dir, "left.yaml", kLeftScenario), models(cameras), pointers(renderers));
  const SimFrame f = sim.step();

  ASSERT_EQ(f.cameras.size(), 4u);
  ASSERT_EQ(f.truth.num_boxes, 4);  // the leader in each of the four cameras
  wingman::sim::TruthDetectionOptions d;
  for (int i = 0; i < 4; ++i) {
    const auto& view = f.cameras[i];
    EXPECT_EQ(view.camera_id, i);
    ASSERT_EQ(view.bgr.size(), cv::Size(1280, 720));
    const wingman::truth_box_t& box = f.truth.boxes[i];
    EXPECT_EQ(box.camera_id, i);
    EXPECT_EQ(box.vehicle_id, 1);
    cv::Mat gray;
    cv::extractChannel(view.bgr, gray, 1);
    const int drone_pixels = static_cast<int>(cv::countNonZero(gray < 250));
    const auto det = wingman::sim::truth_detections(f.truth, f.index, cameras[i].camera.model, view.T_cam_to_world,
                                                    view.camera_id, d, i);
    EXPECT_EQ(det.camera_id, i);
    if (i == 1) {
      // Straight ahead of the left camera: the box is at the image centre (the leader's body origin is 8 m away
      // along the optical axis, the camera 0.1 m out from the body centre).
      EXPECT_TRUE(box.visible);
      EXPECT_NEAR(box.cx, 640, 15) << "camera 1's box";
      EXPECT_NEAR(box.cy, 360, 15) << "camera 1's box";
      EXPECT_NEAR(box.range, 7.9, 1e-6);
      EXPECT_GT(drone_pixels, 50) << "the drone is drawn in camera 1's image";
      // ... where its truth box says (box convention: pixel (x, y) spans [x, x + 1] x [y, y + 1]; 1 px allowed for
      // the supersampled edges).
      const cv::Rect drawn = cv::boundingRect(gray < 250);
      EXPECT_NEAR(drawn.x, box.cx - box.w / 2, 1.0);
      EXPECT_NEAR(drawn.x + drawn.width, box.cx + box.w / 2, 1.0);
      EXPECT_NEAR(drawn.y, box.cy - box.h / 2, 1.0);
      EXPECT_NEAR(drawn.y + drawn.height, box.cy + box.h / 2, 1.0);
      ASSERT_EQ(det.num_detections, 1);
      EXPECT_NEAR(det.detections[0].cx, box.cx, 1e-3);
    } else {
      EXPECT_FALSE(box.visible) << "camera " << i;
      EXPECT_EQ(drone_pixels, 0) << "camera " << i << " sees nothing but the background";
      EXPECT_EQ(det.num_detections, 0) << "camera " << i;
    }
  }
  EXPECT_TRUE(same_pixels(f.bgr, f.cameras[0].bgr));
}

TEST(SimRig, ARigsFirstCameraEqualToTheSingleCameraGivesItsImagesByteForByte) {
  TempDir dir;
  // Camera 0 is the single default camera (1280x720, f 640, forward, at the body origin); camera 1 looks left.
  const std::string rig = dir.file("rig.yaml");
  std::ofstream(rig) << "cameras:\n"
                        "  - camera: {camera_id: 0, width: 1280, height: 720, focal_px: 640}\n"
                        "  - camera: {camera_id: 5, width: 1280, height: 720, focal_px: 640}\n"
                        "    mount: {yaw_deg: 90}\n";
  SimOptions single_options;
  SimOptions rig_options;
  rig_options.camera_rig = rig;
  const auto single_cameras = wingman::sim::sim_cameras(single_options);
  const auto rig_cameras = wingman::sim::sim_cameras(rig_options);
  ASSERT_EQ(rig_cameras.size(), 2u);
  // The default render options (sensor noise on, seeded per frame and camera), at supersampling 1 to keep it short.
  RenderOptions ro;
  ro.supersampling = 1;
  ro.exposure_jitter = 0.05;
  auto single_renderers = make_renderers(single_cameras, ro);
  auto rig_renderers = make_renderers(rig_cameras, ro);
  const auto scenario = wingman::sim::load_scenario(source_path("config/scenarios/follow_1d.yaml"));
  Simulator single(scenario, models(single_cameras), pointers(single_renderers));
  Simulator with_rig(scenario, models(rig_cameras), pointers(rig_renderers));
  for (int k = 0; k < 2; ++k) {  // the second frame's camera 0 comes after camera 1 used the shared context
    const SimFrame a = single.step();
    const SimFrame b = with_rig.step();
    ASSERT_EQ(b.cameras.size(), 2u);
    EXPECT_TRUE(same_pixels(a.bgr, b.cameras[0].bgr)) << "frame " << k;
    EXPECT_EQ(b.cameras[1].camera_id, 5);
    EXPECT_FALSE(same_pixels(b.cameras[0].bgr, b.cameras[1].bgr)) << "frame " << k;
    // The single camera's truth boxes come first, unchanged; then camera 5's.
    ASSERT_EQ(a.truth.num_boxes, 1);
    ASSERT_EQ(b.truth.num_boxes, 2);
    EXPECT_EQ(a.truth.boxes[0].cx, b.truth.boxes[0].cx);
    EXPECT_EQ(a.truth.boxes[0].w, b.truth.boxes[0].w);
    EXPECT_EQ(b.truth.boxes[0].camera_id, 0);
    EXPECT_EQ(b.truth.boxes[1].camera_id, 5);
    EXPECT_TRUE(a.truth.boxes[0].visible);   // the follow_1d leader is ahead
    EXPECT_FALSE(b.truth.boxes[1].visible);  // and not to the left
  }
}

TEST(SimRig, ARendererSharingAContextDrawsWhatOneWithItsOwnDraws) {
  const auto camera = wingman::geometry::CameraModel::pinhole(320, 240, 200, 200, 159.5, 119.5);
  const auto other = wingman::geometry::CameraModel::pinhole(160, 120, 90, 90, 79.5, 59.5);
  RenderOptions ro;
  Renderer owner(other, ro);
  Renderer shared(camera, ro, owner);
  Renderer own(camera, ro);
  Eigen::Isometry3d T_cam_to_world = Eigen::Isometry3d::Identity();
  T_cam_to_world.linear() << 1, 0, 0, 0, 0, 1, 0, -1, 0;  // looking north, level
  T_cam_to_world.translation() = Eigen::Vector3d(0, 0, 5);
  const auto model = wingman::sim::DroneModel::from_spec({});
  wingman::sim::DroneInstance drone;
  drone.vehicle_id = 1;
  drone.model = &model;
  drone.T_body_to_world.translation() = Eigen::Vector3d(0.3, 6, 5.2);
  for (uint64_t seed : {11u, 12u}) {
    (void)owner.render(T_cam_to_world, {drone}, 0, seed);  // the owner between: state must not leak
    const auto a = shared.render(T_cam_to_world, {drone}, 0, seed);
    const auto b = own.render(T_cam_to_world, {drone}, 0, seed);
    EXPECT_TRUE(same_pixels(a.bgr, b.bgr)) << "seed " << seed;
    EXPECT_TRUE(same_pixels(a.mask, b.mask)) << "seed " << seed;
    ASSERT_EQ(a.boxes.size(), 1u);
    EXPECT_TRUE(a.boxes[0].visible);
  }
  EXPECT_EQ(shared.gl_renderer(), owner.gl_renderer());
}

TEST(SimRig, ABadRigFileIsOneConfigurationErrorNamingTheKeyTheFileAndEveryProblem) {
  TempDir dir;
  const std::string rig = dir.file("bad.yaml");
  std::ofstream(rig) << "cameras:\n"
                        "  - camera: {camera_id: 0, width: -5}\n"
                        "  - camera: {camera_id: 0}\n";
  SimOptions o;
  o.camera_rig = rig;
  try {
    (void)wingman::sim::load_sim_rig(o);
    FAIL() << "no error";
  } catch (const wingman::common::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("cameras.rig: " + rig + ":", 0), 0u) << what;
    EXPECT_NE(what.find("camera.width"), std::string::npos) << what;
    EXPECT_NE(what.find("camera_id"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
  }
  o.camera_rig = dir.file("missing.yaml");
  EXPECT_THROW((void)wingman::sim::sim_cameras(o), wingman::common::ConfigError);
  // Larger than an image_t subscriber accepts (common::ImageLimits: 8192), which the rig file itself allows.
  std::ofstream(rig) << "cameras:\n  - camera: {camera_id: 0, width: 9000, height: 720, focal_px: 640}\n";
  o.camera_rig = rig;
  EXPECT_THROW((void)wingman::sim::load_sim_rig(o), wingman::common::ConfigError);
}

// cameras.stagger_s: the rig's camera i exposes i x 1/120 s after its frame's time (free-running cameras), each with
// its own image utime, own pose and ground truth, from the vehicles where they are then. Projected boxes (no
// rendering), the surround flight's first second: the leader accelerates from rest, then flies at 2 m/s.
TEST(SimRig, StaggeredCamerasExposeOneAfterTheOtherEachWithItsOwnPoseAndTruth) {
  SimOptions o;
  o.camera_rig = source_path("config/rigs/surround4.yaml");
  const auto together = wingman::sim::sim_cameras(o);
  o.camera_stagger_s = 1.0 / 120.0;
  const auto staggered = wingman::sim::sim_cameras(o);
  ASSERT_EQ(staggered.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(together[i].camera.exposure_offset_s, 0.0);
    EXPECT_DOUBLE_EQ(staggered[i].camera.exposure_offset_s, static_cast<double>(i) / 120.0);
  }
  const auto scenario = wingman::sim::load_scenario(source_path("config/scenarios/surround.yaml"));
  Simulator a(scenario, models(together), {});
  Simulator b(scenario, models(staggered), {});
  const int64_t step_us[4] = {0, 8333, 16667, 25000};  // llround(i * 1e6 / 120)
  double largest_move_m = 0;
  for (int k = 0; k < 30; ++k) {
    SCOPED_TRACE(::testing::Message() << "frame " << k);
    const SimFrame fa = a.step();
    const SimFrame fb = b.step();
    ASSERT_EQ(fb.utime, fa.utime);
    EXPECT_TRUE(fa.later.empty());
    ASSERT_EQ(fb.later.size(), 3u);
    EXPECT_EQ(fb.own_pose.utime, fb.utime);
    EXPECT_EQ(b.now_utime(), fb.utime + step_us[3]) << "the simulator stands at the last exposure";
    for (size_t i = 0; i < 4; ++i) EXPECT_EQ(fb.cameras[i].utime, fb.utime + step_us[i]);
    // The frame's truth holds camera 0's boxes, each later exposure its own camera's, at its own time.
    for (const auto& box : fb.truth.boxes) EXPECT_EQ(box.camera_id, 0);
    Eigen::Vector3d p0, v0;
    for (int j = 0; j < 3; ++j)
      p0[j] = fb.truth.vehicles[1].p_body_in_world[j], v0[j] = fb.truth.vehicles[1].v_body_in_world[j];
    for (size_t j = 0; j < 3; ++j) {
      const wingman::sim::SimExposure& e = fb.later[j];
      EXPECT_EQ(e.utime, fb.utime + step_us[j + 1]);
      EXPECT_EQ(e.own_pose.utime, e.utime);
      EXPECT_EQ(e.truth.utime, e.utime);
      EXPECT_EQ(e.camera_indices, std::vector<size_t>{j + 1});
      ASSERT_EQ(e.truth.num_boxes, 1);
      EXPECT_EQ(e.truth.boxes[0].camera_id, static_cast<int>(j + 1));
      // The leader where it is at the exposure: moved on by its velocity (1.5 m/s^2 at most over 25 ms: < 0.5 mm).
      Eigen::Vector3d p;
      for (int c = 0; c < 3; ++c) p[c] = e.truth.vehicles[1].p_body_in_world[c];
      const double dt = static_cast<double>(step_us[j + 1]) * 1e-6;
      EXPECT_LT((p - (p0 + v0 * dt)).norm(), 1e-3);
      largest_move_m = std::max(largest_move_m, (p - p0).norm());
    }
    // Camera 0 exposes at t_k in both: the same boxes as the rig exposed together, to the leader's dynamics being
    // integrated in steps split at the later exposures (measured: 0.02 px after 1 s, growing slowly; an exposure a
    // frame off would move the box by about 5 px).
    std::vector<wingman::truth_box_t> cam0;
    for (const auto& box : fa.truth.boxes)
      if (box.camera_id == 0) cam0.push_back(box);
    ASSERT_EQ(fb.truth.boxes.size(), cam0.size());
    for (size_t n = 0; n < cam0.size(); ++n) {
      EXPECT_NEAR(fb.truth.boxes[n].cx, cam0[n].cx, 0.1);
      EXPECT_NEAR(fb.truth.boxes[n].w, cam0[n].w, 0.1);
    }
  }
  EXPECT_GT(largest_move_m, 0.01) << "the leader moved between the exposures of a frame";

  // The last camera must expose within the frame period: 3 x 12 ms at 30 Hz is beyond it; no rig, nothing to stagger.
  o.camera_stagger_s = 0.012;
  try {
    (void)wingman::sim::sim_cameras(o);
    FAIL() << "no error";
  } catch (const wingman::common::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("cameras.stagger_s = 0.012"), std::string::npos) << e.what();
  }
  o.camera_rig.clear();
  o.camera_stagger_s = 0.005;
  const auto problems = o.validate();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("cameras.stagger_s"), std::string::npos) << problems[0];
  o.camera_rig = source_path("config/rigs/surround4.yaml");
  o.camera_stagger_s = -0.001;
  EXPECT_EQ(o.validate().size(), 1u);
}

}  // namespace
