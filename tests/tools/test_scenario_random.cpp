// SPDX-License-Identifier: MIT
// `wingman scenario random`: the written scenarios load with the simulator's reader and stay in the stated ranges.
#include "test_support.hpp"

#include <wingman/common/config.hpp>
#include <wingman/follower_ctrl/follower_options.hpp>
#include <wingman/localizer/localizer_options.hpp>
#include <wingman/sim/drone_model.hpp>
#include <wingman/sim/scenario.hpp>
#include <wingman/sim/sim_options.hpp>
#include <wingman/tools/scenario_random.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace wingman::tools {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// The shared airframes (../shared/meshes beside the checkout), or "" when absent.
std::string shared_mesh(const std::string& name) {
  const std::filesystem::path p = std::filesystem::path(WINGMAN_SOURCE_DIR) / ".." / "shared" / "meshes" / name;
  return std::filesystem::is_regular_file(p) ? p.string() : "";
}

double wrap_deg(double a) { return std::remainder(a, 360.0); }

// Checks one written flight against the ranges the verb states, reading every file with the reader that uses it.
void check_flight(const ScenarioRandomOptions& o, const ScenarioRandomResult& r) {
  SCOPED_TRACE("seed " + std::to_string(o.seed) + ", airframe " + o.airframe + ", view " + o.view);
  const sim::Scenario s = sim::load_scenario(r.scenario_path);
  ASSERT_EQ(s.vehicles.size(), 2u);
  const sim::VehicleSpec& follower = s.camera_vehicle();
  EXPECT_EQ(follower.control, sim::VehicleSpec::Control::kSetpoints);
  const sim::VehicleSpec& leader = s.vehicles[0].id == 0 ? s.vehicles[1] : s.vehicles[0];
  EXPECT_EQ(leader.control, sim::VehicleSpec::Control::kScript);
  EXPECT_GE(s.duration_s, 30.0);
  EXPECT_LE(s.duration_s, 60.0);
  EXPECT_EQ(s.seed, o.seed);
  const Eigen::Vector3d offset = follower.p_initial_in_world - leader.p_initial_in_world;
  EXPECT_GE(offset.norm(), 4.0 - 1e-3);
  EXPECT_LE(offset.norm(), 20.0 + 1e-3);
  EXPECT_LE(std::abs(std::asin(offset.z() / offset.norm())), 10.0 * kDeg + 1e-3);
  // The follower faces the leader; the leader's heading gives the view and never changes on its path.
  const double to_leader = std::atan2(-offset.y(), -offset.x());
  EXPECT_NEAR(wrap_deg((follower.yaw_initial_rad - to_leader) / kDeg), 0.0, 0.01);
  const double view = std::abs(wrap_deg((leader.yaw_initial_rad - to_leader) / kDeg));
  EXPECT_NEAR(view, o.view == "behind" ? 0.0 : 90.0, 0.01);
  ASSERT_EQ(leader.motion.type, sim::MotionSpec::Type::kWaypoints);
  ASSERT_FALSE(leader.motion.waypoints.empty());
  EXPECT_FALSE(leader.motion.loop);
  Eigen::Vector3d p = leader.p_initial_in_world;
  bool climbs = false;
  for (const sim::Waypoint& w : leader.motion.waypoints) {
    EXPECT_GE(w.speed, 0.3);
    EXPECT_LE(w.speed, 3.0);
    EXPECT_FALSE(w.yaw_rad.has_value());
    EXPECT_GE(w.p_in_world.z(), 6.0 - 1e-3);
    EXPECT_LE(w.p_in_world.z(), 18.0 + 1e-3);
    EXPECT_GE(w.p_in_world.z() + offset.z(), 1.0);  // the follower, holding the offset, stays above its floor
    climbs = climbs || std::abs(w.p_in_world.z() - p.z()) > 0.1;
    p = w.p_in_world;
  }
  EXPECT_TRUE(climbs) << "the path never changes height";
  EXPECT_LE(leader.dynamics.max_speed_xy + 1e-9, 5.0);
  EXPECT_GE(leader.dynamics.max_speed_xy, 3.0);

  // The leader's size as the simulator reports it (ground truth) is the localizer's target.radius_m.
  const double radius = sim::DroneModel::from_spec(leader.drone).bounding_radius();
  EXPECT_NEAR(r.bounding_radius_m, radius, 1e-6);
  const auto loc = common::load_options<localizer::LocalizerOptions>(r.localizer_path);
  EXPECT_NEAR(loc.sphere.radius_m, radius, 1e-6);
  const auto fol = common::load_options<follower_ctrl::FollowerOptions>(r.follower_path);
  ASSERT_EQ(fol.formation.offset_m.size(), 3u);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(fol.formation.offset_m[i], offset[i], 1e-3);
  EXPECT_EQ(fol.formation.height_mode, "target");
  // The render file is a valid simulator configuration (render.* keys only).
  const auto sim_options = common::load_options<sim::SimOptions>(r.render_path);
  EXPECT_EQ(sim_options.render_options.sun_elevation_deg, o.lighting == "A" ? 45.0 : 8.0);
  EXPECT_EQ(sim_options.render_options.motion_blur_exposure_s, 0.0);
}

