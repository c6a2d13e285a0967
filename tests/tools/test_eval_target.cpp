// SPDX-License-Identifier: MIT
// `wingman eval --follower-config/--follower-set/--scenario`: the formation target derived from the follower's
// configuration (formation.offset_m) or, for the 1-D follow, from the scenario's start.
#include <gtest/gtest.h>
#include <wingman/tools/eval_target.hpp>
#include "test_support.hpp"

#include <string>

namespace {

using wingman::common::ConfigError;
using wingman::follower_ctrl::FollowerOptions;
using wingman::testing::source_path;
using wingman::tools::FlightStart;
using wingman::tools::FlightTargetSources;
using wingman::tools::formation_offset_for;
using wingman::tools::load_flight_start;

TEST(EvalTarget, FormationModeIsTheFollowersOffset) {
  FollowerOptions f;
  f.formation.offset_m = {-6.0, 2.0, 0.5};
  EXPECT_EQ(formation_offset_for(f, std::nullopt), Eigen::Vector3d(-6.0, 2.0, 0.5));
  // The same through the loader: the defaults, then a file, then --set over it.
  EXPECT_EQ(formation_offset_for(FlightTargetSources{}, 0, 1), Eigen::Vector3d(0.0, -6.0, 0.0));
  FlightTargetSources s;
  s.follower.files = {source_path("config/follower_ctrl.yaml")};
  s.follower.sets = {"formation.offset_m=[-6,2,0]"};
  EXPECT_EQ(formation_offset_for(s, 0, 1), Eigen::Vector3d(-6.0, 2.0, 0.0));
}

TEST(EvalTarget, Pid1dIsTheLeaderMovedToTheFollowersLine) {
  FollowerOptions f;
  f.mode = "pid_1d";
  FlightStart start;
  start.p_follower_in_world = {3.0, 1.5, 5.0};
  start.p_leader_in_world = {-2.0, 9.0, 4.0};
  EXPECT_EQ(formation_offset_for(f, start), Eigen::Vector3d(0.0, -7.5, 0.0));
  EXPECT_THROW(formation_offset_for(f, std::nullopt), ConfigError);  // it needs the scenario
  // config/scenarios/follow_1d.yaml: follower at y 0, leader at y 8 (what tools/fly.sh flies).
  FlightTargetSources s;
  s.follower.sets = {"controller.mode=pid_1d"};
  s.scenario = source_path("config/scenarios/follow_1d.yaml");
  EXPECT_EQ(formation_offset_for(s, 0, 1), Eigen::Vector3d(0.0, -8.0, 0.0));
}

TEST(EvalTarget, ProblemsNameTheirSource) {
  FlightTargetSources s;
  s.follower.sets = {"controller.mode=pid_1d", "formation.offset=[1,2,3]"};
  try {
    formation_offset_for(s, 0, 1);
    ADD_FAILURE() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("--set formation.offset: unknown key"), std::string::npos) << e.what();
  }
  try {
    load_flight_start(source_path("config/scenarios/follow_1d.yaml"), 0, 7);
    ADD_FAILURE() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("follow_1d.yaml: no vehicle with id 7 (the leader"), std::string::npos)
        << e.what();
  }
}

}  // namespace
