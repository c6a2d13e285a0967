// SPDX-License-Identifier: MIT
// Helpers of the follower's tests: input message builders (ENU unless a frame is given), wide limits, vector checks.
#pragma once

#include "wingman/follower_ctrl/velocity_limits.hpp"

#include <wingman/detections_t.hpp>
#include <wingman/own_pose_t.hpp>
#include <wingman/setpoint_t.hpp>
#include <wingman/status_t.hpp>
#include <wingman/targets_t.hpp>

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <vector>

/// Expects two Eigen vectors to agree within `tol` in every component, printing both otherwise.
#define EXPECT_VEC_NEAR(a, b, tol) \
  EXPECT_LT(((a) - (b)).cwiseAbs().maxCoeff(), tol) << (a).transpose() << " vs " << (b).transpose()

namespace wingman::follower_ctrl::test {

constexpr int64_t kT0 = 1700000000000000;  ///< a message time, microseconds
constexpr int64_t kMs = 1000;              ///< one millisecond in utime units
constexpr double kTol = 1e-9;              ///< for hand-computed values: exact decimals, only rounding separates them

// Copies of the LCM constants (the generated static members have no definition to bind a reference to).
constexpr int8_t kHold = wingman::setpoint_t::MODE_HOLD;
constexpr int8_t kVelocity = wingman::setpoint_t::MODE_VELOCITY;
constexpr int8_t kEnuFrame = wingman::own_pose_t::FRAME_ENU;
constexpr int8_t kNedFrame = wingman::own_pose_t::FRAME_NED;
constexpr int8_t kCnnSource = wingman::detections_t::SOURCE_CNN;
constexpr int8_t kGroundTruthSource = wingman::detections_t::SOURCE_GROUND_TRUTH;
constexpr int8_t kOk = wingman::status_t::STATE_OK;
constexpr int8_t kDegraded = wingman::status_t::STATE_DEGRADED;
constexpr int8_t kStopping = wingman::status_t::STATE_STOPPING;

/// An own pose at `utime`: position and velocity in the world frame of `frame`, level, heading
/// `yaw_rad` (ENU: body x from east towards north; NED: body x from north towards east).
inline wingman::own_pose_t own_pose(int64_t utime, const Eigen::Vector3d& p, double yaw_rad = 0.0,
                                    const Eigen::Vector3d& v = Eigen::Vector3d::Zero(),
                                    int8_t frame = wingman::own_pose_t::FRAME_ENU) {
  wingman::own_pose_t m{};
  m.utime = utime;
  m.frame = frame;
  for (int i = 0; i < 3; ++i) {
    m.p_body_in_world[i] = p[i];
    m.v_body_in_world[i] = v[i];
  }
  m.q_body_to_world[0] = std::cos(0.5 * yaw_rad);
  m.q_body_to_world[3] = std::sin(0.5 * yaw_rad);
  return m;
}

/// A world-frame tracked target whose newest image is `source_utime`; state at `state_utime`.
inline wingman::target_t target(int32_t track_id, const Eigen::Vector3d& p, const Eigen::Vector3d& v,
                                int64_t source_utime, int64_t state_utime, float confidence = 0.9f,
                                int8_t source = wingman::detections_t::SOURCE_CNN) {
  wingman::target_t t{};
  t.track_id = track_id;
  for (int i = 0; i < 3; ++i) {
    t.p_target_in_world[i] = p[i];
    t.v_target_in_world[i] = v[i];
  }
  t.world_valid = true;
  t.range = p.norm();
  t.confidence = confidence;
  t.source_utime = source_utime;
  t.predicted_utime = state_utime;
  t.detection_source = source;
  return t;
}

inline wingman::targets_t targets(int64_t utime, std::vector<wingman::target_t> list,
                                  int8_t frame = wingman::own_pose_t::FRAME_ENU) {
  wingman::targets_t m{};
  m.utime = utime;
  m.frame = frame;
  m.targets = std::move(list);
  m.num_targets = static_cast<int32_t>(m.targets.size());
  return m;
}

/// A box of the given centre x (pixels); the other fields are plausible.
inline wingman::detection_t box(float cx, float confidence = 0.8f) {
  wingman::detection_t d{};
  d.cx = cx;
  d.cy = 240.0f;
  d.w = 40.0f;
  d.h = 30.0f;
  d.confidence = confidence;
  return d;
}

inline wingman::detections_t detections(int64_t utime, std::vector<wingman::detection_t> boxes, int width = 1000,
                                        int8_t source = wingman::detections_t::SOURCE_CNN) {
  wingman::detections_t m{};
  m.utime = utime;
  m.image_width = width;
  m.image_height = 480;
  m.source = source;
  m.detections = std::move(boxes);
  m.num_detections = static_cast<int32_t>(m.detections.size());
  return m;
}

/// The default camera mount (extrinsics.R_cam_to_body): camera looking along body +x, image upright.
inline Eigen::Matrix3d default_mount() { return (Eigen::Matrix3d() << 0, 0, 1, -1, 0, 0, 0, -1, 0).finished(); }

/// Limits that do not act on the tested controllers' outputs (the limits have their own tests).
inline LimitsOptions wide_limits() {
  LimitsOptions l;
  l.max_horizontal_speed_mps = 100;
  l.max_vertical_speed_mps = 100;
  l.max_horizontal_accel_mps2 = 1e6;
  l.max_vertical_accel_mps2 = 1e6;
  l.max_yaw_rate_radps = 1.0;
  l.floor_height_m = 1.0;
  return l;
}

}  // namespace wingman::follower_ctrl::test
