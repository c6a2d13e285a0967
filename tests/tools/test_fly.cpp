// SPDX-License-Identifier: MIT
// `wingman fly`'s plan: the processes and command lines a flight runs, and the option errors (nothing is started).
#include <gtest/gtest.h>
#include <wingman/common/config.hpp>
#include <wingman/tools/fly.hpp>

#include "../support/test_support.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace wingman::tools {
namespace {

namespace fs = std::filesystem;
using wingman::testing::TempDir;

const char* kUrl = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304";

FlyOptions options_for_tests() {
  FlyOptions o;
  o.config_dir = wingman::testing::source_path("config");
  o.bin_dir = fs::path(wingman::testing::bin_path("wingman-sim")).parent_path().string();
  o.lcm_url = kUrl;
  o.out = "/tmp/wingman-test-fly-plan";  // planned, never created
  return o;
}

bool has(const std::vector<std::string>& argv, const std::string& item) {
  return std::find(argv.begin(), argv.end(), item) != argv.end();
}

/// The value after `flag`'s first occurrence whose value starts with `prefix`, "" if none.
std::string value_of(const std::vector<std::string>& argv, const std::string& flag, const std::string& prefix) {
  for (size_t i = 0; i + 1 < argv.size(); ++i) {
    if (argv[i] == flag && argv[i + 1].rfind(prefix, 0) == 0) return argv[i + 1];
  }
  return "";
}

std::string error_of(const FlyOptions& o) {
  try {
    plan_flight(o);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(FlyPlan, TheDefaultFlightRunsTheShippedCnnOnRenderedImagesInLockstep) {
  const FlightPlan plan = plan_flight(options_for_tests());
  EXPECT_EQ(plan.name, "formation_2d");
  EXPECT_EQ(plan.scenario_file,
            fs::weakly_canonical(wingman::testing::source_path("config/scenarios/formation_2d.yaml")));
  EXPECT_EQ(plan.log_path, "/tmp/wingman-test-fly-plan/flight.lcmlog");
  ASSERT_EQ(plan.pipeline.size(), 3u);
  EXPECT_EQ(plan.pipeline[0].name, "wingman-detector");
  EXPECT_EQ(plan.pipeline[1].name, "wingman-localizer");
  EXPECT_EQ(plan.pipeline[2].name, "wingman-follower-ctrl");
  const auto& det = plan.pipeline[0].argv;
  EXPECT_TRUE(has(det, "model.cfg=\"builtin:wingman-small\""));
  EXPECT_TRUE(has(det, "model.weights=\"builtin:wingman-small\""));
  EXPECT_TRUE(has(det, "input.mode=replay"));
  EXPECT_TRUE(has(det, "windows.enabled=false"));
  EXPECT_EQ(value_of(det, "--lcm-url", ""), kUrl);
  // No per-flight file for formation_2d: the localizer and follower run on their defaults.
  EXPECT_FALSE(has(plan.pipeline[1].argv, "--config"));
  EXPECT_FALSE(has(plan.pipeline[2].argv, "--config"));
  const auto& sim = plan.sim.argv;
  EXPECT_EQ(value_of(sim, "--set", "sync="),
            "sync={mode: lockstep, timeout_s: 10.0, max_speed: 5.0, wait_for: [detector, localizer, follower_ctrl], "
            "startup_timeout_s: 60.0, scripted_lockstep: false, image_by_image: false}");
  // The box noise's seed is the scenario's (formation_2d.yaml: seed 2).
  EXPECT_EQ(value_of(sim, "--set", "detections="),
            "detections={from_ground_truth: false, box: sphere, noise_px: 1.0, seed: 2}");
  EXPECT_TRUE(has(sim, "render.enabled=true"));
  EXPECT_FALSE(has(sim, "--duration"));
  EXPECT_EQ(plan.sim_print_config.argv.back(), "--print-config");
  EXPECT_EQ(plan.sim_print_config.stdout_path, "/tmp/wingman-test-fly-plan/sim.yaml");
  // The logger leaves the images out.
  EXPECT_TRUE(has(plan.logger.argv, "--channel=IMAGE_.*"));
  EXPECT_TRUE(has(plan.logger.argv, "--invert-channels"));
  EXPECT_EQ(plan.logger.argv.back(), plan.log_path);
  EXPECT_EQ(plan.eval.json_path, "/tmp/wingman-test-fly-plan/eval.json");
  EXPECT_EQ(plan.eval.title, "Wingman flight: formation_2d");
  EXPECT_EQ(plan.eval_target.scenario, plan.scenario_file);
  EXPECT_TRUE(plan.eval_target.follower.files.empty());
  ASSERT_FALSE(plan.notes.empty());
  EXPECT_NE(plan.notes.front().find("detections from the CNN (builtin:wingman-small, builtin:wingman-small)"),
            std::string::npos);
}

TEST(FlyPlan, GroundTruthDetectionsNeedNoModelAndNoImages) {
  FlyOptions o = options_for_tests();
  o.detections = "truth";
  o.truth_box = "silhouette";
  o.duration_s = 2.5;
  o.record_images = true;
  const FlightPlan plan = plan_flight(o);
  EXPECT_TRUE(has(plan.pipeline[0].argv, "model.weights=\"\""));
  EXPECT_FALSE(has(plan.pipeline[0].argv, "windows.enabled=false"));
  EXPECT_TRUE(has(plan.sim.argv, "render.enabled=false"));
  EXPECT_EQ(value_of(plan.sim.argv, "--set", "detections="),
            "detections={from_ground_truth: true, box: silhouette, noise_px: 1.0, seed: 2}");
  EXPECT_EQ(value_of(plan.sim.argv, "--duration", ""), "2.5");
  EXPECT_FALSE(has(plan.logger.argv, "--invert-channels"));  // --record-images
  // --render renders them anyway.
  o.render = "on";
  EXPECT_TRUE(has(plan_flight(o).sim.argv, "render.enabled=true"));
}

TEST(FlyPlan, TheMavlinkAutopilotAddsTheBridgeAndTheSimulatorWaitsForIt) {
  FlyOptions o = options_for_tests();
  o.detections = "truth";
  o.autopilot = "mavlink";
  o.firmware = "ardupilot";
  const FlightPlan plan = plan_flight(o);
  ASSERT_EQ(plan.pipeline.size(), 4u);
  EXPECT_EQ(plan.pipeline[3].name, "wingman-mavlink");
  EXPECT_EQ(value_of(plan.pipeline[3].argv, "--config", ""),
            fs::weakly_canonical(wingman::testing::source_path("config/mavlink_bridge.sim.yaml")).string());
  EXPECT_NE(
      value_of(plan.sim.argv, "--set", "sync=").find("wait_for: [detector, localizer, follower_ctrl, mavlink_bridge]"),
      std::string::npos);
  EXPECT_TRUE(has(plan.sim.argv, "autopilot=mavlink"));
  EXPECT_EQ(value_of(plan.sim.argv, "--set", "mavlink="),
            "mavlink={firmware: ardupilot, streams: [odometry, attitude_quaternion, local_position_ned]}");
}

TEST(FlyPlan, WindowsTurnOnTheLocalizerTheDetectorAndTheSimulatorsScriptedLockstep) {
  FlyOptions o = options_for_tests();
  o.windows = true;
  o.zoom_in = true;
  const FlightPlan plan = plan_flight(o);
  EXPECT_TRUE(has(plan.pipeline[0].argv, "windows.enabled=true"));
  EXPECT_TRUE(has(plan.pipeline[0].argv, "detection.zoom_in=true"));
  EXPECT_TRUE(has(plan.pipeline[1].argv, "windows.publish=true"));
  EXPECT_NE(value_of(plan.sim.argv, "--set", "sync=").find("scripted_lockstep: true"), std::string::npos);
}

TEST(FlyPlan, ARigRunsADetectorPerCameraOnItsChannelsAndTheSimulatorAndLocalizerReadTheSameFile) {
  FlyOptions o = options_for_tests();
  o.scenario = "surround";
  o.rig = "surround4";
  const FlightPlan plan = plan_flight(o);
  const std::string rig = fs::weakly_canonical(wingman::testing::source_path("config/rigs/surround4.yaml")).string();
  EXPECT_EQ(plan.rig_file, rig);
  ASSERT_EQ(plan.pipeline.size(), 6u);  // four detectors, the localizer, the follower
  for (int i = 0; i < 4; ++i) {
    const auto& argv = plan.pipeline[static_cast<size_t>(i)].argv;
    EXPECT_EQ(plan.pipeline[static_cast<size_t>(i)].name, "wingman-detector-cam" + std::to_string(i));
    EXPECT_EQ(value_of(argv, "--name", "detector"), "detector" + std::to_string(i));
    EXPECT_TRUE(has(argv, "input.channel=\"IMAGE_CAM" + std::to_string(i) + "\""));
    EXPECT_TRUE(has(argv, "output.channel=\"DETECTIONS_CAM" + std::to_string(i) + "\""));
    EXPECT_TRUE(has(argv, "windows.channel=\"WINDOWS_CAM" + std::to_string(i) + "\""));
  }
  EXPECT_EQ(plan.pipeline[4].name, "wingman-localizer");
  EXPECT_TRUE(has(plan.pipeline[4].argv, "cameras.rig=\"" + rig + "\""));
  EXPECT_TRUE(has(plan.sim.argv, "cameras.rig=\"" + rig + "\""));
  const std::string sync = value_of(plan.sim.argv, "--set", "sync=");
  EXPECT_NE(sync.find("wait_for: [detector0, detector1, detector2, detector3, localizer, follower_ctrl]"),
            std::string::npos)
      << sync;
  EXPECT_NE(sync.find("scripted_lockstep: true"), std::string::npos) << sync;

  o.rig = "no_such_rig";
  EXPECT_NE(error_of(o).find("cameras.rig (--rig) = 'no_such_rig': no such rig"), std::string::npos) << error_of(o);
  TempDir dir;
  const std::string bad = (fs::path(dir.path()) / "bad.yaml").string();
  std::ofstream(bad) << "cameras:\n  - camera: {camera_id: -1}\n";
  o.rig = bad;
  EXPECT_NE(error_of(o).find("cameras[0].camera.camera_id"), std::string::npos) << error_of(o);
}

TEST(FlyPlan, AFlightsOwnConfigurationIsUsedAndEvalMeasuresAgainstIt) {
  FlyOptions o = options_for_tests();
  o.scenario = "follow_1d";  // config/flights/follow_1d.follower_ctrl.yaml
  const FlightPlan plan = plan_flight(o);
  const std::string follower =
      fs::weakly_canonical(wingman::testing::source_path("config/flights/follow_1d.follower_ctrl.yaml")).string();
  EXPECT_EQ(value_of(plan.pipeline[2].argv, "--config", ""), follower);
  ASSERT_EQ(plan.eval_target.follower.files.size(), 1u);
  EXPECT_EQ(plan.eval_target.follower.files[0], follower);
  // A file given on the command line replaces it.
  TempDir dir;
  std::ofstream(dir.file("f.yaml")) << "formation:\n  offset_m: [0, -5, 0]\n";
  o.follower_config = dir.file("f.yaml");
  EXPECT_EQ(plan_flight(o).eval_target.follower.files.at(0), fs::weakly_canonical(dir.file("f.yaml")).string());
}

TEST(FlyPlan, EachProcessesSetsFollowItsConfigurationAndEvalMeasuresAgainstTheFollowers) {
  FlyOptions o = options_for_tests();
  o.scenario = "follow_1d";  // with config/flights/follow_1d.follower_ctrl.yaml
  o.localizer_sets = {"tracker.window_size=1"};
  o.follower_sets = {"formation.offset_m=[0, -5, 0]"};
  o.detector_sets = {"detection.p_thresh=0.3"};
  const FlightPlan plan = plan_flight(o);
  EXPECT_EQ(value_of(plan.pipeline[1].argv, "--set", "tracker."), "tracker.window_size=1");
  const auto& follower = plan.pipeline[2].argv;
  ASSERT_EQ(value_of(follower, "--set", "formation."), "formation.offset_m=[0, -5, 0]");
  // After the flight's file: a --set wins over it.
  EXPECT_LT(std::find(follower.begin(), follower.end(), "--config") - follower.begin(),
            std::find(follower.begin(), follower.end(), "formation.offset_m=[0, -5, 0]") - follower.begin());
  EXPECT_EQ(plan.eval_target.follower.sets, o.follower_sets);
  EXPECT_TRUE(plan.eval.has_formation);  // pid_1d: the leader's start moved to the follower's line
  EXPECT_EQ(plan.eval.formation_offset_in_world, Eigen::Vector3d(0, -8, 0));
  // A follower key that its loader refuses fails the plan, before anything flies.
  o.follower_sets = {"formation.offset_mm=[0, -5, 0]"};
  EXPECT_NE(error_of(o).find("formation.offset_mm"), std::string::npos) << error_of(o);
  // The detector's own sets come after the flight's (model, passes), so they win.
  const auto& det = plan.pipeline[0].argv;
  EXPECT_LT(std::find(det.begin(), det.end(), "windows.enabled=false") - det.begin(),
            std::find(det.begin(), det.end(), "detection.p_thresh=0.3") - det.begin());
}

TEST(FlyPlan, TheOwnPoseErrorBecomesTheSimulatorsKeys) {
  FlyOptions o = options_for_tests();
  o.own_pose_error = "0.3,0.01";
  const FlightPlan plan = plan_flight(o);
  EXPECT_TRUE(has(plan.sim.argv, "own_pose.position_std_m=0.3"));
  EXPECT_TRUE(has(plan.sim.argv, "own_pose.attitude_std_rad=0.01"));
  EXPECT_TRUE(has(plan.sim.argv, "own_pose.correlation_time_s=2.0"));
  o.own_pose_error = "0.3,0.01,5";
  EXPECT_TRUE(has(plan_flight(o).sim.argv, "own_pose.correlation_time_s=5"));
  for (const char* bad : {"0.3", "0.3,", ",0.01", "0.3,0.01,", "1,2,3,4"}) {
    o.own_pose_error = bad;
    EXPECT_NE(error_of(o).find("--own-pose-error"), std::string::npos) << bad;
  }
}

TEST(FlyPlan, BadOptionsAreOneClearErrorBeforeAnythingStarts) {
  FlyOptions o = options_for_tests();
  o.detections = "radar";
  EXPECT_NE(error_of(o).find("flight.detections = 'radar': must be cnn or truth"), std::string::npos) << error_of(o);
  o = options_for_tests();
  o.render = "off";
  EXPECT_NE(error_of(o).find("flight.render = 'off': cnn detections need images"), std::string::npos) << error_of(o);
  o = options_for_tests();
  o.scenario = "no_such_flight";
  EXPECT_NE(error_of(o).find("no scenario 'no_such_flight' (looked for "), std::string::npos) << error_of(o);
  o = options_for_tests();
  o.localizer_config = "/nonexistent/localizer.yaml";
  EXPECT_NE(
      error_of(o).find("processes.localizer_config (--localizer-config) /nonexistent/localizer.yaml: cannot read it"),
      std::string::npos)
      << error_of(o);
  TempDir empty_bin;
  o = options_for_tests();
  o.bin_dir = empty_bin.path();
  EXPECT_NE(error_of(o).find(empty_bin.file("wingman-sim") + " is missing"), std::string::npos) << error_of(o);
  o = options_for_tests();
  o.model_weights = empty_bin.file("other.weights");  // no other.cfg beside it
  EXPECT_NE(error_of(o).find("has no " + empty_bin.file("other.cfg") + " beside it"), std::string::npos) << error_of(o);
  o = options_for_tests();
  o.duration_s = -1.0;
  EXPECT_NE(error_of(o).find("flight.duration_s = -1"), std::string::npos) << error_of(o);
}

TEST(FlyOptions, AFlightIsDataReadWithTheOneLoaderEveryBadKeyAtOnce) {
  TempDir dir;
  std::ofstream(dir.file("flight.yaml"))
      << "flight:\n  scenario: follow_1d\n  duration_s: 12\nwindows:\n  enabled: true\n";
  common::ConfigSources sources;
  sources.files = {dir.file("flight.yaml")};
  sources.sets = {"flight.duration_s=30", "autopilot.kind=mavlink"};
  const FlyOptions o = common::load_options<FlyOptions>(sources);
  EXPECT_EQ(o.scenario, "follow_1d");
  EXPECT_EQ(o.duration_s, 30.0);  // --set over the file
  EXPECT_TRUE(o.windows);
  EXPECT_EQ(o.autopilot, "mavlink");
  EXPECT_EQ(o.detections, "cnn");  // the default
  // Printed and read back: the same flight.
  const std::string printed = common::print_options(o);
  const FlyOptions again = common::load_options_from_string<FlyOptions>(printed, "printed.yaml");
  EXPECT_EQ(common::print_options(again), printed);

  std::ofstream(dir.file("bad.yaml")) << "flight:\n  duraton_s: 3\n  detections: radar\nwindow:\n  enabled: yes\n";
  try {
    common::load_options<FlyOptions>(common::ConfigSources{{dir.file("bad.yaml")}, {}});
    FAIL() << "expected a ConfigError";
  } catch (const common::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bad.yaml:2: flight.duraton_s: unknown key"), std::string::npos) << what;
    EXPECT_NE(what.find("bad.yaml:5: window.enabled: unknown key"), std::string::npos) << what;
    EXPECT_NE(what.find("flight.detections = 'radar': must be cnn or truth"), std::string::npos) << what;
  }
}

TEST(FlyPlan, WithoutABusItSaysWhereToRunIt) {
  FlyOptions o = options_for_tests();
  o.lcm_url.clear();
  const char* saved = std::getenv("WINGMAN_LCM_URL");
  const std::string keep = saved ? saved : "";
  ::unsetenv("WINGMAN_LCM_URL");
  EXPECT_NE(error_of(o).find("private network namespace"), std::string::npos) << error_of(o);
  if (saved) ::setenv("WINGMAN_LCM_URL", keep.c_str(), 1);
}

TEST(FlyPlan, AScenarioWithProblemsIsReportedByTheSimulatorsLoader) {
  TempDir dir;
  std::ofstream(dir.file("bad.yaml")) << "seed: many\n";
  FlyOptions o = options_for_tests();
  o.scenario = dir.file("bad.yaml");
  const std::string e = error_of(o);
  EXPECT_NE(e.find("bad.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("seed"), std::string::npos) << e;
}

}  // namespace
}  // namespace wingman::tools
