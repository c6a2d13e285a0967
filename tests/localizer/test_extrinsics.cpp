// SPDX-License-Identifier: MIT
// Extrinsics: the hand-worked sign case, camera -> body -> world, covariance rotation, validation.
#include <gtest/gtest.h>
#include <wingman/common/config.hpp>
#include <wingman/localizer/extrinsics.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <random>

namespace {

using wingman::localizer::CameraMeasurement;
using wingman::localizer::Extrinsics;
using wingman::localizer::ExtrinsicsOptions;
using wingman::localizer::PoseSample;
using wingman::localizer::rotate_covariance;
using wingman::localizer::to_world;

constexpr double kPi = 3.14159265358979323846;
constexpr double kTol = 1e-12;  // exact arithmetic up to rounding of a few products

Eigen::Quaterniond yaw(double deg) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(deg * kPi / 180, Eigen::Vector3d::UnitZ()));
}

Extrinsics forward_camera(double x_offset) {
  ExtrinsicsOptions o;
  o.p_cam_in_body = {x_offset, 0, 0};
  return Extrinsics::from_options(o);
}

TEST(ExtrinsicsOptions, DefaultsAreValidAndLookForward) {
  EXPECT_TRUE(ExtrinsicsOptions{}.validate().empty());
  const Extrinsics e = Extrinsics::from_options({});
  // Camera z (optical axis) is body x (forward), camera x (right) is body -y, camera y (down) is body -z.
  EXPECT_TRUE(e.R_cam_to_body.col(2).isApprox(Eigen::Vector3d::UnitX()));
  EXPECT_TRUE(e.R_cam_to_body.col(0).isApprox(-Eigen::Vector3d::UnitY()));
  EXPECT_TRUE(e.R_cam_to_body.col(1).isApprox(-Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE(e.p_cam_in_body.isZero());
}

// The thesis subtracted its 0.24 m camera offset. Camera 0.24 m in front of the body origin, looking
// forward; a target 10 m straight ahead of the camera is 10.24 m ahead of the body origin.
TEST(Extrinsics, HandWorkedSignCaseCameraInFrontAddsItsOffset) {
  const Extrinsics e = forward_camera(0.24);
  const Eigen::Vector3d p_body = e.cam_to_body(Eigen::Vector3d(0, 0, 10));
  EXPECT_NEAR(p_body.x(), 10.24, kTol);
  EXPECT_NEAR(p_body.y(), 0.0, kTol);
  EXPECT_NEAR(p_body.z(), 0.0, kTol);
  // 1 m to the right of and 2 m below the optical axis: body y = -1 (right is -left), z = -2 (down).
  EXPECT_TRUE(e.cam_to_body(Eigen::Vector3d(1, 2, 10)).isApprox(Eigen::Vector3d(10.24, -1, -2), kTol));
}

TEST(Extrinsics, PitchedDownCameraTiltsItsAxisBelowTheHorizon) {
  // Camera pitched 20 degrees nose-down: rotation by +20 deg about body y (left) applied after the
  // default mount. Its optical axis at 10 m lands at (0.24 + 10 cos 20, 0, -10 sin 20).
  const double a = 20 * kPi / 180;
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix() * Extrinsics::from_options({}).R_cam_to_body;
  ExtrinsicsOptions o;
  o.p_cam_in_body = {0.24, 0, 0};
  o.R_cam_to_body.clear();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) o.R_cam_to_body.push_back(R(r, c));
  ASSERT_TRUE(o.validate().empty());
  const Eigen::Vector3d p = Extrinsics::from_options(o).cam_to_body(Eigen::Vector3d(0, 0, 10));
  EXPECT_NEAR(p.x(), 0.24 + 10 * std::cos(a), 1e-12);
  EXPECT_NEAR(p.y(), 0.0, 1e-12);
  EXPECT_NEAR(p.z(), -10 * std::sin(a), 1e-12);
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

TEST(Extrinsics, RotatedCovarianceIsTheCovarianceOfRotatedSamples) {
  // Property over random rotations (seed 7): R cov R^T is symmetric, keeps trace and determinant, and
  // matches x^T cov x identities: for any unit u, u^T (R C R^T) u = (R^T u)^T C (R^T u).
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0, 1);
  for (int k = 0; k < 50; ++k) {
    const Eigen::Quaterniond q = Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized();
    Eigen::Matrix3d A;
    for (int i = 0; i < 9; ++i) A(i / 3, i % 3) = n(rng);
    const Eigen::Matrix3d C = A * A.transpose() + 0.1 * Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d R = q.toRotationMatrix();
    const Eigen::Matrix3d Cr = rotate_covariance(R, C);
    EXPECT_NEAR((Cr - Cr.transpose()).norm(), 0, 1e-12);
    EXPECT_NEAR(Cr.trace(), C.trace(), 1e-9);
    EXPECT_NEAR(Cr.determinant(), C.determinant(), 1e-9 * std::max(1.0, C.determinant()));
    const Eigen::Vector3d u = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
    EXPECT_NEAR(u.dot(Cr * u), (R.transpose() * u).dot(C * (R.transpose() * u)), 1e-9);
  }
}

TEST(ExtrinsicsOptions, RejectsBadRotationsNamingTheKey) {
  ExtrinsicsOptions o;
  o.R_cam_to_body = {1, 0, 0, 0, 1, 0, 0, 0, 1.1};
  auto p = o.validate();
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NE(p[0].find("extrinsics.R_cam_to_body"), std::string::npos) << p[0];
  EXPECT_NE(p[0].find("orthonormal"), std::string::npos) << p[0];
  o.R_cam_to_body = {1, 0, 0, 0, 1, 0, 0, 0, -1};  // a reflection: the classic sign error
  p = o.validate();
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NE(p[0].find("determinant"), std::string::npos) << p[0];
  o.R_cam_to_body = {1, 0, 0};
  o.p_cam_in_body = {0.24, 0};
  EXPECT_EQ(o.validate().size(), 2u);
  EXPECT_THROW(Extrinsics::from_options(o), std::invalid_argument);
}

TEST(ExtrinsicsOptions, LoadsFromYaml) {
  const auto o = wingman::common::load_options_from_string<ExtrinsicsOptions>(
      "extrinsics:\n  p_cam_in_body: [0.24, 0, -0.05]\n", "localizer.yaml");
  EXPECT_EQ(o.p_cam_in_body, (std::vector<double>{0.24, 0, -0.05}));
  EXPECT_EQ(o.R_cam_to_body, ExtrinsicsOptions{}.R_cam_to_body);
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
