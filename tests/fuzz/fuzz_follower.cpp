// SPDX-License-Identifier: MIT
// Fuzz target: wingman-follower-ctrl's handlers. The input is a sequence of records (fuzz_support.hpp);
// selector % 3: 0 = own_pose_t, 1 = targets_t (to the formation follower), 2 = detections_t (to the pid_1d
// follower); own poses go to both. Delivered as follower_ctrl/main.cpp does (Runtime's decode and
// validate_message, then Follower::on_*; exceptions drop the message). Every setpoint published must validate.
#include "fuzz_support.hpp"

#include <wingman/follower_ctrl/follower.hpp>

#include <cstdlib>

namespace {

using namespace wingman;

void check_output(const follower_ctrl::FollowerOutput& out) {
  if (!out.setpoint) return;
  const std::string problem = common::validate_message(*out.setpoint);
  if (!problem.empty()) {
    std::fprintf(stderr, "the follower published an invalid setpoint_t: %s\n", problem.c_str());
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const common::MessageLimits limits;
  follower_ctrl::FollowerOptions formation_options;
  formation_options.mode = "formation";
  follower_ctrl::FollowerOptions pid_options;
  pid_options.mode = "pid_1d";
  follower_ctrl::Follower formation(formation_options);
  follower_ctrl::Follower pid(pid_options);
  fuzz::Records records(data, size);
  uint8_t selector = 0;
  const uint8_t* payload = nullptr;
  size_t n = 0;
  for (int i = 0; i < 64 && records.next(&selector, &payload, &n); ++i) {
    switch (selector % 3) {
      case 0:
        fuzz::deliver<own_pose_t>(payload, n, limits, fuzz::default_validator<own_pose_t>(), [&](const own_pose_t& p) {
          check_output(formation.on_own_pose(p));
          check_output(pid.on_own_pose(p));
        });
        break;
      case 1:
        fuzz::deliver<targets_t>(payload, n, limits, fuzz::default_validator<targets_t>(),
                                 [&](const targets_t& t) { check_output(formation.on_targets(t)); });
        break;
      default:
        fuzz::deliver<detections_t>(payload, n, limits, fuzz::default_validator<detections_t>(),
                                    [&](const detections_t& d) { check_output(pid.on_detections(d)); });
        break;
    }
  }
  return 0;
}
