// SPDX-License-Identifier: MIT
// Scenario files: every shipped scenario loads; each deliberate mistake gives an error naming its key; scripted
// motions (random walk, waypoints, teleport steps) do what the scenarios need.
#include "test_constants.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <wingman/sim/motion_script.hpp>
#include <wingman/sim/scenario.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

namespace {

using wingman::sim::FrameClock;
using wingman::sim::MotionSpec;
using wingman::sim::parse_scenario;
using wingman::sim::Scenario;
using wingman::sim::ScenarioError;
using wingman::sim::VehicleSpec;
using wingman::testing::kDeg;
using wingman::testing::source_path;

/// A valid scenario; each mistake test changes one line of it.
const std::string kValid = R"(name: test
start_utime: 1767225600000000
duration_s: 10
vehicles:
  - name: follower
    id: 0
    initial:
      position: [0, 0, 5]
      yaw_deg: 90
  - name: leader
    id: 1
    initial:
      position: [0, 8, 5]
    dynamics:
      max_speed_xy: 0.5
    motion:
      type: random_walk
      from: [-20, 8, 5]
      to: [20, 8, 5]
      max_speed: 0.5
      seed: 3
)";

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  if (pos == std::string::npos) throw std::logic_error("test text lacks '" + from + "'");
  return text.replace(pos, from.size(), to);
}

/// The message of the ScenarioError that parsing `text` throws ("" if it parses).
std::string error_of(const std::string& text) {
  try {
    parse_scenario(text, "s.yaml");
  } catch (const ScenarioError& e) {
    return e.what();
  }
  return "";
}

TEST(Scenario, TheValidExampleParsesWithItsValues) {
  const Scenario s = parse_scenario(kValid, "s.yaml");
  EXPECT_EQ(s.name, "test");
  EXPECT_EQ(s.start_utime, 1767225600000000);
  EXPECT_EQ(s.duration_s, 10.0);
  EXPECT_EQ(s.command_delay_s, 0.1);  // default
  ASSERT_EQ(s.vehicles.size(), 2u);
  EXPECT_EQ(s.camera_vehicle().name, "follower");
  EXPECT_EQ(s.vehicles[0].control, VehicleSpec::Control::kSetpoints);  // default for id 0
  EXPECT_EQ(s.vehicles[1].control, VehicleSpec::Control::kScript);     // default otherwise
  EXPECT_NEAR(s.vehicles[0].yaw_initial_rad, M_PI / 2, 1e-15);
  EXPECT_EQ(s.vehicles[1].dynamics.max_speed_xy, 0.5);
  EXPECT_EQ(s.vehicles[1].motion.type, MotionSpec::Type::kRandomWalk);
  EXPECT_EQ(s.vehicles[1].motion.segment_from, Eigen::Vector3d(-20, 8, 5));
  EXPECT_EQ(s.vehicles[1].motion.min_speed, 0.5);  // defaults to max_speed
  EXPECT_EQ(s.vehicles[1].motion.seed, 3u);
  EXPECT_EQ(s.vehicles[1].drone.frame, "quad");
}

TEST(Scenario, EveryShippedScenarioLoadsAndValidates) {
  const std::set<std::string> expected = {"follow_1d", "formation_2d", "static_sweep", "crossing", "fast_target",
                                          "fly_away",  "fly_away_far", "approach",     "surround"};
  std::set<std::string> found;
  for (const auto& entry : std::filesystem::directory_iterator(source_path("config/scenarios"))) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    const Scenario s = wingman::sim::load_scenario(entry.path().string());
    found.insert(s.name);
    EXPECT_EQ(s.name, entry.path().stem().string());
    EXPECT_FALSE(s.description.empty());
    EXPECT_EQ(s.start_utime, 1767225600000000);
    EXPECT_GE(s.vehicles.size(), 2u);
    EXPECT_EQ(s.camera_vehicle().id, 0);
    for (const auto& v : s.vehicles) {
      EXPECT_TRUE(v.drone.validate().empty());
      EXPECT_TRUE(v.dynamics.validate().empty());
      if (v.control == VehicleSpec::Control::kScript) {
        EXPECT_TRUE(wingman::sim::validate_motion(v.motion, v.p_initial_in_world).empty());
      }
    }
  }
  EXPECT_EQ(found, expected);
}

