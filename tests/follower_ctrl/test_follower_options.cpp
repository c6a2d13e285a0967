// SPDX-License-Identifier: MIT
// FollowerOptions: valid defaults, every bad key reported at once, and the shipped config equals the defaults.
#include "wingman/follower_ctrl/follower_options.hpp"

#include "test_support.hpp"

#include <gtest/gtest.h>
#include <wingman/common/config.hpp>

#include <fstream>
#include <sstream>

namespace {

using wingman::common::ConfigError;
using wingman::follower_ctrl::ControllerMode;
using wingman::follower_ctrl::FollowerOptions;

/// The YAML text without its leading comment lines (the header names the source).
std::string without_header(const std::string& yaml) {
  std::istringstream in(yaml);
  std::string line, out;
  bool body = false;
  while (std::getline(in, line)) {
    if (!body && (line.empty() || line[0] == '#')) continue;
    body = true;
    out += line + "\n";
  }
  return out;
}

TEST(FollowerOptions, DefaultsAreValidAndSelectTheFormationController) {
  const FollowerOptions o;
  EXPECT_TRUE(o.validate().empty()) << testing::PrintToString(o.validate());
  EXPECT_EQ(o.controller_mode(), ControllerMode::kFormation);
  EXPECT_EQ(o.hold_timeout_us(), 500000);
  // The thesis's numbers.
  EXPECT_EQ(o.pid_1d.kp, 26.0);
  EXPECT_EQ(o.pid_1d.ki, 2.0);
  EXPECT_EQ(o.pid_1d.kd, 2.0);
  EXPECT_EQ(o.pid_1d.integral_max, 0.1);
  EXPECT_EQ(o.formation.avoid_radius_m, 3.0);
  EXPECT_EQ(o.formation.offset_m, (std::vector<double>{0.0, -6.0, 0.0}));
}

TEST(FollowerOptions, ShippedConfigFileEqualsTheBuiltInDefaults) {
  const std::string path = wingman::testing::source_path("config/follower_ctrl.yaml");
  std::ifstream in(path);
  ASSERT_TRUE(in.good()) << path;
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(without_header(text.str()), without_header(wingman::common::print_options(FollowerOptions{})));
  const auto loaded = wingman::common::load_options<FollowerOptions>(path);
  EXPECT_EQ(wingman::common::print_options(loaded), wingman::common::print_options(FollowerOptions{}));
}

TEST(FollowerOptions, EveryBadKeyIsReportedAtOnceNamingTheFileAndTheKey) {
  const std::string yaml =
      "controller:\n  mode: hover\n"
      "hold:\n  timeout_s: 0\n"
      "limits:\n  max_horizontal_speed_mps: -1\n"
      "extrinsics:\n  R_cam_to_body: [1, 0, 0, 0, 1, 0, 0, 0, -1]\n"
      "formation:\n  select: random\n  avoid_climb_mps: 2.0\n"
      "pid_1d:\n  height_mode: target\n  kp: [1, 2]\n";
  try {
    wingman::common::load_options_from_string<FollowerOptions>(yaml, "f.yaml");
    FAIL() << "accepted";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    for (const char* expected : {
             "8 problems in configuration",
             "f.yaml:14: pid_1d.kp: expected a number, got a sequence",
             "f.yaml: controller.mode = 'hover': must be formation or pid_1d",
             "f.yaml: hold.timeout_s = 0: must be a finite number > 0",
             "f.yaml: limits.max_horizontal_speed_mps = -1: must be a finite number > 0",
             "f.yaml: extrinsics.R_cam_to_body = '[1, 0, 0, 0, 1, 0, 0, 0, -1]': must be a rotation (determinant +1, "
             "not a reflection)",
             "f.yaml: formation.select = 'random': must be most_confident or nearest",
             "f.yaml: pid_1d.height_mode = 'target': must be start or fixed",
             "f.yaml: formation.avoid_climb_mps = 2: must not exceed limits.max_vertical_speed_mps = 1",
         })
      EXPECT_NE(what.find(expected), std::string::npos) << expected << "\nnot in: " << what;
  }
}

}  // namespace
