// SPDX-License-Identifier: MIT
// Constant-velocity Kalman filter: a hand-computed step, a plain dense reference, Q composition.
#include <gtest/gtest.h>
#include <wingman/localizer/kalman_cv3d.hpp>

#include <Eigen/Dense>

#include <random>

namespace {

using wingman::localizer::cv_initialize;
using wingman::localizer::cv_process_noise;
using wingman::localizer::Matrix6d;
using wingman::localizer::StateCov;
using wingman::localizer::Vector6d;

// Per axis: p = 1, v = 2, P = diag(1, 4); dt = 1, q = 1; z = x_pred + innovation, R = 2/3.
//   F P F^T = [5 4; 4 4], Q = [1/3 1/2; 1/2 1]  ->  P- = [16/3 9/2; 9/2 5],  x- = (3, 2)
//   S = 16/3 + 2/3 = 6, K = (8/9, 3/4)
//   x+ = (3 + 8/9 y, 2 + 3/4 y),  P+ = [16/27 1/2; 1/2 13/8],  d^2 = y^2 / 6
TEST(KalmanCv3d, OneStepMatchesTheHandComputedCase) {
  StateCov sc;
  sc.x << 1, 1, 1, 2, 2, 2;
  sc.P.setZero();
  sc.P.diagonal() << 1, 1, 1, 4, 4, 4;
  const StateCov pred = wingman::localizer::predict(sc, 1.0, 1.0);
  for (int a = 0; a < 3; ++a) {
    EXPECT_DOUBLE_EQ(pred.x(a), 3);
    EXPECT_DOUBLE_EQ(pred.x(3 + a), 2);
    EXPECT_DOUBLE_EQ(pred.P(a, a), 16.0 / 3);
    EXPECT_DOUBLE_EQ(pred.P(a, 3 + a), 4.5);
    EXPECT_DOUBLE_EQ(pred.P(3 + a, 3 + a), 5);
  }
  const Eigen::Vector3d y(1, -2, 0.5);
  const Eigen::Matrix3d R = 2.0 / 3 * Eigen::Matrix3d::Identity();
  const Eigen::Vector3d z = Eigen::Vector3d(3, 3, 3) + y;
  EXPECT_NEAR(wingman::localizer::mahalanobis2(pred, z, R), y.squaredNorm() / 6, 1e-14);
  const StateCov up = wingman::localizer::update(pred, z, R);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(up.x(a), 3 + 8.0 / 9 * y(a), 1e-14);
    EXPECT_NEAR(up.x(3 + a), 2 + 0.75 * y(a), 1e-14);
    EXPECT_NEAR(up.P(a, a), 16.0 / 27, 1e-14);
    EXPECT_NEAR(up.P(a, 3 + a), 0.5, 1e-14);
    EXPECT_NEAR(up.P(3 + a, a), 0.5, 1e-14);
    EXPECT_NEAR(up.P(3 + a, 3 + a), 13.0 / 8, 1e-14);
  }
  // Axes stay uncoupled when P and R are diagonal per axis.
  EXPECT_NEAR(up.P(0, 1), 0, 1e-15);
  EXPECT_NEAR(up.P(0, 4), 0, 1e-15);
}

Eigen::MatrixXd random_spd(int n, std::mt19937& rng, double floor) {
  std::normal_distribution<double> g(0, 1);
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n * n; ++i) A(i / n, i % n) = g(rng);
  return A * A.transpose() + floor * Eigen::MatrixXd::Identity(n, n);
}

// Plain dense reference: F built element by element, Q by numerically integrating
// F(s) G q G^T F(s)^T over [0, dt] (Simpson, 200 intervals), the textbook update with an explicit inverse.
struct DenseReference {
  static Eigen::MatrixXd F(double dt) {
    Eigen::MatrixXd f = Eigen::MatrixXd::Identity(6, 6);
    for (int a = 0; a < 3; ++a) f(a, 3 + a) = dt;
    return f;
  }
  static Eigen::MatrixXd Q(double accel_noise, double dt) {
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(6, 3);
    G.bottomRows(3).setIdentity();
    const int n = 200;
    const double h = dt / n;
    Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(6, 6);
    for (int k = 0; k <= n; ++k) {
      const double w = (k == 0 || k == n) ? 1 : (k % 2 ? 4 : 2);
      const Eigen::MatrixXd Fs = F(k * h);
      sum += w * Fs * G * G.transpose() * Fs.transpose();
    }
    return accel_noise * accel_noise * h / 3 * sum;
  }
};