TEST(Scenario, ShippedScenariosMatchTheThesisExperiments) {
  const Scenario d1 = wingman::sim::load_scenario(source_path("config/scenarios/follow_1d.yaml"));
  const VehicleSpec& leader = d1.vehicles.at(1);
  EXPECT_EQ(leader.motion.type, MotionSpec::Type::kRandomWalk);
  EXPECT_EQ(leader.motion.segment_from, Eigen::Vector3d(-20, 8, 5));
  EXPECT_EQ(leader.motion.segment_to, Eigen::Vector3d(20, 8, 5));
  EXPECT_LE(leader.motion.max_speed, 0.5);
  EXPECT_EQ(d1.camera_vehicle().p_initial_in_world, Eigen::Vector3d(0, 0, 5));
  EXPECT_NEAR(d1.camera_vehicle().yaw_initial_rad, 90 * kDeg, 1e-12);  // camera along +Y
  EXPECT_EQ(d1.camera_vehicle().control, VehicleSpec::Control::kSetpoints);

  const Scenario sweep = wingman::sim::load_scenario(source_path("config/scenarios/static_sweep.yaml"));
  const VehicleSpec& cam = sweep.camera_vehicle();
  EXPECT_EQ(cam.control, VehicleSpec::Control::kScript);
  EXPECT_EQ(cam.motion.type, MotionSpec::Type::kTeleportSteps);
  EXPECT_NEAR(cam.motion.step.norm(), 0.25, 1e-12);
  EXPECT_EQ(cam.motion.frames_per_step, 100);
  EXPECT_NEAR((cam.p_initial_in_world - sweep.vehicles.at(1).p_initial_in_world).norm(), 0.5, 1e-12);

  const Scenario f2 = wingman::sim::load_scenario(source_path("config/scenarios/formation_2d.yaml"));
  EXPECT_EQ(f2.vehicles.at(1).p_initial_in_world.z(), 11.0);
  EXPECT_NEAR((f2.vehicles.at(1).p_initial_in_world - f2.camera_vehicle().p_initial_in_world).norm(), 6.0, 1e-12);
  for (const auto& w : f2.vehicles.at(1).motion.waypoints) EXPECT_EQ(w.speed, 0.5);

  const Scenario fast = wingman::sim::load_scenario(source_path("config/scenarios/fast_target.yaml"));
  for (const auto& w : fast.vehicles.at(1).motion.waypoints) EXPECT_EQ(w.speed, 5.0);
}

// ---- one test per deliberate mistake: the message names the file, the line and the key ----

TEST(ScenarioErrors, WrongTypeNamesTheKeyAndLine) {
  const std::string e = error_of(replace(kValid, "max_speed: 0.5\n      seed", "max_speed: fast\n      seed"));
  EXPECT_NE(e.find("1 problem in scenario: s.yaml:20: vehicles[1].motion.max_speed: expected a number, got 'fast'"),
            std::string::npos)
      << e;
}

TEST(ScenarioErrors, MisspelledKeyIsUnknown) {
  const std::string e = error_of(replace(kValid, "    dynamics:", "    dynamcs:"));
  EXPECT_NE(e.find("s.yaml:15: vehicles[1].dynamcs.max_speed_xy: unknown key"), std::string::npos) << e;
}

TEST(ScenarioErrors, KeyOfAnotherMotionTypeIsUnknownWithAHint) {
  const std::string e = error_of(replace(kValid, "      seed: 3\n", "      seed: 3\n      frames_per_step: 10\n"));
  EXPECT_NE(e.find("vehicles[1].motion.frames_per_step: unknown key (motion.type random_walk takes other keys"),
            std::string::npos)
      << e;
}

TEST(ScenarioErrors, UnknownMotionType) {
  const std::string e = error_of(replace(kValid, "type: random_walk", "type: zigzag"));
  EXPECT_NE(e.find("vehicles[1].motion.type: 'zigzag' is not a motion type"), std::string::npos) << e;
}

TEST(ScenarioErrors, AKeyThatIsNotAPlainNameHidesNoOtherProblemOfItsVehicle) {
  const std::string e = error_of(replace(replace(kValid, "    dynamics:", "    [a, b]: 1\n    dynamics:"),
                                         "max_speed: 0.5\n      seed", "max_speed: fast\n      seed"));
  EXPECT_NE(e.find("vehicles[1]: a key must be a plain name, got a sequence"), std::string::npos) << e;
  EXPECT_NE(e.find("vehicles[1].motion.max_speed: expected a number, got 'fast'"), std::string::npos) << e;
}

