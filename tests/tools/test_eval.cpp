// SPDX-License-Identifier: MIT
// Tests of `wingman eval`: errors against hand-computed values from a synthetic log, false targets, formation error.
#include "test_support.hpp"

#include <wingman/tools/eval.hpp>

#include <wingman/detections_t.hpp>
#include <wingman/ground_truth_t.hpp>
#include <wingman/targets_t.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

namespace wingman::tools {
namespace {

using testing::make_event;

constexpr int64_t kT0 = 1767225600000000;

vehicle_truth_t vehicle(int id, double x, double y, double z) {
  vehicle_truth_t v{};
  v.vehicle_id = id;
  v.name = id == 0 ? "follower" : "leader";
  v.p_body_in_world[0] = x;
  v.p_body_in_world[1] = y;
  v.p_body_in_world[2] = z;
  v.q_body_to_world[0] = 1.0;
  v.bounding_radius = 0.348;
  return v;
}

target_t world_target(int id, double x, double y, double z, int64_t utime) {
  target_t t{};
  t.track_id = id;
  t.p_target_in_world[0] = x;
  t.p_target_in_world[1] = y;
  t.p_target_in_world[2] = z;
  t.world_valid = true;
  t.range = 1.0;
  t.confidence = 1.0f;
  t.source_utime = utime;
  t.predicted_utime = utime;
  return t;
}

/// Ten frames at 10 Hz: leader moving +x at 1 m/s from (0, 10, 5), follower fixed at (0, 0, 5). The estimate at
/// frame k is off by (+0.3, -0.4, 0) (|e| = 0.5 m) on even frames and exact on odd ones; one false target far away.
std::string write_flight(const testing::TempDir& dir) {
  std::vector<testing::LogEvent> events;
  for (int k = 0; k < 10; ++k) {
    const int64_t u = kT0 + k * 100000;
    ground_truth_t g{};
    g.utime = u;
    g.image_seq = k;
    g.vehicles = {vehicle(0, 0, 0, 5), vehicle(1, 0.1 * k, 10, 5)};
    g.num_vehicles = 2;
    truth_box_t b{};
    b.vehicle_id = 1;
    b.cx = b.cy = 100;
    b.w = b.h = 10;
    b.visible = k != 9;  // last frame: not visible
    b.range = 10;
    g.boxes = {b};
    g.num_boxes = 1;
    events.push_back(make_event("GROUND_TRUTH", g, u));

    detections_t d{};
    d.utime = u;
    d.seq = k;
    d.image_width = 640;
    d.image_height = 480;
    d.source = detections_t::SOURCE_GROUND_TRUTH;
    if (k != 3) {  // frame 3: missed
      detection_t det{};
      det.cx = det.cy = 100;
      det.w = det.h = 10;
      det.confidence = 1.0f;
      d.detections = {det};
      d.num_detections = 1;
    }
    events.push_back(make_event("DETECTIONS_CAM0", d, u));

    targets_t ts{};
    ts.utime = u;
    const double ex = (k % 2 == 0) ? 0.3 : 0.0, ey = (k % 2 == 0) ? -0.4 : 0.0;
    ts.targets = {world_target(7, 0.1 * k + ex, 10 + ey, 5, u)};
    if (k == 5) ts.targets.push_back(world_target(8, 50, 50, 50, u));
    ts.num_targets = static_cast<int32_t>(ts.targets.size());
    events.push_back(make_event("TARGETS", ts, u));
  }
  const std::string path = dir.path() + "/flight.lcmlog";
  testing::write_log(path, events);
  return path;
}

TEST(Eval, LocalizationErrorsMatchHandComputedValues) {
  testing::TempDir dir;
  EvalOptions o;
  o.log = write_flight(dir);
  const EvalResult r = evaluate_log(o);
  EXPECT_EQ(r.detection_source, "ground_truth");
  EXPECT_EQ(r.truth_frames, 10);
  EXPECT_EQ(r.frames_leader_visible, 9);
  EXPECT_EQ(r.frames_leader_detected, 8);  // frame 3 missed, frame 9 not visible
  EXPECT_EQ(r.target_estimates, 10);
  EXPECT_EQ(r.false_targets, 1);
  EXPECT_EQ(r.track_ids_on_leader, 1);
  // Five errors of 0.5 m and five of 0: RMS sqrt(5 * 0.25 / 10), mean 0.25, max 0.5.
  EXPECT_NEAR(r.localization.rms, std::sqrt(0.125), 1e-9);
  EXPECT_NEAR(r.localization.mean, 0.25, 1e-9);
  EXPECT_NEAR(r.localization.max, 0.5, 1e-9);
  EXPECT_NEAR(r.localization_axis[0].rms, std::sqrt(5 * 0.09 / 10), 1e-9);
  EXPECT_NEAR(r.localization_axis[1].rms, std::sqrt(5 * 0.16 / 10), 1e-9);
  EXPECT_NEAR(r.localization_axis[2].max, 0.0, 1e-12);
  // Line of sight: from (0,0,5) to (0.1k, 10, 5): mostly +y, so the -0.4 m error is mostly along it.
  EXPECT_GT(r.along_line_of_sight.max, 0.35);
  EXPECT_LT(r.across_line_of_sight.max, 0.35);
  EXPECT_EQ(r.formation_horizontal.n, 0);  // no formation requested
  EXPECT_NE(r.report().find("GROUND TRUTH"), std::string::npos);
}

TEST(Eval, FormationErrorIsFollowerMinusLeaderPlusOffsetAfterSettling) {
  testing::TempDir dir;
  EvalOptions o;
  o.log = write_flight(dir);
  o.has_formation = true;
  o.formation_offset_in_world = {0.0, -10.0, 0.0};  // desired follower: leader - 10 m north
  o.formation_height_m = 5.0;
  o.settle_s = 0.45;  // frames 5..9
  o.report_path = dir.path() + "/report.html";
  o.json_path = dir.path() + "/eval.json";
  const EvalResult r = evaluate_log(o);
  // Desired position (0.1k, 0, 5), follower at (0, 0, 5): horizontal error 0.1k for k = 5..9.
  ASSERT_EQ(r.formation_horizontal.n, 5);
  EXPECT_NEAR(r.formation_horizontal.max, 0.9, 1e-9);
  EXPECT_NEAR(r.formation_horizontal.mean, (0.5 + 0.6 + 0.7 + 0.8 + 0.9) / 5, 1e-9);
  EXPECT_NEAR(r.formation_vertical.max, 0.0, 1e-12);
  std::ifstream html(o.report_path);
  std::stringstream s;
  s << html.rdbuf();
  EXPECT_NE(s.str().find("<svg id=\"topdown\""), std::string::npos);
  EXPECT_NE(s.str().find("<polyline"), std::string::npos);
  EXPECT_NE(s.str().find("Detections came from simulator ground truth"), std::string::npos);
  std::ifstream js(o.json_path);
  std::stringstream j;
  j << js.rdbuf();
  EXPECT_NE(j.str().find("\"formation_horizontal\": {\"n\": 5"), std::string::npos) << j.str();
}

TEST(Eval, MissingLogOrTruthIsAClearError) {
  testing::TempDir dir;
  EvalOptions o;
  o.log = dir.path() + "/nope.lcmlog";
  try {
    evaluate_log(o);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nope.lcmlog"), std::string::npos) << e.what();
  }
  const std::string empty = dir.path() + "/empty.lcmlog";
  testing::write_log(empty, {});
  o.log = empty;
  try {
    evaluate_log(o);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no ground_truth_t"), std::string::npos) << e.what();
  }
  o.settle_s = -1;
  EXPECT_THROW(evaluate_log(o), std::invalid_argument);
}

}  // namespace
}  // namespace wingman::tools