TEST(KalmanCv3d, MatchesAPlainDenseReferenceOnRandomCases) {
  std::mt19937 rng(42);
  std::normal_distribution<double> g(0, 1);
  std::uniform_real_distribution<double> u(0.001, 1.5);
  for (int k = 0; k < 100; ++k) {
    StateCov sc;
    for (int i = 0; i < 6; ++i) sc.x(i) = 10 * g(rng);
    sc.P = random_spd(6, rng, 0.01);
    const double dt = u(rng);
    const double q = 3 * u(rng);
    const Eigen::MatrixXd R = random_spd(3, rng, 0.01);
    Eigen::Vector3d z;
    for (int i = 0; i < 3; ++i) z(i) = 10 * g(rng);

    const StateCov pred = wingman::localizer::predict(sc, q, dt);
    const StateCov up = wingman::localizer::update(pred, z, R);

    const Eigen::MatrixXd F = DenseReference::F(dt);
    const Eigen::VectorXd x_ref = F * sc.x;
    const Eigen::MatrixXd P_ref = F * sc.P * F.transpose() + DenseReference::Q(q, dt);
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(3, 6);
    H.leftCols(3).setIdentity();
    const Eigen::MatrixXd S = H * P_ref * H.transpose() + R;
    const Eigen::MatrixXd K = P_ref * H.transpose() * S.inverse();
    const Eigen::VectorXd x_up = x_ref + K * (z - H * x_ref);
    const Eigen::MatrixXd P_up = (Eigen::MatrixXd::Identity(6, 6) - K * H) * P_ref;
    const Eigen::VectorXd y = z - H * x_ref;
    const double d2_ref = y.dot(S.inverse() * y);

    const double scale = std::max(1.0, P_ref.norm());
    EXPECT_LT((pred.x - x_ref).norm(), 1e-12) << "case " << k << " dt " << dt;
    EXPECT_LT((pred.P - P_ref).norm(), 1e-9 * scale) << "case " << k << " dt " << dt << " q " << q;
    EXPECT_LT((up.x - x_up).norm(), 1e-8 * std::max(1.0, x_up.norm())) << "case " << k;
    EXPECT_LT((up.P - P_up).norm(), 1e-8 * scale) << "case " << k;
    EXPECT_NEAR(wingman::localizer::mahalanobis2(pred, z, R), d2_ref, 1e-8 * std::max(1.0, d2_ref)) << "case " << k;
  }
}

TEST(KalmanCv3d, PredictingInTwoStepsEqualsOneStep) {
  // Continuous white-noise acceleration: Q(dt1 + dt2) = F(dt2) Q(dt1) F(dt2)^T + Q(dt2).
  StateCov sc = cv_initialize({1, 2, 3}, Eigen::Matrix3d::Identity(), 2.0);
  sc.x.tail<3>() << 1, -1, 0.5;
  const StateCov two = wingman::localizer::predict(wingman::localizer::predict(sc, 1.7, 0.03), 1.7, 0.27);
  const StateCov one = wingman::localizer::predict(sc, 1.7, 0.30);
  EXPECT_LT((two.x - one.x).norm(), 1e-12);
  EXPECT_LT((two.P - one.P).norm(), 1e-12);
}

TEST(KalmanCv3d, InitializeZeroDtAndBadDt) {
  const Eigen::Matrix3d R = Eigen::Vector3d(0.1, 0.2, 0.3).asDiagonal();
  const StateCov sc = cv_initialize({4, 5, 6}, R, 3.0);
  EXPECT_TRUE(sc.p().isApprox(Eigen::Vector3d(4, 5, 6)));
  EXPECT_TRUE(sc.v().isZero());
  EXPECT_TRUE((sc.P.topLeftCorner<3, 3>().isApprox(R)));
  EXPECT_TRUE((sc.P.bottomRightCorner<3, 3>().isApprox(9 * Eigen::Matrix3d::Identity())));
  EXPECT_TRUE((sc.P.topRightCorner<3, 3>().isZero()));
  const StateCov same = wingman::localizer::predict(sc, 5.0, 0.0);
  EXPECT_EQ(same.x, sc.x);
  EXPECT_TRUE(same.P.isApprox(sc.P));
  EXPECT_TRUE(cv_process_noise(5.0, 0.0).isZero());
  EXPECT_THROW(wingman::localizer::predict(sc, 1.0, -0.001), std::invalid_argument);
}

TEST(KalmanCv3d, IsConsistentOnItsOwnModel) {
  // Simulate the model itself (seed 3): truth driven by sampled Q, measurements with R. The mean
  // NEES over 2000 steps should be near 6 (state dimension); 5.5..6.5 is about +-4 sigma of the mean
  // for correlated samples of this length.
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0, 1);
  const double q = 1.0, dt = 0.1;
  const Eigen::Matrix3d R = Eigen::Vector3d(0.04, 0.09, 0.25).asDiagonal();
  const Eigen::LLT<Matrix6d> Lq(cv_process_noise(q, dt));
  Vector6d truth;
  truth << 0, 0, 0, 1, 2, 0;
  Eigen::Vector3d z0 = truth.head<3>();
  for (int i = 0; i < 3; ++i) z0(i) += std::sqrt(R(i, i)) * g(rng);
  StateCov sc = cv_initialize(z0, R, 3.0);
  double nees_sum = 0;
  int n = 0;
  for (int k = 1; k <= 2100; ++k) {
    Vector6d w;
    for (int i = 0; i < 6; ++i) w(i) = g(rng);
    truth = wingman::localizer::cv_transition(dt) * truth + Lq.matrixL() * w;
    Eigen::Vector3d z = truth.head<3>();
    for (int i = 0; i < 3; ++i) z(i) += std::sqrt(R(i, i)) * g(rng);
    sc = wingman::localizer::update(wingman::localizer::predict(sc, q, dt), z, R);
    if (k > 100) {
      const Vector6d e = sc.x - truth;
      nees_sum += e.dot(sc.P.ldlt().solve(e));
      ++n;
    }
  }
  const double nees = nees_sum / n;
  std::printf("[ measured ] KalmanCv3d mean NEES over %d steps: %.3f (expected 6)\n", n, nees);
  EXPECT_GT(nees, 5.5);
  EXPECT_LT(nees, 6.5);
}

}  // namespace