TEST(ScenarioErrors, AVehicleThatIsNotAMappingIsOneProblem) {
  const std::string e = error_of(replace(kValid, "  - name: leader\n", "  - leader\n  - name: leader\n"));
  EXPECT_NE(e.find("vehicles[1]: expected a mapping, got 'leader'"), std::string::npos) << e;
}

TEST(ScenarioErrors, NoCameraVehicle) {
  const std::string e = error_of(replace(kValid, "id: 0", "id: 2"));
  EXPECT_NE(e.find("vehicles: no vehicle has id 0 (the camera vehicle)"), std::string::npos) << e;
}

TEST(ScenarioErrors, DuplicateIds) {
  const std::string e = error_of(replace(kValid, "id: 1", "id: 0\n    control: script"));
  EXPECT_NE(e.find("vehicles[1].id: 0 is also the id of vehicles[0]"), std::string::npos) << e;
}

TEST(ScenarioErrors, SetpointControlForATarget) {
  const std::string e = error_of(replace(kValid, "    id: 1\n", "    id: 1\n    control: setpoints\n"));
  EXPECT_NE(e.find("vehicles[1].control: 'setpoints': only the camera vehicle (id 0) takes setpoints"),
            std::string::npos)
      << e;
}

TEST(ScenarioErrors, RuleViolationInDynamicsNamesKeyValueAndRule) {
  const std::string e = error_of(replace(kValid, "max_speed_xy: 0.5", "max_speed_xy: -1"));
  EXPECT_NE(e.find("s.yaml:15: vehicles[1].dynamics.max_speed_xy = -1: must be > 0"), std::string::npos) << e;
}

TEST(ScenarioErrors, BadDroneAppearanceNamesTheDroneKey) {
  const std::string e = error_of(replace(kValid, "    dynamics:", "    drone:\n      frame: triangle\n    dynamics:"));
  EXPECT_NE(e.find("vehicles[1].drone.frame"), std::string::npos) << e;
}

TEST(ScenarioErrors, MissingInitialPosition) {
  const std::string e = error_of(replace(kValid, "      position: [0, 0, 5]\n", ""));
  EXPECT_NE(e.find("vehicles[0].initial.position: missing"), std::string::npos) << e;
}

TEST(ScenarioErrors, PositionWithTwoNumbers) {
  const std::string e = error_of(replace(kValid, "position: [0, 8, 5]", "position: [0, 8]"));
  EXPECT_NE(e.find("s.yaml:13: vehicles[1].initial.position: expected 3 numbers [x, y, z], got 2"), std::string::npos)
      << e;
}

TEST(ScenarioErrors, RandomWalkThatDoesNotContainTheInitialPosition) {
  const std::string e = error_of(replace(kValid, "position: [0, 8, 5]", "position: [0, 9, 5]"));
  EXPECT_NE(e.find("vehicles[1].motion.from/to: the segment [-20, 8, 5] .. [20, 8, 5] must contain the vehicle's "
                   "initial.position [0, 9, 5]"),
            std::string::npos)
      << e;
}

TEST(ScenarioErrors, MinSpeedAboveMaxSpeed) {
  const std::string e = error_of(replace(kValid, "      seed: 3\n", "      seed: 3\n      min_speed: 2\n"));
  EXPECT_NE(e.find("vehicles[1].motion.min_speed = 2: must be <= max_speed (0.5)"), std::string::npos) << e;
}

TEST(ScenarioErrors, WaypointWithoutPositionAndWithBadSpeed) {
  const std::string text = replace(kValid, R"(      type: random_walk
      from: [-20, 8, 5]
      to: [20, 8, 5]
      max_speed: 0.5
      seed: 3
)",
                                   R"(      type: waypoints
      waypoints:
        - {speed: 1}
        - {position: [1, 2, 3], speed: -2}
)");
  const std::string e = error_of(text);
  EXPECT_NE(e.find("vehicles[1].motion.waypoints[0].position: missing"), std::string::npos) << e;
  EXPECT_NE(e.find("vehicles[1].motion.waypoints[1].speed = -2: must be > 0"), std::string::npos) << e;
}

