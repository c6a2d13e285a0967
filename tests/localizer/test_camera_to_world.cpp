// SPDX-License-Identifier: MIT
// The camera -> body -> world mapping of a measurement: the body pose after the mount, covariance rotation, the own
// pose's uncertainty (the mount itself: tests/geometry/test_extrinsics.cpp).
#include <gtest/gtest.h>
#include <wingman/geometry/extrinsics.hpp>
#include <wingman/localizer/camera_to_world.hpp>

#include "test_rotations.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include <cmath>
#include <random>

namespace {

using wingman::geometry::Extrinsics;
using wingman::geometry::ExtrinsicsOptions;
using wingman::geometry::rotate_covariance;
using wingman::localizer::CameraMeasurement;
using wingman::localizer::PoseSample;
using wingman::localizer::to_world;

using wingman::testing::kPi;
using wingman::testing::yaw;

constexpr double kTol = 1e-12;  // exact arithmetic up to rounding of a few products

Extrinsics forward_camera(double x_offset) {
  ExtrinsicsOptions o;
  o.p_cam_in_body = {x_offset, 0, 0};
  return Extrinsics::from_options(o);
}

TEST(Extrinsics, ToWorldAppliesTheBodyPoseAfterTheMount) {
  // Body at (100, 50, 20) in ENU, yawed 90 degrees (nose north): body forward is world +y.
  PoseSample pose;
  pose.utime = 1000;
  pose.p_body_in_world = {100, 50, 20};
  pose.q_body_to_world = yaw(90);
  CameraMeasurement m;
  m.p_target_in_cam = {0, 0, 10};
  m.range = 10;
  m.confidence = 0.8;
  const auto w = to_world(m, forward_camera(0.24), pose, 1234, 3);
  EXPECT_TRUE(w.p_target_in_world.isApprox(Eigen::Vector3d(100, 60.24, 20), kTol)) << w.p_target_in_world.transpose();
  EXPECT_EQ(w.utime, 1234);
  EXPECT_EQ(w.camera_id, 3);
  EXPECT_DOUBLE_EQ(w.range, 10);
  EXPECT_DOUBLE_EQ(w.confidence, 0.8);
  EXPECT_TRUE(w.p_target_in_cam.isApprox(m.p_target_in_cam));
}

TEST(Extrinsics, CovarianceIsRotatedIntoTheWorld) {
  // Range (camera z) uncertain by 1 m, lateral by 0.1 / 0.2 m. Through the default mount the range
  // axis becomes body x; yawed 90 degrees, world y.
  CameraMeasurement m;
  m.cov_p_in_cam = Eigen::Vector3d(0.01, 0.04, 1.0).asDiagonal();
  PoseSample level;
  const auto w0 = to_world(m, forward_camera(0), level, 0, 0);
  EXPECT_TRUE(w0.cov_p_in_world.isApprox(Eigen::Matrix3d(Eigen::Vector3d(1.0, 0.01, 0.04).asDiagonal()), kTol))
      << w0.cov_p_in_world;
  PoseSample north;
  north.q_body_to_world = yaw(90);
  const auto w1 = to_world(m, forward_camera(0), north, 0, 0);
  EXPECT_TRUE(w1.cov_p_in_world.isApprox(Eigen::Matrix3d(Eigen::Vector3d(0.01, 1.0, 0.04).asDiagonal()), kTol))
      << w1.cov_p_in_world;
}

}  // namespace

TEST(Extrinsics, OwnPoseCovarianceIsTheCovarianceOfTheTargetUnderSampledPoseErrors) {
  // Monte-Carlo reference (seed 11): perturb the body position by N(0, P) and the attitude by small rotations
  // about the body axes with variances var_rpy, map an exact measurement through each, and compare the sample
  // covariance of p_target_in_world with to_world's first-order covariance. The target is 30 m ahead and 5 m up,
  // the body yawed 30 degrees and pitched 5, the camera 0.2 m forward.
  PoseSample pose;
  pose.p_body_in_world = {10, -4, 12};
  pose.q_body_to_world = yaw(30) * Eigen::Quaterniond(Eigen::AngleAxisd(5 * kPi / 180, Eigen::Vector3d::UnitY()));
  pose.cov_p_body_in_world << 0.09, 0.02, 0.0,  //
      0.02, 0.04, -0.01,                        //
      0.0, -0.01, 0.16;
  pose.var_rpy_body = Eigen::Vector3d(std::pow(0.01, 2), std::pow(0.02, 2), std::pow(0.03, 2));
  CameraMeasurement m;
  m.p_target_in_cam = {0, -5, 30};  // camera y is down
  m.cov_p_in_cam.setZero();         // the measurement itself exact: only the pose's share is compared
  const Extrinsics mount = forward_camera(0.2);
  const auto w = to_world(m, mount, pose, 0, 0);

  std::mt19937 rng(11);
  std::normal_distribution<double> n(0, 1);
  const Eigen::LLT<Eigen::Matrix3d> llt(pose.cov_p_body_in_world);
  const int kSamples = 200000;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (int k = 0; k < kSamples; ++k) {
    PoseSample s = pose;
    s.cov_p_body_in_world.setZero();
    s.var_rpy_body.setZero();
    s.p_body_in_world += llt.matrixL() * Eigen::Vector3d(n(rng), n(rng), n(rng));
    const Eigen::Vector3d dtheta(std::sqrt(pose.var_rpy_body.x()) * n(rng), std::sqrt(pose.var_rpy_body.y()) * n(rng),
                                 std::sqrt(pose.var_rpy_body.z()) * n(rng));
    s.q_body_to_world =
        pose.q_body_to_world * Eigen::Quaterniond(Eigen::AngleAxisd(dtheta.norm(), dtheta.normalized()));
    const Eigen::Vector3d p = to_world(m, mount, s, 0, 0).p_target_in_world - w.p_target_in_world;
    mean += p;
    second += p * p.transpose();
  }
  mean /= kSamples;
  const Eigen::Matrix3d sample_cov = second / kSamples - mean * mean.transpose();
  // Sampling error of a covariance entry is about sqrt(2/N) of its scale (0.3 % here); first-order error at
  // 0.03 rad is of order 1e-3 relative. 2 % of the largest entry covers both.
  EXPECT_LT((sample_cov - w.cov_p_in_world).cwiseAbs().maxCoeff(), 0.02 * w.cov_p_in_world.cwiseAbs().maxCoeff())
      << "first order:\n"
      << w.cov_p_in_world << "\nsampled:\n"
      << sample_cov;
  // The attitude's share dominates at 30 m (0.03 rad of yaw is 0.9 m sideways), so the test would catch it missing.
  EXPECT_GT(w.cov_p_in_world.trace(), 3 * pose.cov_p_body_in_world.trace());
}

TEST(Extrinsics, APoseWithoutCovarianceAddsNothing) {
  PoseSample pose;
  pose.q_body_to_world = yaw(40);
  CameraMeasurement m;
  m.p_target_in_cam = {1, 2, 20};
  m.cov_p_in_cam = Eigen::Vector3d(0.01, 0.02, 0.5).asDiagonal();
  const auto w = to_world(m, forward_camera(0), pose, 0, 0);
  const Eigen::Matrix3d R = pose.q_body_to_world.toRotationMatrix() * forward_camera(0).R_cam_to_body;
  EXPECT_TRUE(w.cov_p_in_world.isApprox(rotate_covariance(R, m.cov_p_in_cam), kTol));
}
