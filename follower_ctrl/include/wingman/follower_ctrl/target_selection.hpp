// SPDX-License-Identifier: MIT
// Which tracked target the formation follows: usable targets of a targets_t, and the choice of one.
#pragma once

#include <wingman/targets_t.hpp>

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace wingman::follower_ctrl {

/// One tracked target in Wingman's ENU world frame.
struct TargetState {
  int32_t track_id = 0;
  Eigen::Vector3d p_target_in_world = Eigen::Vector3d::Zero();  ///< ENU, metres, at state_utime
  Eigen::Vector3d v_target_in_world = Eigen::Vector3d::Zero();  ///< ENU, m/s
  int64_t state_utime = 0;      ///< time of p and v (target_t.predicted_utime, or targets_t.utime when unset)
  int64_t source_utime = 0;     ///< exposure utime of the newest image that updated the track
  float confidence = 0.0f;      ///< track confidence, 0..1
  int8_t detection_source = 0;  ///< detections_t.SOURCE_ of that image
  /// The track's size doubt: target_t.radius_sigma_m / radius_m (0 when the localizer does not estimate the size).
  double size_sigma_rel = 0.0;

  /// The state moved to `utime` at constant velocity (the tracker's motion model).
  TargetState predicted_to(int64_t utime) const;
};

/// How a new target is chosen when none is followed or the followed track has gone.
enum class SelectPolicy {
  kMostConfident,  ///< "most_confident": highest confidence, ties to the nearest, then the lowest track_id
  kNearest,        ///< "nearest": smallest distance to the own position, ties to the lowest track_id
};

/// "most_confident" or "nearest"; nullopt for anything else.
std::optional<SelectPolicy> parse_select_policy(const std::string& name);

/// The targets of `msg` a controller may follow, converted to ENU (msg.frame NED is swapped): those
/// with world_valid, whose newest image is at most `max_age_us` older than msg.utime and not after it
/// (0 <= msg.utime - source_utime <= max_age_us; message time), and whose state time (predicted_utime, when set) is
/// within max_age_us of msg.utime. Order kept.
std::vector<TargetState> usable_targets(const wingman::targets_t& msg, int64_t max_age_us);

/// The target to follow among `usable`: the one with `followed_track_id` while it is there (0: none
/// followed), else the best by `policy` (distances from `p_own_in_world`, ENU). nullopt when `usable` is empty.
std::optional<TargetState> select_target(const std::vector<TargetState>& usable, int32_t followed_track_id,
                                         SelectPolicy policy, const Eigen::Vector3d& p_own_in_world);

}  // namespace wingman::follower_ctrl