TEST(ScenarioErrors, DurationZeroNeedsAScriptThatEnds) {
  const std::string e = error_of(replace(kValid, "duration_s: 10", "duration_s: 0"));
  EXPECT_NE(e.find("duration_s: 0 (until the scripts end) needs a script that ends"), std::string::npos) << e;
}

TEST(ScenarioErrors, UnknownTopLevelKey) {
  const std::string e = error_of(replace(kValid, "duration_s: 10", "duration_s: 10\nlength_s: 3"));
  EXPECT_NE(e.find("s.yaml:4: length_s: unknown key"), std::string::npos) << e;
}

TEST(ScenarioErrors, NotYaml) {
  const std::string e = error_of("vehicles: [a, b\nname: x\n");
  EXPECT_NE(e.find("s.yaml:"), std::string::npos) << e;
  EXPECT_NE(e.find("not valid YAML"), std::string::npos) << e;
}

TEST(ScenarioErrors, VehiclesNotAList) {
  const std::string e = error_of("name: x\nduration_s: 1\nvehicles: 3\n");
  EXPECT_NE(e.find("s.yaml:3: vehicles: expected a non-empty sequence of vehicles, got '3'"), std::string::npos) << e;
}

TEST(ScenarioErrors, EveryProblemIsReportedAtOnce) {
  std::string text = replace(kValid, "max_speed: 0.5\n      seed", "max_speed: fast\n      seed");
  text = replace(text, "duration_s: 10", "duration_s: -1");
  text = replace(text, "yaw_deg: 90", "yaw_deg: [1]");
  const std::string e = error_of(text);
  EXPECT_EQ(e.rfind("3 problems in scenario: ", 0), 0u) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << "one line: " << e;
  EXPECT_NE(e.find("duration_s: -1: must be >= 0"), std::string::npos) << e;
  EXPECT_NE(e.find("vehicles[0].initial.yaw_deg: expected a number, got a sequence"), std::string::npos) << e;
}

TEST(ScenarioErrors, UnreadableFile) {
  try {
    wingman::sim::load_scenario("/nonexistent/s.yaml");
    FAIL() << "no error";
  } catch (const ScenarioError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/s.yaml: cannot open scenario file");
  }
}

TEST(Scenario, RelativeMeshPathsAreRelativeToTheScenarioFile) {
  wingman::testing::TempDir dir;
  const std::string path = dir.file("mesh.yaml");
  std::ofstream(path) << replace(
      kValid, "    dynamics:", "    drone:\n      frame: mesh\n      mesh_path: m/x.glb\n    dynamics:");
  const Scenario s = wingman::sim::load_scenario(path);
  EXPECT_EQ(s.vehicles[1].drone.mesh_path, dir.path() + "/m/x.glb");
}

// ---- scripted motions ----

TEST(MotionScript, RandomWalkStaysOnItsSegmentWithinTheSpeedLimit) {
  const Scenario s = wingman::sim::load_scenario(source_path("config/scenarios/follow_1d.yaml"));
  const VehicleSpec& leader = s.vehicles.at(1);
  const FrameClock clock(s.start_utime, 30.0);
  auto script =
      wingman::sim::make_motion_script(leader.motion, leader.p_initial_in_world, leader.yaw_initial_rad, clock);
  EXPECT_FALSE(script->end_utime().has_value());
  double min_x = 0, max_x = 0, max_speed = 0;
  Eigen::Vector3d prev = script->at(0.0).p_in_world;
  const double dt = 0.01;
  for (int i = 1; i <= 360000; ++i) {  // one hour at 100 Hz
    const auto r = script->at(i * dt);
    ASSERT_GE(r.p_in_world.x(), -20.0) << "t = " << i * dt;
    ASSERT_LE(r.p_in_world.x(), 20.0) << "t = " << i * dt;
    ASSERT_EQ(r.p_in_world.y(), 8.0);
    ASSERT_EQ(r.p_in_world.z(), 5.0);
    ASSERT_LE(r.v_in_world.norm(), 0.5 + 1e-12);
    // The velocity is the derivative of the position (finite difference over 10 ms).
    max_speed = std::max(max_speed, (r.p_in_world - prev).norm() / dt);
    min_x = std::min(min_x, r.p_in_world.x());
    max_x = std::max(max_x, r.p_in_world.x());
    prev = r.p_in_world;
  }
  EXPECT_LE(max_speed, 0.5 + 1e-9);
  EXPECT_GT(max_speed, 0.45);  // it does fly at up to the limit
  EXPECT_LT(min_x, -18.0);     // and covers the segment
  EXPECT_GT(max_x, 18.0);
  // Same seed, same walk, whatever the query order; another seed, another walk.
  auto again = wingman::sim::make_motion_script(leader.motion, leader.p_initial_in_world, 0.0, clock);
  EXPECT_EQ(again->at(1234.5).p_in_world, script->at(1234.5).p_in_world);
  MotionSpec other = leader.motion;
  other.seed = 8;
  auto different = wingman::sim::make_motion_script(other, leader.p_initial_in_world, 0.0, clock);
  EXPECT_NE(different->at(100.0).p_in_world, script->at(100.0).p_in_world);
}