TEST(ScenarioRandom, ProceduralFlightsLoadWithTheSimulatorsReaderWithinTheStatedRanges) {
  testing::TempDir dir;
  int n = 0;
  for (uint64_t seed = 1001; seed <= 1004; ++seed) {
    for (const char* airframe : {"quad", "hex", "octo"}) {
      ScenarioRandomOptions o;
      o.seed = seed;
      o.airframe = airframe;
      o.view = seed % 2 ? "behind" : "side";
      o.lighting = seed % 2 ? "A" : "B";
      o.out = dir.file(std::to_string(n++) + "/flight.yaml");
      const ScenarioRandomResult r = write_random_scenario(o);
      check_flight(o, r);
      EXPECT_EQ(sim::load_scenario(r.scenario_path).vehicles[1].drone.frame, airframe);
    }
  }
}

TEST(ScenarioRandom, SharedMeshAirframesCarryTheirTrueBoundingRadius) {
  // The radii the meshes' README lists (r_spin, propellers at any angle), to the millimetre.
  const std::pair<const char*, double> meshes[] = {
      {"dji_f450.glb", 0.348}, {"holybro_x500v2.glb", 0.429}, {"tarot_t650.glb", 0.494}, {"3dr_iris.glb", 0.390}};
  if (shared_mesh("dji_f450.glb").empty()) GTEST_SKIP() << "no ../shared/meshes beside the checkout";
  testing::TempDir dir;
  uint64_t seed = 1001;
  for (const auto& [name, r_spin] : meshes) {
    ScenarioRandomOptions o;
    o.seed = seed++;
    o.airframe = shared_mesh(name);
    o.view = "side";
    o.out = dir.file(std::string(name) + ".yaml");
    const ScenarioRandomResult r = write_random_scenario(o);
    check_flight(o, r);
    EXPECT_NEAR(r.bounding_radius_m, r_spin, 0.0015) << name;
    const sim::Scenario s = sim::load_scenario(r.scenario_path);
    EXPECT_EQ(s.vehicles[1].drone.frame, "mesh");
    EXPECT_TRUE(std::filesystem::path(s.vehicles[1].drone.mesh_path).is_absolute());
  }
}

TEST(ScenarioRandom, TheSameSeedWritesTheSameBytesAndAnotherSeedAnotherFlight) {
  testing::TempDir dir;
  ScenarioRandomOptions o;
  o.seed = 1005;
  o.out = dir.file("a.yaml");
  const ScenarioRandomResult a = write_random_scenario(o);
  o.out = dir.file("b.yaml");
  const ScenarioRandomResult b = write_random_scenario(o);
  o.seed = 1006;
  o.out = dir.file("c.yaml");
  const ScenarioRandomResult c = write_random_scenario(o);
  // The files differ only in the name they carry (b for a): compare what follows the name line.
  const auto body = [](const std::string& text) { return text.substr(text.find("\nstart_utime")); };
  EXPECT_EQ(body(slurp(a.scenario_path)), body(slurp(b.scenario_path)));
  EXPECT_EQ(slurp(a.follower_path).substr(slurp(a.follower_path).find('\n')),
            slurp(b.follower_path).substr(slurp(b.follower_path).find('\n')));
  EXPECT_NE(body(slurp(a.scenario_path)), body(slurp(c.scenario_path)));
}

TEST(ScenarioRandom, BadOptionsAreOneErrorNamingTheOption) {
  testing::TempDir dir;
  ScenarioRandomOptions o;
  o.out = dir.file("x.yaml");
  EXPECT_TRUE(o.validate().empty());
  o.view = "above";
  try {
    write_random_scenario(o);
    FAIL() << "accepted --view above";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--view = 'above'"), std::string::npos) << e.what();
  }
  o.view = "side";
  o.airframe = dir.file("no-such-airframe.glb");
  try {
    write_random_scenario(o);
    FAIL() << "accepted a missing mesh";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no-such-airframe.glb"), std::string::npos) << e.what();
  }
  o.airframe = "quad";
  o.out = dir.file("x.yml");
  EXPECT_FALSE(o.validate().empty());
  o.out = dir.file("x.yaml");
  o.lighting = "C";
  EXPECT_NE(o.validate().at(0).find("--lighting"), std::string::npos);
}

