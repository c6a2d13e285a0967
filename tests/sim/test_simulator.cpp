// SPDX-License-Identifier: MIT
// The Simulator without rendering: frame times, setpoint timing (command delay, late, ignored), own pose and truth,
// truth boxes projected from the models, the camera tilting with the body, the static sweep and the 1-D random
// walk flown through the dynamics, determinism, and detections built from ground truth.
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <wingman/common/message_validation.hpp>
#include <wingman/geometry/sphere_projection.hpp>
#include <wingman/sim/scenario.hpp>
#include <wingman/sim/simulator.hpp>
#include <wingman/sim/truth_detections.hpp>

#include <cmath>
#include <iostream>

namespace {

using wingman::setpoint_t;
using wingman::sim::Scenario;
using wingman::sim::SimCamera;
using wingman::sim::SimFrame;
using wingman::sim::Simulator;
using wingman::testing::source_path;

constexpr int64_t kStart = 1767225600000000;

/// The localizer's built-in camera (config/localizer.yaml): pinhole 1280x720, f = 640 px, looking along body +x.
SimCamera default_camera(double rate_hz = 30.0) {
  return SimCamera{wingman::geometry::CameraModel::pinhole(1280, 720, 640, 640, 639.5, 359.5),
                   wingman::geometry::Extrinsics::from_options({}), rate_hz, 0};
}

Scenario scenario(const std::string& name) {
  return wingman::sim::load_scenario(source_path("config/scenarios/" + name + ".yaml"));
}

setpoint_t velocity_setpoint(int64_t utime, double ve, double vn, double vu = 0.0) {
  setpoint_t sp{};
  sp.utime = utime;
  sp.mode = setpoint_t::MODE_VELOCITY;
  sp.frame = wingman::own_pose_t::FRAME_ENU;
  sp.velocity[0] = ve;
  sp.velocity[1] = vn;
  sp.velocity[2] = vu;
  return sp;
}

Eigen::Vector3d vec(const double (&v)[3]) { return {v[0], v[1], v[2]}; }

const wingman::vehicle_truth_t& truth_of(const SimFrame& f, int id) {
  for (const auto& v : f.truth.vehicles) {
    if (v.vehicle_id == id) return v;
  }
  throw std::logic_error("no vehicle " + std::to_string(id));
}

const wingman::truth_box_t& box_of(const SimFrame& f, int id) {
  for (const auto& b : f.truth.boxes) {
    if (b.vehicle_id == id) return b;
  }
  throw std::logic_error("no box for vehicle " + std::to_string(id));
}

std::vector<uint8_t> encode(const wingman::ground_truth_t& m) {
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

TEST(Simulator, FramesAreAtStartPlusKOverRateUntilTheDuration) {
  Simulator sim(scenario("follow_1d"), default_camera());
  EXPECT_EQ(sim.frame_count(), 180 * 30);
  EXPECT_TRUE(sim.takes_setpoints());
  for (int64_t k = 0; k < 4; ++k) {
    const SimFrame f = sim.step();
    EXPECT_EQ(f.index, k);
    EXPECT_EQ(f.utime, kStart + std::llround(k * 1e6 / 30.0));
    EXPECT_EQ(f.own_pose.utime, f.utime);
    EXPECT_EQ(f.truth.utime, f.utime);
    EXPECT_EQ(f.truth.image_seq, -1);  // no renderer: no image
    EXPECT_TRUE(f.bgr.empty());
    EXPECT_EQ(f.truth.num_vehicles, 2);
    EXPECT_EQ(f.truth.num_boxes, 1);  // the camera vehicle has no box
  }
  EXPECT_EQ(Simulator(scenario("static_sweep"), default_camera()).frame_count(), 11900);
  EXPECT_EQ(Simulator(scenario("static_sweep"), default_camera(10.0)).frame_count(), 11900);  // counted in frames
}

TEST(Simulator, OwnPoseIsTheCameraVehiclesTruth) {
  Simulator sim(scenario("follow_1d"), default_camera());
  sim.step();
  sim.on_setpoint(velocity_setpoint(kStart, 1.0, 0.5));
  for (int k = 1; k < 60; ++k) {
    const SimFrame f = sim.step();
    const auto& t = truth_of(f, 0);
    EXPECT_EQ(vec(f.own_pose.p_body_in_world), vec(t.p_body_in_world));
    EXPECT_EQ(vec(f.own_pose.v_body_in_world), vec(t.v_body_in_world));
    for (int i = 0; i < 4; ++i) EXPECT_EQ(f.own_pose.q_body_to_world[i], t.q_body_to_world[i]);
    EXPECT_EQ(int{f.own_pose.frame}, int{wingman::own_pose_t::FRAME_ENU});
    EXPECT_EQ(t.name, "follower");
  }
}

TEST(Simulator, TheReportedOwnPoseCarriesTheConfiguredErrorAndItsCovariance) {
  // own_pose.position_std_m 0.5, attitude_std_rad 0.02, correlation 0.5 s, over 60 s at 30 Hz (seed 3): the sample
  // std of the reported-minus-true position and rotation is the configured one within 25 % (about 120 correlation
  // times: a sampling error near 13 % of the std), successive errors are correlated as exp(-dt / tau), and the
  // message reports the variances. The true pose (ground truth, the camera) is untouched.
  Simulator sim(scenario("follow_1d"), default_camera());
  wingman::sim::OwnPoseErrorOptions o;
  o.position_std_m = 0.5;
  o.attitude_std_rad = 0.02;
  o.correlation_time_s = 0.5;
  o.seed = 3;
  sim.set_own_pose_error(o);
  double sum_p2 = 0, sum_a2 = 0, lag1 = 0, sum_x2 = 0;
  int n = 0;
  double previous_ex = 0;
  for (int k = 0; k < 1800; ++k) {
    const SimFrame f = sim.step();
    const auto& t = truth_of(f, 0);
    const Eigen::Vector3d dp = vec(f.own_pose.p_body_in_world) - vec(t.p_body_in_world);
    const Eigen::Quaterniond q_rep(f.own_pose.q_body_to_world[0], f.own_pose.q_body_to_world[1],
                                   f.own_pose.q_body_to_world[2], f.own_pose.q_body_to_world[3]);
    const Eigen::Quaterniond q_true(t.q_body_to_world[0], t.q_body_to_world[1], t.q_body_to_world[2],
                                    t.q_body_to_world[3]);
    const Eigen::AngleAxisd d(q_true.conjugate() * q_rep);  // the rotation error in the body frame
    sum_p2 += dp.squaredNorm() / 3;
    sum_a2 += std::pow(d.angle(), 2) / 3;
    if (k > 0) lag1 += dp.x() * previous_ex;
    sum_x2 += dp.x() * dp.x();
    previous_ex = dp.x();
    ++n;
    EXPECT_TRUE(f.own_pose.has_covariance);
    EXPECT_DOUBLE_EQ(f.own_pose.cov_p_body_in_world[0], 0.25);
    EXPECT_DOUBLE_EQ(f.own_pose.cov_p_body_in_world[3], 0.25);
    EXPECT_DOUBLE_EQ(f.own_pose.cov_p_body_in_world[5], 0.25);
    EXPECT_DOUBLE_EQ(f.own_pose.cov_p_body_in_world[1], 0.0);
    EXPECT_DOUBLE_EQ(f.own_pose.var_rpy_body[2], 0.0004);
    EXPECT_EQ(wingman::common::validate_message(f.own_pose), "");
    EXPECT_TRUE((f.own_reported.p_body_in_world - dp - vec(t.p_body_in_world)).isZero(1e-9));
  }
  EXPECT_NEAR(std::sqrt(sum_p2 / n), 0.5, 0.125);
  EXPECT_NEAR(std::sqrt(sum_a2 / n), 0.02, 0.005);
  // Lag-one correlation of x over 1/30 s: exp(-1/15) = 0.936.
  EXPECT_NEAR(lag1 / (n - 1) / (sum_x2 / n), std::exp(-1.0 / 15.0), 0.03);

  // report_covariance false: the same error, reported as unknown.
  Simulator quiet(scenario("follow_1d"), default_camera());
  o.report_covariance = false;
  quiet.set_own_pose_error(o);
  const SimFrame f = quiet.step();
  EXPECT_FALSE(f.own_pose.has_covariance);
  EXPECT_EQ(wingman::common::validate_message(f.own_pose), "");
  EXPECT_GT((vec(f.own_pose.p_body_in_world) - vec(truth_of(f, 0).p_body_in_world)).norm(), 0.0);
  // Bad options are named.
  o.correlation_time_s = 0;
  try {
    quiet.set_own_pose_error(o);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("own_pose.correlation_time_s"), std::string::npos) << e.what();
  }
}

TEST(Simulator, ASetpointTakesEffectAfterTheCommandDelay) {
  Simulator sim(scenario("follow_1d"), default_camera());  // command_delay_s 0.1 = 3 frames at 30 Hz
  const SimFrame f0 = sim.step();
  sim.on_setpoint(velocity_setpoint(f0.utime, 1.0, 0.0));
  EXPECT_EQ(sim.setpoint_counts().queued, 1);
  const Eigen::Vector3d p0 = vec(f0.own_pose.p_body_in_world);
  for (int k = 1; k <= 3; ++k) {  // t_3 = t_0 + 100 ms exactly: the command starts there
    const SimFrame f = sim.step();
    EXPECT_EQ(vec(f.own_pose.p_body_in_world), p0) << "frame " << k;
    EXPECT_EQ(vec(f.own_pose.v_body_in_world), Eigen::Vector3d::Zero()) << "frame " << k;
  }
  const SimFrame f4 = sim.step();
  EXPECT_GT(f4.own_pose.v_body_in_world[0], 0.05);
  EXPECT_GT(f4.own_pose.p_body_in_world[0], p0.x());
  // A setpoint whose time + delay has passed applies at once and is counted as late.
  sim.on_setpoint(velocity_setpoint(f0.utime, 0.0, 0.0));
  EXPECT_EQ(sim.setpoint_counts().late, 1);
  // A malformed one is refused.
  setpoint_t bad = velocity_setpoint(f4.utime, NAN, 0);
  EXPECT_THROW(sim.on_setpoint(bad), std::invalid_argument);
}

TEST(Simulator, AScriptedCameraVehicleIgnoresSetpoints) {
  Simulator sim(scenario("static_sweep"), default_camera());
  EXPECT_FALSE(sim.takes_setpoints());
  sim.step();
  sim.on_setpoint(velocity_setpoint(kStart, 1.0, 0.0));
  EXPECT_EQ(sim.setpoint_counts().ignored, 1);
}

TEST(Simulator, TruthBoxOfATargetStraightAheadIsCentredWithTheRightSizeAndRange) {
  Simulator sim(scenario("follow_1d"), default_camera());
  const SimFrame f = sim.step();  // leader 8 m straight ahead of the camera, same height
  const auto& b = box_of(f, 1);
  EXPECT_TRUE(b.visible);
  EXPECT_EQ(b.camera_id, 0);
  EXPECT_NEAR(b.range, 8.0, 1e-12);
  EXPECT_NEAR(b.cx, 640.0, 4.0);  // the propellers' angles make the silhouette slightly asymmetric
  EXPECT_GT(b.cy, 360.0);         // the landing gear reaches lower below the body origin than the motors above it
  EXPECT_LT(b.cy, 370.0);
  // Width: at most the bounding sphere's (0.348 m); at least the motor axes' spread seen from behind (arms at 45
  // degrees in the X layout: 2 x 0.23 / sqrt(2) m).
  const double r = truth_of(f, 1).bounding_radius;
  EXPECT_NEAR(r, 0.348, 0.002);
  EXPECT_LE(b.w, 2 * 640 * r / std::sqrt(64 - r * r) + 0.5);
  EXPECT_GE(b.w, 2 * 640 * (0.23 / std::sqrt(2.0)) / 8.0);
  EXPECT_LT(b.h, b.w);  // a multirotor seen from the side is flat
}

TEST(Simulator, ATargetBehindTheCameraIsNotVisible) {
  Scenario s = scenario("follow_1d");
  s.vehicles[1].motion.type = wingman::sim::MotionSpec::Type::kHover;
  s.vehicles[1].p_initial_in_world = {0, -8, 5};
  Simulator sim(s, default_camera());
  const auto frame = sim.step();  // box_of refers into it: keep it alive
  const auto& b = box_of(frame, 1);
  EXPECT_FALSE(b.visible);
  EXPECT_NEAR(b.range, 8.0, 1e-12);
}

TEST(Simulator, TheCameraTiltsWithTheBodyWhenTheVehicleAccelerates) {
  Scenario s = scenario("follow_1d");
  s.vehicles[1].motion.type = wingman::sim::MotionSpec::Type::kHover;  // a still target
  Simulator sim(s, default_camera());
  const SimFrame level = sim.step();
  EXPECT_NEAR(level.T_cam_to_world.linear().col(2).z(), 0.0, 1e-12);  // optical axis horizontal in hover
  sim.on_setpoint(velocity_setpoint(level.utime, 0.0, 3.0));          // forward (north), hard
  SimFrame f = sim.step();
  while (f.utime < level.utime + 200000) f = sim.step();  // 0.1 s after the command took effect
  const double a = truth_of(f, 0).v_body_in_world[1];
  ASSERT_GT(a, 0.1);
  // Pitched nose-down by atan(a / g) with a at the acceleration limit (3 m/s^2 in follow_1d): the optical axis
  // points below the horizon by that angle, and the target, level with the camera, moves up in the image.
  const double tilt = std::atan(3.0 / wingman::sim::kGravity);
  EXPECT_NEAR(std::asin(-f.T_cam_to_world.linear().col(2).z()), tilt, 1e-9);
  const double dv = box_of(f, 1).cy - box_of(level, 1).cy;
  EXPECT_LT(dv, -0.8 * 640 * std::tan(tilt));  // ~ -f tan(tilt) = -194 px (less the approach's parallax)
}

TEST(Simulator, StaticSweepStepsTheCameraByAQuarterMetreEveryHundredFrames) {
  Simulator sim(scenario("static_sweep"), default_camera());
  ASSERT_EQ(sim.frame_count(), 11900);
  int64_t k = 0;
  while (!sim.done()) {
    const SimFrame f = sim.step();
    const double expected = 0.5 + 0.25 * static_cast<double>(k / 100);
    ASSERT_EQ(f.index, k);
    ASSERT_NEAR(box_of(f, 1).range, expected, 1e-9) << "frame " << k;
    ASSERT_EQ(vec(truth_of(f, 0).v_body_in_world), Eigen::Vector3d::Zero());
    ASSERT_EQ(vec(truth_of(f, 1).p_body_in_world), Eigen::Vector3d(0, 0, 5));  // the target hovers
    ASSERT_TRUE(box_of(f, 1).visible) << "frame " << k;
    ++k;
  }
  EXPECT_EQ(k, 11900);
}

/// Flies follow_1d with a simple follower (velocity towards the leader's x, from the truth) for `frames` frames.
std::vector<std::vector<uint8_t>> fly_follow_1d(int frames, uint64_t walk_seed, double* max_leader_speed = nullptr,
                                                double* max_leader_x = nullptr) {
  Scenario s = scenario("follow_1d");
  s.vehicles[1].motion.seed = walk_seed;
  Simulator sim(s, default_camera());
  std::vector<std::vector<uint8_t>> out;
  for (int k = 0; k < frames && !sim.done(); ++k) {
    const SimFrame f = sim.step();
    out.push_back(encode(f.truth));
    const double dx = truth_of(f, 1).p_body_in_world[0] - truth_of(f, 0).p_body_in_world[0];
    sim.on_setpoint(velocity_setpoint(f.utime, std::clamp(0.8 * dx, -2.0, 2.0), 0.0));
    const auto& leader = truth_of(f, 1);
    if (max_leader_speed)
      *max_leader_speed = std::max(*max_leader_speed, std::hypot(leader.v_body_in_world[0], leader.v_body_in_world[1]));
    if (max_leader_x) *max_leader_x = std::max(*max_leader_x, std::abs(leader.p_body_in_world[0]));
  }
  return out;
}

TEST(Simulator, TheOneDimensionalLeaderStaysWithinTwentyMetresAtHalfAMetrePerSecond) {
  double max_speed = 0, max_x = 0;
  fly_follow_1d(180 * 30, 7, &max_speed, &max_x);
  EXPECT_LE(max_speed, 0.5 + 1e-12);  // the leader's dynamics clamp its speed at 0.5 m/s
  EXPECT_GT(max_speed, 0.45);
  // The reference stays in [-20, 20] (MotionScript test); the flown leader follows it with acceleration
  // feed-forward, so it leaves the segment by at most a centimetre at the turns.
  EXPECT_LE(max_x, 20.01);
  EXPECT_GT(max_x, 10.0);
}

TEST(Simulator, SameScenarioAndSetpointsGiveTheSameTruthBitForBit) {
  const auto a = fly_follow_1d(600, 7);
  const auto b = fly_follow_1d(600, 7);
  ASSERT_EQ(a.size(), 600u);
  EXPECT_EQ(a, b);
  const auto c = fly_follow_1d(600, 8);  // another walk seed: another run
  EXPECT_NE(a, c);
}

const wingman::geometry::CameraModel kCamera = default_camera().model;

TEST(TruthDetections, VisibleBoxesOfThisCameraBecomeGroundTruthDetections) {
  wingman::ground_truth_t t{};
  t.utime = kStart;
  auto add = [&](int id, int camera, float cx, float cy, float w, float h, bool visible, double range) {
    wingman::truth_box_t b{};
    b.vehicle_id = id;
    b.camera_id = camera;
    b.cx = cx, b.cy = cy, b.w = w, b.h = h, b.visible = visible, b.range = range;
    t.boxes.push_back(b);
  };
  add(1, 0, 640, 360, 100, 40, true, 8);
  add(2, 0, 100, 100, 30, 10, false, 5);  // not visible
  add(3, 1, 300, 300, 30, 10, true, 5);   // another camera
  add(4, 0, 1270, 50, 40, 20, true, 60);  // far, and cut by the right border
  add(5, 0, 600, 600, 1, 1, true, 90);    // too small
  t.num_boxes = static_cast<int32_t>(t.boxes.size());
  wingman::sim::TruthDetectionOptions o;
  o.from_ground_truth = true;
  auto d = wingman::sim::truth_detections(t, 42, kCamera, Eigen::Isometry3d::Identity(), 0, o);
  EXPECT_EQ(d.utime, kStart);
  EXPECT_EQ(d.seq, 42);
  EXPECT_EQ(int{d.source}, int{wingman::detections_t::SOURCE_GROUND_TRUTH});
  EXPECT_EQ(d.image_width, 1280);
  EXPECT_EQ(d.image_height, 720);
  ASSERT_EQ(d.num_detections, 2);
  EXPECT_EQ(d.detections[0].cx, 640);
  EXPECT_EQ(d.detections[0].w, 100);
  EXPECT_EQ(d.detections[0].confidence, 1.0f);
  EXPECT_EQ(d.detections[0].class_id, 0);  // every simulated vehicle is a drone
  EXPECT_EQ(d.detections[0].drone_score, 1.0f);
  EXPECT_EQ(d.detections[1].cx, 1265);  // clipped to the image: [1250, 1280]
  EXPECT_EQ(d.detections[1].w, 30);
  o.max_range_m = 50;
  EXPECT_EQ(wingman::sim::truth_detections(t, 42, kCamera, Eigen::Isometry3d::Identity(), 0, o).num_detections, 1);
}

TEST(TruthDetections, EdgeNoiseHasTheConfiguredDeviationAndRepeatsWithTheSeed) {
  wingman::ground_truth_t t{};
  wingman::truth_box_t b{};
  b.cx = 640, b.cy = 360, b.w = 100, b.h = 80, b.visible = true;
  t.boxes.push_back(b);
  t.num_boxes = 1;
  wingman::sim::TruthDetectionOptions o;
  o.noise_px = 2.0;
  o.seed = 9;
  double sum = 0, sum2 = 0;
  int n = 0;
  for (int64_t seq = 0; seq < 1000; ++seq) {
    const auto d = wingman::sim::truth_detections(t, seq, kCamera, Eigen::Isometry3d::Identity(), 0, o);
    ASSERT_EQ(d.num_detections, 1);
    const auto& x = d.detections[0];
    for (double e : {x.cx - x.w / 2 - 590.0, x.cx + x.w / 2 - 690.0, x.cy - x.h / 2 - 320.0, x.cy + x.h / 2 - 400.0}) {
      sum += e;
      sum2 += e * e;
      ++n;
    }
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  // 4000 edges: the standard error of the mean is 0.03 px and that of the deviation about 1.1 %.
  EXPECT_NEAR(mean, 0.0, 0.1);
  EXPECT_NEAR(sd, 2.0, 0.1);
  const auto a = wingman::sim::truth_detections(t, 5, kCamera, Eigen::Isometry3d::Identity(), 0, o);
  const auto a2 = wingman::sim::truth_detections(t, 5, kCamera, Eigen::Isometry3d::Identity(), 0, o);
  EXPECT_EQ(a.detections[0].cx, a2.detections[0].cx);
  o.seed = 10;
  EXPECT_NE(wingman::sim::truth_detections(t, 5, kCamera, Eigen::Isometry3d::Identity(), 0, o).detections[0].cx,
            a.detections[0].cx);
}

}  // namespace

namespace {

TEST(TruthDetections, SphereBoxesAreTheBoundingSpheresExactBoxWhichTheLocalizerInverts) {
  // The follow_1d leader seen by the follower, with detections.box sphere: the box is the exact image of the
  // model's bounding sphere, so the localizer's sphere model (same radius) recovers the true position.
  Simulator sim(scenario("follow_1d"), default_camera());
  sim.step();
  sim.on_setpoint(velocity_setpoint(kStart, -0.7, 0.0));  // move so that the leader is off the optical axis
  SimFrame f = sim.step();
  for (int k = 0; k < 60; ++k) f = sim.step();
  wingman::sim::TruthDetectionOptions o;
  o.box = "sphere";
  const auto d = wingman::sim::truth_detections(f.truth, f.index, kCamera, f.T_cam_to_world, 0, o);
  ASSERT_EQ(d.num_detections, 1);
  const auto& leader = truth_of(f, 1);
  const Eigen::Vector3d p_in_cam = f.T_cam_to_world.inverse() * vec(leader.p_body_in_world);
  const auto expected = wingman::geometry::project_sphere(kCamera, p_in_cam, leader.bounding_radius).pixel_box();
  EXPECT_GT(std::abs(expected.cx - 640), 20.0);  // off-axis
  EXPECT_NEAR(d.detections[0].cx, expected.cx, 1e-3);
  EXPECT_NEAR(d.detections[0].cy, expected.cy, 1e-3);
  EXPECT_NEAR(d.detections[0].w, expected.w, 1e-3);
  EXPECT_NEAR(d.detections[0].h, expected.h, 1e-3);
  // The drone lies inside its bounding sphere, so its silhouette box lies inside the sphere's box, whatever the
  // propellers' angles (which make the silhouette's width vary from frame to frame).
  double min_ratio = 1, max_ratio = 0;
  for (int k = 0; k < 30; ++k, f = sim.step()) {
    o.box = "sphere";
    const auto sp = wingman::sim::truth_detections(f.truth, f.index, kCamera, f.T_cam_to_world, 0, o).detections.at(0);
    o.box = "silhouette";
    const auto si = wingman::sim::truth_detections(f.truth, f.index, kCamera, f.T_cam_to_world, 0, o).detections.at(0);
    ASSERT_GE(si.cx - si.w / 2, sp.cx - sp.w / 2 - 1e-3) << "frame " << f.index;
    ASSERT_LE(si.cx + si.w / 2, sp.cx + sp.w / 2 + 1e-3) << "frame " << f.index;
    ASSERT_GE(si.cy - si.h / 2, sp.cy - sp.h / 2 - 1e-3) << "frame " << f.index;
    ASSERT_LE(si.cy + si.h / 2, sp.cy + sp.h / 2 + 1e-3) << "frame " << f.index;
    min_ratio = std::min(min_ratio, static_cast<double>(si.w / sp.w));
    max_ratio = std::max(max_ratio, static_cast<double>(si.w / sp.w));
  }
  EXPECT_LT(min_ratio, 0.8);  // seen from behind, the outline is much narrower than the sphere at some angles
  std::cout << "silhouette / sphere box width over 30 frames: " << min_ratio << " .. " << max_ratio << std::endl;
}

}  // namespace