TEST(MotionScript, TeleportStepsHoldEachPositionForExactlyItsFrames) {
  const Scenario s = wingman::sim::load_scenario(source_path("config/scenarios/static_sweep.yaml"));
  const VehicleSpec& cam = s.camera_vehicle();
  const FrameClock clock(s.start_utime, 30.0);
  auto script = wingman::sim::make_motion_script(cam.motion, cam.p_initial_in_world, cam.yaw_initial_rad, clock);
  ASSERT_TRUE(script->kinematic());
  ASSERT_EQ(script->end_utime(), clock.utime(119 * 100));
  EXPECT_EQ(clock.frames_before(*script->end_utime()), 11900);
  for (int64_t k = 0; k < 11900; ++k) {
    const auto r = script->at(clock.seconds_since_start(clock.utime(k)));
    const double distance = 0.5 + 0.25 * static_cast<double>(k / 100);
    ASSERT_NEAR(r.p_in_world.y(), -distance, 1e-9) << "frame " << k;
    ASSERT_EQ(r.v_in_world, Eigen::Vector3d::Zero());
  }
  EXPECT_NEAR(script->at(clock.seconds_since_start(clock.utime(11899))).p_in_world.y(), -30.0, 1e-9);
}

TEST(MotionScript, WaypointsAreReachedAtTheirSpeedsAndStopsLastTheirTime) {
  const Scenario s = wingman::sim::load_scenario(source_path("config/scenarios/formation_2d.yaml"));
  const VehicleSpec& leader = s.vehicles.at(1);
  const FrameClock clock(s.start_utime, 30.0);
  auto script =
      wingman::sim::make_motion_script(leader.motion, leader.p_initial_in_world, leader.yaw_initial_rad, clock);
  ASSERT_TRUE(script->end_utime().has_value());
  const double end_s = clock.seconds_since_start(*script->end_utime());
  size_t next = 0;
  double stopped_since = -1, longest_stop = 0, max_speed = 0;
  for (double t = 0; t <= end_s + 1.0; t += 0.01) {
    const auto r = script->at(t);
    max_speed = std::max(max_speed, r.v_in_world.norm());
    if (next < leader.motion.waypoints.size() &&
        (r.p_in_world - leader.motion.waypoints[next].p_in_world).norm() < 1e-9)
      ++next;
    if (r.v_in_world.norm() == 0 && t > 1.0) {
      if (stopped_since < 0) stopped_since = t;
      if (t < end_s) longest_stop = std::max(longest_stop, t - stopped_since);
    } else {
      stopped_since = -1;
    }
  }
  EXPECT_EQ(next, leader.motion.waypoints.size());  // every waypoint reached, in order
  EXPECT_NEAR(max_speed, 0.5, 1e-12);
  EXPECT_NEAR(longest_stop, 10.0, 0.02);  // the stop at the second waypoint
  EXPECT_EQ(script->at(end_s + 100).p_in_world, leader.motion.waypoints.back().p_in_world);
  // Legs: 8 m, 8 m, 10 m, 12 m at 0.5 m/s with 0.5 m/s^2 ramps (each leg 1 s longer than distance / speed), stops
  // 10 s and 5 s: 76 + 4 + 15 = 95 s.
  EXPECT_NEAR(end_s, 95.0, 1e-6);
}

}  // namespace