// `wingman scenario sweep`: the target hovers, the scripted camera steps straight away from it, the localizer file
// carries the airframe's radius.
TEST(ScenarioSweep, TheSweepLoadsWithTheSimulatorsReaderAndStepsFromFromToTo) {
  testing::TempDir dir;
  for (const std::string view : {"behind", "side"}) {
    ScenarioSweepOptions o;
    o.airframe = "hex";
    o.view = view;
    o.from_m = 3.0;
    o.to_m = 12.0;
    o.step_m = 1.5;
    o.frames_per_step = 4;
    o.out = dir.file("w-" + view + ".yaml");
    const ScenarioRandomResult r = write_sweep_scenario(o);
    SCOPED_TRACE(view);
    EXPECT_EQ(r.legs, 7);  // 3, 4.5, ..., 12 m
    const sim::Scenario s = sim::load_scenario(r.scenario_path);
    ASSERT_EQ(s.vehicles.size(), 2u);
    const sim::VehicleSpec& camera = s.camera_vehicle();
    const sim::VehicleSpec& target = s.vehicles[0].id == 0 ? s.vehicles[1] : s.vehicles[0];
    EXPECT_EQ(camera.control, sim::VehicleSpec::Control::kScript);
    ASSERT_EQ(camera.motion.type, sim::MotionSpec::Type::kTeleportSteps);
    EXPECT_EQ(camera.motion.steps, 7);
    EXPECT_EQ(camera.motion.frames_per_step, 4);
    EXPECT_EQ(target.motion.type, sim::MotionSpec::Type::kHover);
    // First and last distances along the line of sight (camera looks along +Y at the target).
    const Eigen::Vector3d first = target.p_initial_in_world - camera.p_initial_in_world;
    const Eigen::Vector3d last = first - 6.0 * camera.motion.step;
    EXPECT_NEAR(first.norm(), 3.0, 1e-9);
    EXPECT_NEAR(last.norm(), 12.0, 1e-9);
    EXPECT_NEAR(camera.yaw_initial_rad, 90.0 * kDeg, 1e-9);
    EXPECT_NEAR(target.yaw_initial_rad, view == "behind" ? 90.0 * kDeg : 0.0, 1e-9);
    const auto loc = common::load_options<localizer::LocalizerOptions>(r.localizer_path);
    EXPECT_NEAR(loc.sphere.radius_m, r.bounding_radius_m, 1e-9);
    EXPECT_NEAR(loc.sphere.radius_m, sim::DroneModel::from_spec(target.drone).bounding_radius(), 1e-9);
    const nlohmann::json drawn = nlohmann::json::parse(slurp(r.json_path));
    EXPECT_EQ(drawn.at("kind"), "sweep");
    EXPECT_EQ(drawn.at("steps"), 7);
    EXPECT_EQ(drawn.at("view"), view);
    EXPECT_NEAR(drawn.at("bounding_radius_m").get<double>(), r.bounding_radius_m, 1e-12);
  }
  // Bad options name the option.
  ScenarioSweepOptions bad;
  bad.out = dir.file("bad.yaml");
  bad.to_m = 2.0;
  bad.step_m = 0.0;
  bad.frames_per_step = 0;
  const auto problems = bad.validate();
  std::string all;
  for (const auto& p : problems) all += p + "\n";
  EXPECT_NE(all.find("--to = 2"), std::string::npos) << all;
  EXPECT_NE(all.find("--step = 0"), std::string::npos) << all;
  EXPECT_NE(all.find("--frames-per-step = 0"), std::string::npos) << all;
  bad = ScenarioSweepOptions{};
  bad.out = dir.file("bad.yaml");
  bad.step_m = 0.001;  // 27000 steps
  EXPECT_NE(bad.validate().at(0).find("more than 1000 steps"), std::string::npos);
  bad.step_m = 0.5;
  bad.from_m = 0.3;  // inside 1.5 x the radius
  EXPECT_THROW(write_sweep_scenario(bad), std::invalid_argument);
}

}  // namespace
}  // namespace wingman::tools
