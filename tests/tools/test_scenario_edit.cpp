// SPDX-License-Identifier: MIT
// `wingman scenario set`: a scenario's copy with keys replaced, read back with the simulator's loader (issue 32:
// tools/experiment.sh's variants as data, not sed).
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <wingman/common/config.hpp>
#include <wingman/sim/scenario.hpp>
#include <wingman/tools/scenario_edit.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

using wingman::common::ConfigError;
using wingman::testing::source_path;
using wingman::testing::TempDir;
using wingman::tools::ScenarioSetOptions;
using wingman::tools::write_scenario_copy;

std::string error_of(const ScenarioSetOptions& o) {
  try {
    write_scenario_copy(o);
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected ConfigError";
  return "";
}

TEST(ScenarioSet, ReplacesTopLevelAndVehicleKeysByNameAndKeepsTheRest) {
  TempDir dir;
  const std::string original = source_path("config/scenarios/static_sweep.yaml");
  write_scenario_copy({original,
                       {"seed=7", "vehicles.camera.motion.frames_per_step=2", "vehicles.target.initial.yaw_deg=90",
                        "vehicles.camera.initial.position=[0, -10, 5]"},
                       dir.file("static_sweep.yaml")});
  const auto a = wingman::sim::load_scenario(original);
  const auto b = wingman::sim::load_scenario(dir.file("static_sweep.yaml"));
  EXPECT_EQ(b.seed, 7u);
  EXPECT_EQ(b.name, a.name);
  EXPECT_EQ(b.start_utime, a.start_utime);
  ASSERT_EQ(b.vehicles.size(), 2u);
  EXPECT_EQ(b.vehicles[0].motion.frames_per_step, 2);
  EXPECT_EQ(b.vehicles[0].motion.steps, a.vehicles[0].motion.steps);
  EXPECT_EQ(b.vehicles[0].p_initial_in_world, Eigen::Vector3d(0, -10, 5));
  EXPECT_NEAR(b.vehicles[1].yaw_initial_rad, M_PI / 2, 1e-12);
  EXPECT_EQ(b.vehicles[1].p_initial_in_world, a.vehicles[1].p_initial_in_world);
}

TEST(ScenarioSet, ProblemsAreNamedAndNothingIsWritten) {
  TempDir dir;
  const std::string original = source_path("config/scenarios/static_sweep.yaml");
  const std::string out = dir.file("copy.yaml");
  EXPECT_NE(error_of({original, {"vehicles.cam.motion.steps=2"}, out})
                .find("--set vehicles.cam.motion.steps: vehicles has no entry named 'cam' (names: camera, target)"),
            std::string::npos);
  EXPECT_NE(error_of({original, {"vehicles.camera.motion.stepz=2"}, out})
                .find("copy.yaml:20: vehicles[0].motion.stepz: unknown key"),
            std::string::npos);
  EXPECT_NE(error_of({original, {"seed=abc"}, out}).find("seed: expected a non-negative integer, got 'abc'"),
            std::string::npos);
  EXPECT_NE(error_of({original, {"seed"}, out}).find("--set 'seed': expected KEY=VALUE"), std::string::npos);
  EXPECT_NE(error_of({original, {"vehicles.camera.initial.position.x=1"}, out})
                .find("--set vehicles.camera.initial.position.x: vehicles.camera.initial.position is a value"),
            std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(ScenarioSet, RelativeMeshPathsPointAtTheOriginalsFolder) {
  TempDir dir;
  std::filesystem::create_directories(dir.file("src"));
  std::ifstream in(source_path("config/scenarios/static_sweep.yaml"));
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const std::string hover = "      type: hover";
  ASSERT_NE(yaml.find(hover), std::string::npos);
  yaml += "    drone:\n      mesh_path: meshes/x.glb\n";  // the target's (the last vehicle's) mesh, relative
  std::ofstream(dir.file("src/s.yaml")) << yaml;
  write_scenario_copy({dir.file("src/s.yaml"), {"seed=4"}, dir.file("elsewhere/s.yaml")});
  const auto copy = wingman::sim::load_scenario(dir.file("elsewhere/s.yaml"));
  EXPECT_EQ(copy.vehicles[1].drone.mesh_path, dir.file("src/meshes/x.glb"));
}

}  // namespace
