// SPDX-License-Identifier: MIT
// Usable targets and the choice of the one to follow.
#include "wingman/follower_ctrl/target_selection.hpp"

#include "wingman/follower_ctrl/world_frame.hpp"

#include <wingman/common/time_sanity.hpp>
#include <wingman/geometry/message_eigen.hpp>

#include <tuple>

namespace wingman::follower_ctrl {

TargetState TargetState::predicted_to(int64_t utime) const {
  TargetState out = *this;
  out.p_target_in_world = p_target_in_world + v_target_in_world * (static_cast<double>(utime - state_utime) * 1e-6);
  out.state_utime = utime;
  return out;
}

std::optional<SelectPolicy> parse_select_policy(const std::string& name) {
  if (name == "most_confident") return SelectPolicy::kMostConfident;
  if (name == "nearest") return SelectPolicy::kNearest;
  return std::nullopt;
}

std::vector<TargetState> usable_targets(const wingman::targets_t& msg, int64_t max_age_us) {
  const bool ned = msg.frame == wingman::own_pose_t::FRAME_NED;
  std::vector<TargetState> out;
  for (const auto& t : msg.targets) {
    // The image must be at most max_age_us old and not dated after the message (a negative age is stale, not
    // fresh: such a target was coasted forever, issue 33); a difference that overflows is not usable either. The
    // state's time (predicted_utime) must lie within max_age_us of the message either way: the prediction to
    // msg.utime is then bounded.
    if (!t.world_valid || !common::is_fresh(msg.utime, t.source_utime, max_age_us)) continue;
    if (t.predicted_utime > 0 && !common::is_fresh(msg.utime, t.predicted_utime, max_age_us, max_age_us)) continue;
    TargetState s;
    s.track_id = t.track_id;
    s.p_target_in_world = geometry::to_vector3(t.p_target_in_world);
    s.v_target_in_world = geometry::to_vector3(t.v_target_in_world);
    if (ned) {
      s.p_target_in_world = swap_ned_enu(s.p_target_in_world);
      s.v_target_in_world = swap_ned_enu(s.v_target_in_world);
    }
    s.state_utime = t.predicted_utime > 0 ? t.predicted_utime : msg.utime;
    s.source_utime = t.source_utime;
    s.confidence = t.confidence;
    s.detection_source = t.detection_source;
    s.size_sigma_rel = t.radius_m > 0 && std::isfinite(t.radius_sigma_m) ? t.radius_sigma_m / t.radius_m : 0.0;
    out.push_back(s);
  }
  return out;
}

std::optional<TargetState> select_target(const std::vector<TargetState>& usable, int32_t followed_track_id,
                                         SelectPolicy policy, const Eigen::Vector3d& p_own_in_world) {
  if (followed_track_id != 0) {
    for (const auto& t : usable)
      if (t.track_id == followed_track_id) return t;
  }
  const TargetState* best = nullptr;
  auto key = [&](const TargetState& t) {
    const double distance = (t.p_target_in_world - p_own_in_world).norm();
    const double confidence = policy == SelectPolicy::kMostConfident ? -static_cast<double>(t.confidence) : 0.0;
    return std::make_tuple(confidence, distance, t.track_id);
  };
  for (const auto& t : usable)
    if (!best || key(t) < key(*best)) best = &t;
  if (!best) return std::nullopt;
  return *best;
}

}  // namespace wingman::follower_ctrl
