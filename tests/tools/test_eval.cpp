// SPDX-License-Identifier: MIT
// Tests of `wingman eval` and `wingman report`: every metric against hand-computed values from synthetic logs.
#include "test_support.hpp"

#include <wingman/tools/eval.hpp>
#include <wingman/tools/report.hpp>

#include <wingman/detections_t.hpp>
#include <wingman/ground_truth_t.hpp>
#include <wingman/image_t.hpp>
#include <wingman/status_t.hpp>
#include <wingman/targets_t.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
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
  t.radius_m = 0.348;
  t.radius_sigma_m = 0.0125;
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

TEST(Eval, NamesEachDetectorsBackendFromItsHeartbeat) {
  // The two backends' boxes differ in the 4th decimal, so a flight's figures are those of the backend that ran: the
  // first heartbeat of each STATUS_DETECTOR... channel whose detail names it is in the JSON and the report. Other
  // heartbeats (other processes, later details) are not.
  testing::TempDir dir;
  const std::string flight = write_flight(dir);
  std::vector<testing::LogEvent> events = testing::read_log(flight);
  const auto heartbeat = [](const std::string& process, const std::string& detail, int64_t u) {
    status_t s{};
    s.utime = u;
    s.process = process;
    s.pid = 1;
    s.state = status_t::STATE_OK;
    s.detail = detail;
    return s;
  };
  const std::string ocl =
      "backend opencl: pthread (auto, not timed: OpenCL whenever a device is usable, so that runs repeat)";
  events.push_back(make_event("STATUS_DETECTOR", heartbeat("detector", "waiting for images", kT0), kT0));
  events.push_back(make_event("STATUS_DETECTOR", heartbeat("detector", ocl, kT0 + 1), kT0 + 1));
  events.push_back(
      make_event("STATUS_DETECTOR", heartbeat("detector", "backend cpu (a later line)", kT0 + 2), kT0 + 2));
  events.push_back(make_event("STATUS_DETECTOR_CAM1",
                              heartbeat("detector_cam1", "backend cpu (OpenCV DNN), as configured", kT0), kT0));
  events.push_back(make_event("STATUS_LOCALIZER", heartbeat("localizer", "backend of nothing", kT0), kT0));
  EvalOptions o;
  o.log = dir.file("with_heartbeats.lcmlog");
  testing::write_log(o.log, events);
  const EvalResult r = evaluate_log(o);
  const std::map<std::string, std::string> want = {{"STATUS_DETECTOR", ocl},
                                                   {"STATUS_DETECTOR_CAM1", "backend cpu (OpenCV DNN), as configured"}};
  EXPECT_EQ(r.detector_backends, want);
  const auto j = nlohmann::json::parse(r.json());
  EXPECT_EQ(j["detector_backends"]["STATUS_DETECTOR"], ocl);
  EXPECT_EQ(j["detector_backends"].size(), 2u);
  EXPECT_NE(r.report().find("detector (STATUS_DETECTOR): " + ocl + "\n"), std::string::npos) << r.report();

  EvalOptions without;
  without.log = flight;
  const EvalResult none = evaluate_log(without);
  EXPECT_TRUE(none.detector_backends.empty());
  EXPECT_TRUE(nlohmann::json::parse(none.json())["detector_backends"].empty());
  EXPECT_EQ(none.report().find("detector ("), std::string::npos);
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
  write_html_report(r, o, o.report_path);  // evaluate_log leaves the HTML page to its caller
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
  EXPECT_NE(s.str().find("id=\"no-images\""), std::string::npos);  // the log has no IMAGE_CAM0
  std::ifstream js(o.json_path);
  std::stringstream j;
  j << js.rdbuf();
  EXPECT_EQ(nlohmann::json::parse(j.str()).at("formation_horizontal").at("n"), 5) << j.str();
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

ground_truth_t truth_frame(int k, int64_t u, const std::vector<vehicle_truth_t>& vehicles) {
  ground_truth_t g{};
  g.utime = u;
  g.image_seq = k;
  g.vehicles = vehicles;
  g.num_vehicles = static_cast<int32_t>(vehicles.size());
  return g;
}

targets_t targets_msg(int64_t u, const std::vector<target_t>& targets) {
  targets_t ts{};
  ts.utime = u;
  ts.targets = targets;
  ts.num_targets = static_cast<int32_t>(targets.size());
  return ts;
}

/// Follower fixed at (0, 0, 5); at frame k the leader is at (0, d_k, 5), d = 3, 7, 12, 25, 40 m, and its estimate is
/// off by 0.1 (k + 1) m along x.
std::string write_ranges(const testing::TempDir& dir) {
  const double d[] = {3, 7, 12, 25, 40};
  std::vector<testing::LogEvent> events;
  for (int k = 0; k < 5; ++k) {
    const int64_t u = kT0 + k * 100000;
    events.push_back(make_event("GROUND_TRUTH", truth_frame(k, u, {vehicle(0, 0, 0, 5), vehicle(1, 0, d[k], 5)}), u));
    events.push_back(make_event("TARGETS", targets_msg(u, {world_target(7, 0.1 * (k + 1), d[k], 5, u)}), u));
  }
  const std::string path = dir.file("ranges.lcmlog");
  testing::write_log(path, events);
  return path;
}

TEST(Eval, LocalizationErrorIsBinnedByTrueRange) {
  testing::TempDir dir;
  EvalOptions o;
  o.log = write_ranges(dir);
  const EvalResult r = evaluate_log(o);
  // Default bins 0-5, 5-10, 10-15, 15-20, 20-30, 30+: 3 m, 7 m, 12 m, none, 25 m, 40 m.
  ASSERT_EQ(r.localization_by_range.size(), 6u);
  const double expected[] = {0.1, 0.2, 0.3, 0.0, 0.4, 0.5};
  for (size_t i = 0; i < 6; ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(r.localization_by_range[i].error.n, i == 3 ? 0 : 1);
    EXPECT_NEAR(r.localization_by_range[i].error.rms, expected[i], 1e-9);
  }
  EXPECT_EQ(r.localization_by_range[0].lo_m, 0.0);
  EXPECT_EQ(r.localization_by_range[4].hi_m, 30.0);
  EXPECT_TRUE(std::isinf(r.localization_by_range[5].hi_m));

  o.range_bins_m = {10};  // [0, 10): 0.1, 0.2; [10, inf): 0.3, 0.4, 0.5
  const EvalResult r2 = evaluate_log(o);
  ASSERT_EQ(r2.localization_by_range.size(), 2u);
  EXPECT_EQ(r2.localization_by_range[0].error.n, 2);
  EXPECT_NEAR(r2.localization_by_range[0].error.rms, std::sqrt((0.01 + 0.04) / 2), 1e-9);
  EXPECT_EQ(r2.localization_by_range[1].error.n, 3);
  EXPECT_NEAR(r2.localization_by_range[1].error.mean, 0.4, 1e-9);
  EXPECT_NE(r2.report().find("range 10+ m"), std::string::npos) << r2.report();
  const nlohmann::json bins = nlohmann::json::parse(r2.json()).at("localization_by_range");
  ASSERT_EQ(bins.size(), 2u) << r2.json();
  EXPECT_EQ(bins[0].at("lo_m"), 0.0);
  EXPECT_EQ(bins[0].at("hi_m"), 10.0);
  EXPECT_EQ(bins[0].at("error").at("n"), 2);
  EXPECT_NEAR(bins[0]["error"].at("rms_m").get<double>(), std::sqrt((0.01 + 0.04) / 2), 1e-12);
  EXPECT_TRUE(bins[1].at("hi_m").is_null()) << r2.json();  // the last bin is open
}

TEST(Eval, RangeBinsMustIncrease) {
  EvalOptions o;
  o.log = "x.lcmlog";
  o.range_bins_m = {5, 5};
  ASSERT_EQ(o.validate().size(), 1u);
  EXPECT_NE(o.validate()[0].find("--range-bins"), std::string::npos);
  o.range_bins_m = {-1};
  EXPECT_FALSE(o.validate().empty());
  EvalOptions defaults;
  defaults.log = "x.lcmlog";
  EXPECT_TRUE(defaults.validate().empty()) << defaults.validate()[0];  // the defaults are valid
}

/// Leader fixed at (0, 10, 5), ten frames. Leader track ids by frame: 7 7 7 9 9 7 7 7 7 7 (two switches); frame 4
/// also has track 12 on the leader, 1 m off (the leader is track 9's there: a duplicate, not a switch, not an id).
/// False targets: track 20 on frames 2 and 3, track 21 on frame 6.
std::string write_switches(const testing::TempDir& dir) {
  std::vector<testing::LogEvent> events;
  for (int k = 0; k < 10; ++k) {
    const int64_t u = kT0 + k * 100000;
    events.push_back(make_event("GROUND_TRUTH", truth_frame(k, u, {vehicle(0, 0, 0, 5), vehicle(1, 0, 10, 5)}), u));
    std::vector<target_t> ts = {world_target(k == 3 || k == 4 ? 9 : 7, 0, 10, 5, u)};
    if (k == 4) ts.push_back(world_target(12, 1, 10, 5, u));
    if (k == 2 || k == 3) ts.push_back(world_target(20, 50, 50, 50, u));
    if (k == 6) ts.push_back(world_target(21, -50, 50, 50, u));
    events.push_back(make_event("TARGETS", targets_msg(u, ts), u));
  }
  const std::string path = dir.file("switches.lcmlog");
  testing::write_log(path, events);
  return path;
}

/// Ten frames of the follower at the origin, the leader (1) at (0, 10, 5) and vehicle 2 at (`x2`, 10, 5), with the
/// targets `targets(k, utime)` of frame k, evaluated with the default options.
EvalResult evaluate_two_drones(double x2, const std::function<std::vector<target_t>(int, int64_t)>& targets) {
  testing::TempDir dir;
  std::vector<testing::LogEvent> events;
  for (int k = 0; k < 10; ++k) {
    const int64_t u = kT0 + k * 100000;
    events.push_back(make_event(
        "GROUND_TRUTH", truth_frame(k, u, {vehicle(0, 0, 0, 5), vehicle(1, 0, 10, 5), vehicle(2, x2, 10, 5)}), u));
    events.push_back(make_event("TARGETS", targets_msg(u, targets(k, u)), u));
  }
  EvalOptions o;
  o.log = dir.file("two.lcmlog");
  testing::write_log(o.log, events);
  return evaluate_log(o);
}

TEST(Eval, ANeighboursTrackPassingNearerTheLeaderIsNotTheLeadersIdentity) {
  // The leader (1) at (0, 10, 5) is track 3 throughout, 0.6 m off; vehicle 2 stands 2 m east of it, track 4, 0.5 m
  // off, except in frames 4-6, where track 4 (a neighbour's track coasting through a crossing with a range error) lies
  // 0.5 m from the leader, nearer than track 3. One to one, each track keeps its vehicle: no switch and one id each
  // (matched to the nearest vehicle independently, the leader had two ids and two switches).
  const EvalResult r = evaluate_two_drones(2.0, [](int k, int64_t u) {
    const double x4 = k >= 4 && k <= 6 ? 0.5 : 2.5;
    return std::vector<target_t>{world_target(3, -0.6, 10, 5, u), world_target(4, x4, 10, 5, u)};
  });
  EXPECT_EQ(r.track_ids_on_leader, 1);
  EXPECT_EQ(r.leader_id_switches, 0);
  ASSERT_EQ(r.ids_by_vehicle.size(), 2u);
  EXPECT_EQ(r.ids_by_vehicle.at(2).track_ids, 1);
  EXPECT_EQ(r.ids_by_vehicle.at(2).id_switches, 0);
  EXPECT_EQ(r.target_estimates, 20);
  EXPECT_EQ(r.duplicate_targets, 0);
  EXPECT_EQ(r.false_targets, 0);
}

TEST(Eval, CountsTrackIdsAndSwitchesOfEveryVehicleNotOnlyTheLeaders) {
  // Two targets (a crossing scenario): the leader (1) keeps track 3; vehicle 2, 5 m beside it, is track 4 for four
  // frames, then track 5: 2 ids, 1 switch.
  const EvalResult r = evaluate_two_drones(5.0, [](int k, int64_t u) {
    return std::vector<target_t>{world_target(3, 0, 10, 5, u), world_target(k < 4 ? 4 : 5, 5, 10, 5, u)};
  });
  ASSERT_EQ(r.ids_by_vehicle.size(), 2u);
  EXPECT_EQ(r.ids_by_vehicle.at(1).track_ids, 1);
  EXPECT_EQ(r.ids_by_vehicle.at(1).id_switches, 0);
  EXPECT_EQ(r.ids_by_vehicle.at(2).track_ids, 2);
  EXPECT_EQ(r.ids_by_vehicle.at(2).id_switches, 1);
  EXPECT_EQ(r.track_ids_on_leader, 1);
  EXPECT_NE(
      r.report().find("track ids per vehicle: vehicle 1: 1 id(s), 0 switch(es); vehicle 2: 2 id(s), 1 switch(es)"),
      std::string::npos)
      << r.report();
  EXPECT_EQ(
      nlohmann::json::parse(r.json()).at("ids_by_vehicle"),
      nlohmann::json::parse(R"({"1": {"track_ids": 1, "id_switches": 0}, "2": {"track_ids": 2, "id_switches": 1}})"))
      << r.json();
}

TEST(EvalCli, JsonDashPrintsTheJsonAsJsonStdoutDoesAndReportTakesOut) {
  // One meaning per flag: --json FILE writes the JSON, --json - prints it (val too); report's file is --out like
  // the other verbs' (-o and --output still work).
  testing::TempDir dir;
  const std::string log = write_switches(dir), wingman = std::string(WINGMAN_DEFAULT_BIN_DIR) + "/wingman";
  const auto dash = testing::run({wingman, "eval", log, "--json", "-", "--quiet"});
  const auto flag = testing::run({wingman, "eval", log, "--json-stdout", "--quiet"});
  ASSERT_EQ(dash.exit_code, 0) << dash.err;
  ASSERT_EQ(flag.exit_code, 0) << flag.err;
  EXPECT_EQ(nlohmann::ordered_json::parse(dash.out).begin().key(), "detection_source") << dash.out;  // keys in order
  EXPECT_EQ(dash.out, flag.out);
  EXPECT_FALSE(std::ifstream("-").good()) << "no file named -";
  const auto file = testing::run({wingman, "eval", log, "--json", dir.file("e.json"), "--quiet"});
  ASSERT_EQ(file.exit_code, 0) << file.err;
  std::stringstream written;
  written << std::ifstream(dir.file("e.json")).rdbuf();
  EXPECT_EQ(written.str(), dash.out);
  for (const char* out_flag : {"--out", "-o", "--output"}) {
    const std::string html = dir.file(std::string("r") + out_flag + ".html");
    const auto rep = testing::run({wingman, "report", log, out_flag, html, "--quiet"});
    ASSERT_EQ(rep.exit_code, 0) << out_flag << ": " << rep.err;
    EXPECT_TRUE(std::ifstream(html).good()) << out_flag;
  }
}

TEST(Eval, CountsLeaderIdSwitchesAndFalseTracks) {
  testing::TempDir dir;
  EvalOptions o;
  o.log = write_switches(dir);
  o.csv_path = dir.file("targets.csv");
  const EvalResult r = evaluate_log(o);
  EXPECT_EQ(r.leader_id_switches, 2);
  EXPECT_EQ(r.track_ids_on_leader, 2);  // 7, 9 (12 is a duplicate: one target per vehicle and message)
  EXPECT_EQ(r.duplicate_targets, 1);
  EXPECT_EQ(r.target_estimates, 10);
  EXPECT_EQ(r.false_targets, 3);
  EXPECT_EQ(r.false_track_ids, 2);
  EXPECT_NEAR(r.duration_s, 0.9, 1e-12);
  EXPECT_NEAR(r.false_targets_per_s, 3 / 0.9, 1e-9);
  EXPECT_NE(r.report().find("2 id switch(es)"), std::string::npos) << r.report();
  EXPECT_NE(r.report().find("10 matched, 3 false, 1 duplicate"), std::string::npos) << r.report();
  // CSV: a header and one row per matched or false world target (10 + 3); a false target has no truth.
  std::ifstream csv(o.csv_path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(csv, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 14u);
  EXPECT_EQ(lines[0],
            "t_s,track_id,vehicle_id,range_m,est_x,est_y,est_z,truth_x,truth_y,truth_z,error_m,range_est_m,radius_m,"
            "radius_sigma_m,camera_id");
  // range_m: the true range of the matched vehicle; range_est_m: target_t.range (1 m in these targets); radius_m and
  // radius_sigma_m: the track's size estimate as published (target_t.radius_m, radius_sigma_m); camera_id: the camera
  // of the track's last detection.
  EXPECT_EQ(lines[1], "0.000000,7,1,10.0000,0.0000,10.0000,5.0000,0.0000,10.0000,5.0000,0.0000,1.0000,0.3480,0.0125,0");
  EXPECT_NE(
      std::find(lines.begin(), lines.end(), "0.200000,20,-1,1.0000,50.0000,50.0000,50.0000,,,,,1.0000,0.3480,0.0125,0"),
      lines.end());
}

/// Ten frames; the logger saw ground truth k at W_k = 5e12 + k s and the targets from it (L_k = k + 1 ms) later. Frame
/// 0 also has an image logged 2 ms before its ground truth: the image is the exposure, so L_0 = 3 ms. A last targets_t
/// refers to an exposure that is not in the log (no sample). inference_latency_us = 2 (k + 1) ms.
std::string write_latency(const testing::TempDir& dir) {
  constexpr int64_t kW = 5000000000000;
  std::vector<testing::LogEvent> events;
  for (int k = 0; k < 10; ++k) {
    const int64_t u = kT0 + k * 100000, w = kW + k * 1000000;
    if (k == 0) {
      image_t img{};
      img.utime = u;
      img.width = 4;
      img.height = 2;
      img.stride = 4;
      img.pixel_format = image_t::GRAY8;
      img.data.assign(8, 128);
      img.size = 8;
      events.push_back(make_event("IMAGE_CAM0", img, w - 2000));
    }
    events.push_back(make_event("GROUND_TRUTH", truth_frame(k, u, {vehicle(0, 0, 0, 5), vehicle(1, 0, 10, 5)}), w));
    detections_t d{};
    d.utime = u;
    d.seq = k;
    d.image_width = 640;
    d.image_height = 480;
    d.inference_latency_us = 2000 * (k + 1);
    events.push_back(make_event("DETECTIONS_CAM0", d, w + 500));
    events.push_back(make_event("TARGETS", targets_msg(u, {world_target(7, 0, 10, 5, u)}), w + 1000 * (k + 1)));
  }
  const int64_t u_missing = kT0 + 5 * 100000 + 1;
  events.push_back(
      make_event("TARGETS", targets_msg(u_missing, {world_target(7, 0, 10, 5, u_missing)}), kW + 20000000));
  const std::string path = dir.file("latency.lcmlog");
  testing::write_log(path, events);
  return path;
}

TEST(Eval, LatencyPercentilesFromLogEventTimestamps) {
  testing::TempDir dir;
  EvalOptions o;
  o.log = write_latency(dir);
  const EvalResult r = evaluate_log(o);
  // Samples {3, 2, 3, 4, ..., 10} ms; nearest rank: p50 = 5th = 5, p90 = 9th = 9, p99 = 10th = 10.
  ASSERT_EQ(r.latency_ms.n, 10);
  ASSERT_EQ(r.latency_samples_ms.size(), 10u);
  EXPECT_NEAR(r.latency_samples_ms[0], 3.0, 1e-9);
  EXPECT_NEAR(r.latency_ms.p50, 5.0, 1e-9);
  EXPECT_NEAR(r.latency_ms.p90, 9.0, 1e-9);
  EXPECT_NEAR(r.latency_ms.p99, 10.0, 1e-9);
  EXPECT_NEAR(r.latency_ms.max, 10.0, 1e-9);
  // Inference 2, 4, ..., 20 ms: p50 = 10, p90 = 18, p99 = 20.
  EXPECT_EQ(r.inference_latency_ms.n, 10);
  EXPECT_NEAR(r.inference_latency_ms.p50, 10.0, 1e-9);
  EXPECT_NEAR(r.inference_latency_ms.p90, 18.0, 1e-9);
  EXPECT_NEAR(r.inference_latency_ms.p99, 20.0, 1e-9);
  EXPECT_EQ(r.image_utimes, std::vector<int64_t>{kT0});
  const nlohmann::json latency = nlohmann::json::parse(r.json()).at("latency");
  EXPECT_EQ(latency.at("n"), 10) << r.json();
  EXPECT_NEAR(latency.at("p50_ms").get<double>(), 5.0, 1e-9) << r.json();
}

detection_t box(float cx, float cy, float w, bool zoom) {
  detection_t d{};
  d.cx = cx;
  d.cy = cy;
  d.w = d.h = w;
  d.confidence = 0.9f;
  // (Not `zoom ? A : B`: a conditional of two lvalues odr-uses the constants, which lcm-gen declares but never
  // defines.)
  if (zoom)
    d.pass_kind = wingman::detection_t::PASS_ZOOM_IN;
  else
    d.pass_kind = wingman::detection_t::PASS_SINGLE;
  return d;
}

/// A detections_t of CAM0 at `u` with `boxes`, for a width x height image.
detections_t detections_msg(int64_t u, int seq, std::vector<detection_t> boxes, int width = 640, int height = 480) {
  detections_t d{};
  d.utime = u;
  d.seq = seq;
  d.image_width = width;
  d.image_height = height;
  d.detections = std::move(boxes);
  d.num_detections = static_cast<int32_t>(d.detections.size());
  return d;
}

/// Leader truth box centred at (100, 100), 20 x 20 px, range 8 m (frames 0, 1) and 25 m (frames 2, 3), 640 px wide
/// images. Detections (w in px): frame 0: single 26 (error 6) and one far outside the box; frame 1: single 18 at
/// cx 105 (2), zoom 21 (1); frame 2: zoom 19.5 (0.5) and a single centred outside the box; frame 3: singles 30 at
/// cx 104 and 22 at cx 101 (the nearer: 2).
std::string write_box_widths(const testing::TempDir& dir) {
  const std::vector<std::vector<detection_t>> dets = {
      {box(100, 100, 26, false), box(300, 100, 5, false)},
      {box(105, 100, 18, false), box(100, 101, 21, true)},
      {box(100, 100, 19.5f, true), box(111, 100, 20, false)},
      {box(104, 100, 30, false), box(101, 100, 22, false)},
  };
  std::vector<testing::LogEvent> events;
  for (int k = 0; k < 4; ++k) {
    const int64_t u = kT0 + k * 100000;
    ground_truth_t g = truth_frame(k, u, {vehicle(0, 0, 0, 5), vehicle(1, 0, k < 2 ? 8 : 25, 5)});
    truth_box_t b{};
    b.vehicle_id = 1;
    b.cx = b.cy = 100;
    b.w = b.h = 20;
    b.visible = true;
    b.range = k < 2 ? 8 : 25;
    g.boxes = {b};
    g.num_boxes = 1;
    events.push_back(make_event("DETECTIONS_CAM0", detections_msg(u, k, dets[static_cast<size_t>(k)]),
                                u));  // before its ground truth: order must not matter
    events.push_back(make_event("GROUND_TRUTH", g, u));
  }
  const std::string path = dir.file("widths.lcmlog");
  testing::write_log(path, events);
  return path;
}

TEST(Eval, BoxWidthErrorSingleAndZoomAgainstTruthBox) {
  testing::TempDir dir;
  EvalOptions o;
  o.log = write_box_widths(dir);
  const EvalResult r = evaluate_log(o);
  // Single: 6, 2, 2 px of 640; zoom: 1, 0.5 px.
  EXPECT_EQ(r.box_width_single.n, 3);
  EXPECT_NEAR(r.box_width_single.mean, 10.0 / 3 / 640, 1e-9);
  EXPECT_NEAR(r.box_width_single.max, 6.0 / 640, 1e-9);
  EXPECT_EQ(r.box_width_zoom.n, 2);
  EXPECT_NEAR(r.box_width_zoom.mean, 0.75 / 640, 1e-9);
  // By truth range: 8 m is in 5-10, 25 m in 20-30.
  EXPECT_EQ(r.box_width_single_by_range[1].error.n, 2);
  EXPECT_NEAR(r.box_width_single_by_range[1].error.mean, 4.0 / 640, 1e-9);
  EXPECT_EQ(r.box_width_single_by_range[4].error.n, 1);
  EXPECT_NEAR(r.box_width_single_by_range[4].error.mean, 2.0 / 640, 1e-9);
  EXPECT_NEAR(r.box_width_zoom_by_range[1].error.mean, 1.0 / 640, 1e-9);
  EXPECT_NEAR(r.box_width_zoom_by_range[4].error.mean, 0.5 / 640, 1e-9);
  ASSERT_EQ(r.box_widths.size(), 5u);
  EXPECT_NEAR(r.box_widths[0].w_det_frac, 26.0 / 640, 1e-7);
  EXPECT_NEAR(r.box_widths[0].w_truth_frac, 20.0 / 640, 1e-7);
  EXPECT_NE(r.report().find("zoom-in"), std::string::npos);
  // Detection by range: every frame has a box centred in the truth box; (300, 100) and (111, 100) are not in it.
  ASSERT_EQ(r.detection_by_range.size(), 6u);
  EXPECT_EQ(r.detection_by_range[1].visible, 2);
  EXPECT_EQ(r.detection_by_range[1].detected, 2);
  EXPECT_EQ(r.detection_by_range[4].visible, 2);
  EXPECT_EQ(r.detection_by_range[4].detected, 2);
  EXPECT_EQ(r.detection_by_range[0].visible + r.detection_by_range[2].visible + r.detection_by_range[3].visible +
                r.detection_by_range[5].visible,
            0);
  EXPECT_EQ(r.detections_total, 8);
  EXPECT_EQ(r.detections_outside_truth, 2);
  // False boxes: (300, 100) in frame 0 (5-10 m) and (111, 100) in frame 2 (20-30 m).
  EXPECT_EQ(r.detection_by_range[1].false_boxes, 1);
  EXPECT_EQ(r.detection_by_range[4].frames_with_false_box, 1);
  const nlohmann::json bins = nlohmann::json::parse(r.json()).at("detection_by_range");
  ASSERT_GE(bins.size(), 2u) << r.json();
  EXPECT_EQ(bins[0], nlohmann::json::parse(R"({"lo_m": 0.0, "hi_m": 5.0, "visible": 0, "detected": 0, "false_boxes": 0,
                                               "frames_with_false_box": 0})"));
  EXPECT_EQ(bins[1], nlohmann::json::parse(R"({"lo_m": 5.0, "hi_m": 10.0, "visible": 2, "detected": 2, "false_boxes": 1,
                                               "frames_with_false_box": 1})"));
}

truth_box_t truth_box(int vehicle_id, float cx, float cy, float size, bool visible, double range) {
  truth_box_t b{};
  b.vehicle_id = vehicle_id;
  b.cx = cx;
  b.cy = cy;
  b.w = b.h = size;
  b.visible = visible;
  b.range = range;
  return b;
}

TEST(Eval, BoxOnLeaderIsACentreInsideTheLeadersVisibleTruthBoxOfTheSameCamera) {
  const std::vector<truth_box_t> truth = {truth_box(1, 200, 150, 40, true, 8), truth_box(2, 400, 150, 40, true, 9)};
  EXPECT_TRUE(box_on_leader(box(200, 150, 10, false), 0, truth, 1));
  EXPECT_TRUE(box_on_leader(box(220, 170, 80, false), 0, truth, 1));  // on the corner: edges included; size ignored
  EXPECT_FALSE(box_on_leader(box(220.5f, 150, 40, false), 0, truth, 1));
  EXPECT_FALSE(box_on_leader(box(200, 150, 10, false), 1, truth, 1));  // another camera
  EXPECT_FALSE(box_on_leader(box(400, 150, 10, false), 0, truth, 1));  // on vehicle 2, not the leader
  EXPECT_TRUE(box_on_leader(box(400, 150, 10, false), 0, truth, 2));
  EXPECT_FALSE(box_on_leader(box(200, 150, 10, false), 0, {truth_box(1, 200, 150, 40, false, 8)}, 1));  // hidden
  EXPECT_FALSE(box_on_leader(box(200, 150, 10, false), 0, {}, 1));
}

/// Ten frames; the leader's truth box is centred at (200, 150), 40 x 40 px, range 8 m (frames 0-4) and 18 m (5-9).
/// Boxes by frame (on = centred in it, off = elsewhere): 0: on (on its right edge); 1: off; 2: on, off, off; 3: an
/// empty detections_t; 4: off (0.5 px past the edge); 5: on; 6: off, off; 7: no detections_t; 8: the leader hidden,
/// a box where it would be (off); 9: on, and one on vehicle 2's visible box (off, but inside a truth box). A
/// detections_t between frames 4 and 5, with no ground truth at its utime: off.
std::string write_false_boxes(const testing::TempDir& dir) {
  const float on = 200, off = 400, v2 = 500;
  const std::vector<std::vector<detection_t>> dets = {
      {box(220, 150, 30, false)},
      {box(off, 300, 30, false)},
      {box(on, 150, 30, false), box(off, 300, 30, false), box(off, 20, 30, false)},
      {},
      {box(220.5f, 150, 30, false)},
      {box(on, 150, 12, false)},
      {box(off, 300, 12, false), box(off, 20, 12, false)},
      {},
      {box(on, 150, 12, false)},
      {box(on, 150, 12, true), box(v2, 150, 12, false)},
  };
  std::vector<testing::LogEvent> events;
  for (int k = 0; k < 10; ++k) {
    const int64_t u = kT0 + k * 100000;
    const double range = k < 5 ? 8 : 18;
    ground_truth_t g = truth_frame(k, u, {vehicle(0, 0, 0, 5), vehicle(1, 0, range, 5), vehicle(2, 3, range, 5)});
    g.boxes = {truth_box(1, 200, 150, 40, k != 8, range), truth_box(2, v2, 150, 40, k == 9, range)};
    g.num_boxes = 2;
    events.push_back(make_event("GROUND_TRUTH", g, u));
    if (k == 7) continue;
    events.push_back(make_event("DETECTIONS_CAM0", detections_msg(u, k, dets[static_cast<size_t>(k)]), u));
    if (k == 4)
      events.push_back(
          make_event("DETECTIONS_CAM0", detections_msg(u + 50000, k, {box(on, 150, 12, false)}), u + 50000));
  }
  const std::string path = dir.file("false_boxes.lcmlog");
  testing::write_log(path, events);
  return path;
}

TEST(Eval, LeaderCountsAsDetectedOnlyWithABoxOnItAndOtherBoxesAreFalse) {
  testing::TempDir dir;
  EvalOptions o;
  o.log = write_false_boxes(dir);
  o.json_path = dir.file("eval.json");
  const EvalResult r = evaluate_log(o);
  // Visible: frames 0-7 and 9. On the leader: 0, 2, 5, 9 (frames 1, 4 and 6 have boxes, none on it).
  EXPECT_EQ(r.frames_leader_visible, 9);
  EXPECT_EQ(r.frames_leader_detected, 4);
  // False boxes in visible frames: 1 (frame 1) + 2 (2) + 1 (4) + 2 (6) + 1 (9) in five frames.
  EXPECT_EQ(r.false_boxes_leader_visible, 7);
  EXPECT_EQ(r.frames_leader_visible_with_false_box, 5);
  // Over every detections_t: also frame 8's box and the one without ground truth.
  EXPECT_EQ(r.detections_total, 13);
  EXPECT_EQ(r.detection_frames, 10);  // frames 0-6, 8, 9 and the one between 4 and 5
  EXPECT_EQ(r.false_boxes, 9);
  EXPECT_EQ(r.frames_with_false_box, 7);
  EXPECT_EQ(r.detections_outside_truth, 8);  // every false box but the one on vehicle 2
  // By the leader's range: 8 m is in 5-10 (frames 0-4), 18 m in 15-20 (5, 6, 7, 9); the bins add up to the totals.
  ASSERT_EQ(r.detection_by_range.size(), 6u);
  const DetectionBin& near = r.detection_by_range[1];
  const DetectionBin& far = r.detection_by_range[3];
  EXPECT_EQ(near.visible, 5);
  EXPECT_EQ(near.detected, 2);
  EXPECT_EQ(near.false_boxes, 4);
  EXPECT_EQ(near.frames_with_false_box, 3);
  EXPECT_EQ(far.visible, 4);
  EXPECT_EQ(far.detected, 2);
  EXPECT_EQ(far.false_boxes, 3);
  EXPECT_EQ(far.frames_with_false_box, 2);
  int64_t visible = 0, detected = 0;
  for (const auto& b : r.detection_by_range) visible += b.visible, detected += b.detected;
  EXPECT_EQ(visible, r.frames_leader_visible);
  EXPECT_EQ(detected, r.frames_leader_detected);
  const std::string text = r.report();
  EXPECT_NE(text.find("leader detected in 4 of 9 frames where it is visible (44.4 %"), std::string::npos) << text;
  EXPECT_NE(text.find("7 false box(es) in 5 of those frames"), std::string::npos) << text;
  EXPECT_NE(text.find("detected boxes: 13 in 10 frames with a detections_t; 9 not on the leader (false boxes) in 7 "
                      "frames, 8 of them"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("  leader detected at range 5-10 m         40.0 % of 5 frames (2), 4 false box(es) in 3 frames"),
            std::string::npos)
      << text;
  std::ifstream js(o.json_path);
  std::stringstream j;
  j << js.rdbuf();
  const nlohmann::json doc = nlohmann::json::parse(j.str());
  for (const auto& [key, value] : std::vector<std::pair<std::string, int>>{{"frames_leader_visible", 9},
                                                                           {"frames_leader_detected", 4},
                                                                           {"false_boxes_leader_visible", 7},
                                                                           {"frames_leader_visible_with_false_box", 5},
                                                                           {"detection_frames", 10},
                                                                           {"false_boxes", 9},
                                                                           {"frames_with_false_box", 7},
                                                                           {"non_drone_boxes", 0}})
    EXPECT_EQ(doc.at(key), value) << key << " in " << j.str();
  EXPECT_EQ(doc.at("detection_by_range").at(3),
            nlohmann::json::parse(R"({"lo_m": 15.0, "hi_m": 20.0, "visible": 4, "detected": 2, "false_boxes": 3,
                                      "frames_with_false_box": 2})"));
}

/// Several cameras (a rig): every camera's detections channel is read by default, and each box is judged against its
/// own camera's truth boxes. Four frames; the leader is in camera 1's view only (truth box at (200, 150)); camera 1
/// boxes it in frames 0-2; camera 0 has a box at the same pixels in frames 0 and 3 (false: not its camera's truth).
TEST(Eval, EveryCamerasDetectionsAreJudgedAgainstTheirOwnCamerasTruth) {
  testing::TempDir dir;
  std::vector<testing::LogEvent> events;
  for (int k = 0; k < 4; ++k) {
    const int64_t u = kT0 + k * 100000;
    ground_truth_t g = truth_frame(k, u, {vehicle(0, 0, 0, 5), vehicle(1, 0, 8, 5)});
    truth_box_t b = truth_box(1, 200, 150, 40, true, 8);
    b.camera_id = 1;
    g.boxes = {b};
    g.num_boxes = 1;
    events.push_back(make_event("GROUND_TRUTH", g, u));
    detections_t d0 = detections_msg(
        u, k, k == 0 || k == 3 ? std::vector<detection_t>{box(200, 150, 30, false)} : std::vector<detection_t>{});
    events.push_back(make_event("DETECTIONS_CAM0", d0, u));
    detections_t d1 =
        detections_msg(u, k, k < 3 ? std::vector<detection_t>{box(200, 150, 30, false)} : std::vector<detection_t>{});
    d1.camera_id = 1;
    events.push_back(make_event("DETECTIONS_CAM1", d1, u));
    // Not a detections channel of the default pattern: never read.
    events.push_back(make_event("DETECTIONS_CAM1_COPY", d1, u));
  }
  EvalOptions o;
  o.log = dir.file("rig.lcmlog");
  testing::write_log(o.log, events);
  EvalResult r = evaluate_log(o);
  EXPECT_EQ(r.frames_leader_visible, 4);
  EXPECT_EQ(r.frames_leader_detected, 3);
  EXPECT_EQ(r.detections_total, 5);
  EXPECT_EQ(r.false_boxes, 2);  // camera 0's two boxes
  // One camera's channel only: camera 0 never sees the leader.
  o.detections_channel = "DETECTIONS_CAM0";
  r = evaluate_log(o);
  EXPECT_EQ(r.frames_leader_detected, 0);
  EXPECT_EQ(r.detections_total, 2);
  // A pattern that cannot be one is named.
  o.detections_channel = "DETECTIONS_(CAM";
  bool named = false;
  for (const auto& line : o.validate()) named = named || line.find("--detections-channel: 'DETECTIONS_(CAM'") == 0;
  EXPECT_TRUE(named);
}

TEST(Eval, BoxesOfOtherClassesAreNeitherDetectionsNorFalseBoxes) {
  // Two frames with the leader visible at (200, 150): frame 0 has a bird box (class 2) centred on it and a drone box
  // off it; frame 1 a helicopter box (class 3) on it. Only drone boxes count: nothing finds the leader.
  testing::TempDir dir;
  std::vector<testing::LogEvent> events;
  for (int k = 0; k < 2; ++k) {
    const int64_t u = kT0 + k * 100000;
    ground_truth_t g = truth_frame(k, u, {vehicle(0, 0, 0, 5), vehicle(1, 0, 8, 5)});
    g.boxes = {truth_box(1, 200, 150, 40, true, 8)};
    g.num_boxes = 1;
    events.push_back(make_event("GROUND_TRUTH", g, u));
    detection_t on = box(200, 150, 30, false);
    on.class_id = static_cast<int16_t>(k == 0 ? 2 : 3);
    std::vector<detection_t> boxes = {on};
    if (k == 0) boxes.push_back(box(400, 300, 30, false));
    events.push_back(make_event("DETECTIONS_CAM0", detections_msg(u, k, boxes), u));
  }
  EvalOptions o;
  o.log = dir.file("classes.lcmlog");
  testing::write_log(o.log, events);
  const EvalResult r = evaluate_log(o);
  EXPECT_EQ(r.frames_leader_visible, 2);
  EXPECT_EQ(r.frames_leader_detected, 0);
  EXPECT_EQ(r.detections_total, 1);
  EXPECT_EQ(r.false_boxes, 1);
  EXPECT_EQ(r.non_drone_boxes, 2);
  EXPECT_EQ(nlohmann::json::parse(r.json()).at("non_drone_boxes"), 2) << r.json();
  EXPECT_NE(r.report().find("; 2 box(es) of other classes (not drones: not counted)"), std::string::npos) << r.report();
}

/// An image_t of a 64 x 48 grey frame in `format`.
image_t test_image(int64_t u, int8_t format) {
  cv::Mat bgr(48, 64, CV_8UC3, cv::Scalar(90, 120, 150));
  image_t img{};
  img.utime = u;
  img.width = 64;
  img.height = 48;
  img.pixel_format = format;
  cv::Mat m;
  if (format == image_t::BGR8) {
    m = bgr;
  } else if (format == image_t::GRAY8) {
    cv::cvtColor(bgr, m, cv::COLOR_BGR2GRAY);
  } else if (format == image_t::YUYV) {
    m = cv::Mat(48, 64, CV_8UC2, cv::Scalar(128, 128));
  }
  if (format == image_t::MJPEG) {
    cv::imencode(".jpg", bgr, img.data);
    img.stride = 0;
  } else {
    img.stride = static_cast<int32_t>(m.step[0]);
    img.data.assign(m.data, m.data + m.total() * m.elemSize());
  }
  img.size = static_cast<int32_t>(img.data.size());
  return img;
}

TEST(Report, DrawsFramesOfEveryPixelFormatAndEveryChart) {
  testing::TempDir dir;
  std::vector<testing::LogEvent> events;
  const int8_t formats[] = {image_t::BGR8, image_t::GRAY8, image_t::YUYV, image_t::MJPEG};
  for (int k = 0; k < 8; ++k) {
    const int64_t u = kT0 + k * 100000;
    events.push_back(make_event("IMAGE_CAM0", test_image(u, formats[k % 4]), u));
    ground_truth_t g = truth_frame(k, u, {vehicle(0, 0, 0, 5), vehicle(1, 0.2 * k, 10, 5)});
    truth_box_t b{};
    b.vehicle_id = 1;
    b.cx = 32;
    b.cy = 24;
    b.w = b.h = 10;
    b.visible = true;
    b.range = 10;
    g.boxes = {b};
    g.num_boxes = 1;
    events.push_back(make_event("GROUND_TRUTH", g, u));
    events.push_back(
        make_event("DETECTIONS_CAM0", detections_msg(u, k, {box(32, 24, 11, k % 2 == 1)}, 64, 48), u + 1000));
    events.push_back(make_event("TARGETS", targets_msg(u, {world_target(7, 0.2 * k + 0.1, 10, 5, u)}), u + 2000));
  }
  const std::string log = dir.file("images.lcmlog");
  testing::write_log(log, events);
  EvalOptions o;
  o.log = log;
  o.report_frames = 4;
  const EvalResult r = evaluate_log(o);
  ASSERT_EQ(r.image_utimes.size(), 8u);
  const auto frames = draw_report_frames(r, o);
  ASSERT_EQ(frames.size(), 4u);  // images 0, 2, 5, 7 of 8: BGR8, YUYV, GRAY8, MJPEG
  EXPECT_EQ(frames.front().utime, kT0);
  EXPECT_EQ(frames.back().utime, kT0 + 7 * 100000);
  for (const auto& f : frames) {
    EXPECT_EQ(f.width, 64);
    EXPECT_FALSE(f.jpeg_b64.empty());
  }
  const std::string html = html_report(r, o, frames);
  size_t uris = 0;
  for (size_t p = html.find("data:image/jpeg;base64,"); p != std::string::npos;
       p = html.find("data:image/jpeg;base64,", p + 1))
    ++uris;
  EXPECT_EQ(uris, 4u);
  for (const char* id : {"topdown", "errors", "error-by-range", "box-width", "latency"}) {
    const size_t at = html.find(std::string("<svg id=\"") + id + "\"");
    ASSERT_NE(at, std::string::npos) << id;
    const size_t end = html.find("</svg>", at);
    EXPECT_NE(html.substr(at, end - at).find("class=\"data\""), std::string::npos) << id << " has no data";
  }
  for (const char* remote : {"src=\"http", "href=\"http", "<link", "<script src", "url(http"}) {
    EXPECT_EQ(html.find(remote), std::string::npos) << remote;  // nothing is fetched: the page opens offline
  }
  EXPECT_EQ(html.find("no-images"), std::string::npos);
}

/// The headline row `key` of the page (its <tr> up to </tr>); "" when absent.
std::string headline_row(const std::string& html, const std::string& key) {
  const size_t at = html.find("<tr data-key=\"" + key + "\"");
  return at == std::string::npos ? "" : html.substr(at, html.find("</tr>", at) - at);
}

TEST(Report, HeadlineShowsTheEvalsNumbersBeforeEverythingElse) {
  testing::TempDir dir;
  EvalOptions o;
  o.log = write_flight(dir);
  o.has_formation = true;
  o.formation_offset_in_world = {0.0, -10.0, 0.0};
  o.formation_height_m = 5.0;
  o.settle_s = 0.45;
  const EvalResult r = evaluate_log(o);
  const auto h = report_headline(r);
  ASSERT_EQ(h.size(), 6u);
  std::map<std::string, HeadlineItem> by_key;
  for (const auto& i : h) {
    EXPECT_TRUE(i.measured) << i.key << ": " << i.detail;
    by_key[i.key] = i;
  }
  // The eval's numbers (hand-computed in the Eval tests above), and as the page shows them.
  EXPECT_EQ(by_key["localization_rms"].values, std::vector<double>{r.localization.rms});
  EXPECT_NEAR(r.localization.rms, std::sqrt(0.125), 1e-9);
  EXPECT_EQ(by_key["localization_rms"].text, "0.354 m");
  EXPECT_EQ(by_key["localization_rms"].thesis.rfind("2.86 m", 0), 0u);
  EXPECT_EQ(by_key["formation_rms"].values, std::vector<double>{r.formation_horizontal.rms});
  EXPECT_NEAR(r.formation_horizontal.rms, std::sqrt((0.25 + 0.36 + 0.49 + 0.64 + 0.81) / 5), 1e-9);
  EXPECT_EQ(by_key["formation_rms"].text, "0.714 m");
  EXPECT_EQ(by_key["formation_rms"].thesis, "");
  EXPECT_EQ(by_key["detection_rate"].values, (std::vector<double>{8, 9}));
  EXPECT_EQ(by_key["detection_rate"].text, "8 of 9 frames (88.9 %)");
  EXPECT_EQ(by_key["false_targets"].values, (std::vector<double>{1, 1}));
  EXPECT_EQ(by_key["false_targets"].text, "1 in 1 track id(s)");
  EXPECT_EQ(by_key["track_ids"].values, (std::vector<double>{1, 0}));
  EXPECT_EQ(by_key["track_ids"].text, "1, 0 id switch(es)");
  ASSERT_GT(r.latency_ms.n, 0);
  EXPECT_EQ(by_key["latency"].values, (std::vector<double>{r.latency_ms.p50, r.latency_ms.p99}));
  char latency[64];
  std::snprintf(latency, sizeof latency, "%.1f ms / %.1f ms", r.latency_ms.p50, r.latency_ms.p99);
  EXPECT_EQ(by_key["latency"].text, latency);
  EXPECT_EQ(by_key["latency"].thesis.rfind("about 0.7 s", 0), 0u);

  const std::string html = html_report(r, o, {});
  const size_t table = html.find("<table id=\"headline\"");
  ASSERT_NE(table, std::string::npos);
  EXPECT_LT(table, html.find("<svg"));
  EXPECT_LT(table, html.find("<pre"));
  EXPECT_NE(headline_row(html, "localization_rms").find(">0.354 m<"), std::string::npos);
  EXPECT_NE(headline_row(html, "localization_rms").find("2.86 m"), std::string::npos);
  EXPECT_NE(headline_row(html, "detection_rate").find(">8 of 9 frames (88.9 %)<"), std::string::npos);
  EXPECT_NE(headline_row(html, "formation_rms").find("&mdash;"), std::string::npos);  // no thesis figure
  EXPECT_EQ(html.find("not measured"), std::string::npos);

  // Without a formation target the formation error is not measured, not 0.
  o.has_formation = false;
  const EvalResult r2 = evaluate_log(o);
  const auto h2 = report_headline(r2);
  EXPECT_FALSE(h2[1].measured);
  EXPECT_EQ(h2[1].text, "not measured");
  EXPECT_TRUE(h2[1].values.empty());
  const std::string row = headline_row(html_report(r2, o, {}), "formation_rms");
  EXPECT_NE(row.find("data-measured=\"0\""), std::string::npos) << row;
  EXPECT_NE(row.find(">not measured<"), std::string::npos) << row;
  EXPECT_EQ(row.find(" m<"), std::string::npos) << row;
}

TEST(Report, ThumbnailsOfALogWithLargeImagesAreScaledDown) {
  testing::TempDir dir;
  std::vector<testing::LogEvent> events;
  for (int k = 0; k < 10; ++k) {
    const int64_t u = kT0 + k * 100000;
    events.push_back(make_event("GROUND_TRUTH", truth_frame(k, u, {vehicle(0, 0, 0, 5), vehicle(1, 0, 10, 5)}), u));
    cv::Mat bgr(720, 1280, CV_8UC3, cv::Scalar(200, 170, 120));
    image_t img{};
    img.utime = u;
    img.width = 1280;
    img.height = 720;
    img.pixel_format = image_t::BGR8;
    img.stride = static_cast<int32_t>(bgr.step[0]);
    img.data.assign(bgr.data, bgr.data + bgr.total() * bgr.elemSize());
    img.size = static_cast<int32_t>(img.data.size());
    events.push_back(make_event("IMAGE_CAM0", img, u));
  }
  EvalOptions o;
  o.log = dir.file("large.lcmlog");
  testing::write_log(o.log, events);
  const EvalResult r = evaluate_log(o);  // the default: report_frames = 6
  const auto frames = draw_report_frames(r, o);
  ASSERT_EQ(frames.size(), 6u);
  for (const auto& f : frames) {
    EXPECT_EQ(f.width, kReportThumbnailWidth);
    EXPECT_EQ(f.height, kReportThumbnailWidth * 720 / 1280);
    EXPECT_LT(f.jpeg_b64.size(), 40000u);  // a thumbnail, not the frame
  }
  const std::string html = html_report(r, o, frames);
  const size_t at = html.find("<div id=\"frames\">");
  ASSERT_NE(at, std::string::npos);
  EXPECT_LT(at, html.find("<svg"));  // right under the headline
  size_t n = 0;
  const std::string thumb = "<img class=\"frame\" width=\"320\" height=\"180\"";
  for (size_t p = html.find(thumb); p != std::string::npos; p = html.find(thumb, p + 1)) ++n;
  EXPECT_EQ(n, 6u);
  EXPECT_EQ(html.find("no-images"), std::string::npos);
}

/// Standard base64 (the report's thumbnails) to bytes: a plain decoder for the test.
std::vector<uint8_t> unbase64(const std::string& s) {
  const std::string a = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<uint8_t> out;
  uint32_t acc = 0;
  int bits = 0;
  for (const char c : s) {
    const size_t v = a.find(c);
    if (v == std::string::npos) continue;  // '=' padding
    acc = (acc << 6) | static_cast<uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<uint8_t>((acc >> bits) & 0xff));
    }
  }
  return out;
}

TEST(Report, WithoutFullImagesTheFramesAreTheCamerasPreviewsWithBoxesScaledToThem) {
  // A flight log as tools/fly.sh records it: no IMAGE_CAM0, one 320x180 preview a second on PREVIEW_CAM0, detections
  // in the 1280x720 image's pixels: a 200-px box centred at (640, 360) is a 50-px box centred at (160, 90).
  testing::TempDir dir;
  std::vector<testing::LogEvent> events;
  for (int k = 0; k < 30; ++k) {
    const int64_t u = kT0 + k * 100000;
    events.push_back(make_event("GROUND_TRUTH", truth_frame(k, u, {vehicle(0, 0, 0, 5), vehicle(1, 0, 10, 5)}), u));
    events.push_back(make_event("DETECTIONS_CAM0", detections_msg(u, k, {box(640, 360, 200, false)}, 1280, 720), u));
    if (k % 10 != 0) continue;
    cv::Mat small(180, 320, CV_8UC3, cv::Scalar(200, 170, 120));
    std::vector<uint8_t> jpeg;
    cv::imencode(".jpg", small, jpeg);
    image_t p{};
    p.utime = u;
    p.seq = k;
    p.width = 320;
    p.height = 180;
    p.pixel_format = image_t::MJPEG;
    p.data = jpeg;
    p.size = static_cast<int32_t>(jpeg.size());
    events.push_back(make_event("PREVIEW_CAM0", p, u));
  }
  EvalOptions o;
  o.log = dir.file("previews.lcmlog");
  testing::write_log(o.log, events);
  const EvalResult r = evaluate_log(o);
  EXPECT_TRUE(r.image_utimes.empty());
  ASSERT_EQ(r.preview_utimes.size(), 3u);
  const auto frames = draw_report_frames(r, o);
  ASSERT_EQ(frames.size(), 3u);
  for (const auto& f : frames) {
    EXPECT_EQ(f.width, 320);
    EXPECT_EQ(f.height, 180);
    const std::vector<uint8_t> bytes = unbase64(f.jpeg_b64);
    const cv::Mat img = cv::imdecode(bytes, cv::IMREAD_COLOR);
    ASSERT_EQ(img.cols, 320);
    // The box's left edge (x 135) is drawn red over the background; the image centre inside the box is background.
    const cv::Vec3b edge = img.at<cv::Vec3b>(90, 135), inside = img.at<cv::Vec3b>(90, 160);
    EXPECT_GT(edge[2], 150);
    EXPECT_LT(edge[0], 120) << "red (BGR 40, 39, 214), not the background (200, 170, 120)";
    EXPECT_NEAR(inside[0], 200, 12);
  }
  const std::string html = html_report(r, o, frames);
  EXPECT_NE(html.find("3 of the log's 3 previews"), std::string::npos);
  EXPECT_EQ(html.find("no-images"), std::string::npos);
}

TEST(Report, UnwritableOutputNamesTheFile) {
  testing::TempDir dir;
  EvalOptions o;
  o.log = write_ranges(dir);
  o.report_path = dir.file("no/such/dir/report.html");
  const EvalResult r = evaluate_log(o);  // writes no HTML: that is write_html_report's
  try {
    write_html_report(r, o, o.report_path);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no/such/dir/report.html"), std::string::npos) << e.what();
  }
  o.report_path.clear();
  o.log = dir.path();
  EXPECT_THROW(evaluate_log(o), std::runtime_error);  // a directory
}

}  // namespace
}  // namespace wingman::tools
