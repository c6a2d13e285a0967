// SPDX-License-Identifier: MIT
// Extrinsics: the hand-worked sign case, camera -> body, covariance rotation, validation (camera -> world: the
// localizer's tests/localizer/test_camera_to_world.cpp).
#include <gtest/gtest.h>
#include <wingman/common/config.hpp>
#include <wingman/geometry/extrinsics.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <random>

namespace {

using wingman::geometry::Extrinsics;
using wingman::geometry::ExtrinsicsOptions;
using wingman::geometry::rotate_covariance;

constexpr double kPi = 3.14159265358979323846;
constexpr double kTol = 1e-12;  // exact arithmetic up to rounding of a few products

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
