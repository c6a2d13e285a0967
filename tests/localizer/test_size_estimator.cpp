// SPDX-License-Identifier: MIT
// Online size estimation (size_estimator.hpp, and the tracker with it): convergence when the camera moves across
// the line of sight, the prior when it cannot tell, the bias of a manoeuvring target, and what the tracker publishes.
#include <wingman/localizer/size_estimator.hpp>
#include <wingman/localizer/tracker.hpp>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>

namespace wingman::localizer {
namespace {

constexpr int64_t kT0 = 1'767'225'600'000'000;
constexpr double kDt = 0.1;  // 10 Hz detections

/// The localizer's detection of a target at p_target from a camera at p_cam, made with a radius `true_scale` times
/// too small (so it comes out that much too near), with 5 % range noise and 5 cm across.
WorldMeasurement detect(const Eigen::Vector3d& p_target, const Eigen::Vector3d& p_cam, double true_scale,
                        std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Vector3d rel = p_target - p_cam;
  const Eigen::Vector3d u = rel.normalized();
  const double range = rel.norm() / true_scale;
  const double sr = 0.05 * range, sx = 0.05;
  const Eigen::Vector3d e1 = u.cross(Eigen::Vector3d::UnitZ()).normalized(), e2 = u.cross(e1);
  WorldMeasurement z;
  z.p_cam_in_world = p_cam;
  z.p_target_in_world = p_cam + u * (range + sr * n(rng)) + e1 * sx * n(rng) + e2 * sx * n(rng);
  z.cov_p_in_world = sr * sr * u * u.transpose() + sx * sx * (e1 * e1.transpose() + e2 * e2.transpose());
  z.range = range;
  z.confidence = 0.9;
  return z;
}

using Path = std::function<Eigen::Vector3d(double)>;

/// Flies `seconds` of detections through a tracker with size estimation; returns the last published scale and sigma.
std::pair<double, double> fly(const Path& target, const Path& camera, double true_scale, double seconds,
                              unsigned seed) {
  std::mt19937 rng(seed);
  TrackerOptions o;
  o.size.enabled = true;
  Tracker tracker(o);
  std::pair<double, double> result{0, 0};
  for (int k = 0; k <= static_cast<int>(seconds / kDt); ++k) {
    const double t = k * kDt;
    const int64_t utime = kT0 + static_cast<int64_t>(std::llround(t * 1e6));
    EXPECT_TRUE(tracker.update(utime, {detect(target(t), camera(t), true_scale, rng)}));
    const auto out = tracker.confirmed(utime);
    if (k >= o.birth_hits - 1) {
      EXPECT_EQ(out.size(), 1u) << "t = " << t;  // confirmed at the M-th detection
    }
    if (out.size() == 1) result = {out[0].size_scale, out[0].size_scale_sigma};
  }
  return result;
}

// A leader flying straight at 1 m/s, 8 m ahead and to the side.
const Path kStraightLeader = [](double t) { return Eigen::Vector3d(1.0 * t, 8.0, 10.0); };
// A follower keeping pace but weaving +-2 m across the line of sight with a 6-s period.
const Path kWeavingFollower = [](double t) {
  return Eigen::Vector3d(1.0 * t + 2.0 * std::sin(2 * M_PI * t / 6.0), 0.0, 10.0);
};
// A follower in lock step: the same velocity, no weave.
const Path kLockStepFollower = [](double t) { return Eigen::Vector3d(1.0 * t, 0.0, 10.0); };

TEST(SizeEstimator, AFollowerWeavingAcrossTheLineOfSightFindsTheSizeWithin5PercentIn10Seconds) {
  for (const double true_scale : {0.7, 1.3}) {  // target.radius_m 30 % too large or too small
    for (unsigned seed : {1u, 2u, 3u}) {
      const auto [s, sigma] = fly(kStraightLeader, kWeavingFollower, true_scale, 10.0, seed);
      std::printf("[ measured ] true scale %.2f, seed %u: %.3f +- %.3f after 10 s\n", true_scale, seed, s, sigma);
      EXPECT_NEAR(s / true_scale, 1.0, 0.05) << "true scale " << true_scale << ", seed " << seed;
      EXPECT_LT(sigma, 0.05 * true_scale);
    }
  }
}

TEST(SizeEstimator, AFollowerInLockStepCannotTellAndKeepsThePriorSayingSo) {
  const auto [s, sigma] = fly(kStraightLeader, kLockStepFollower, 1.3, 10.0, 4);
  std::printf("[ measured ] lock step, true scale 1.30: %.3f +- %.3f after 10 s\n", s, sigma);
  EXPECT_NEAR(s, 1.0, 0.05);
  EXPECT_GT(sigma, 0.25);
}

TEST(SizeEstimator, AStillCameraCannotTellWhateverTheTargetDoes) {
  // A turning target seen from a camera that does not move: any size fits (a smaller target, nearer, turns on a
  // smaller circle), so the prior stays.
  const Path circling = [](double t) {
    return Eigen::Vector3d(8.0 * std::cos(0.5 * t), 12.0 + 8.0 * std::sin(0.5 * t), 10.0);
  };
  const Path still = [](double) { return Eigen::Vector3d(0.0, 0.0, 10.0); };
  const auto [s, sigma] = fly(circling, still, 1.3, 20.0, 5);
  std::printf("[ measured ] target circling at 4 m/s, still camera, true scale 1.30: %.3f +- %.3f\n", s, sigma);
  EXPECT_NEAR(s, 1.0, 0.05);
  EXPECT_GT(sigma, 0.25);
}

TEST(SizeEstimator, AFollowerLaggingATurningLeaderAdoptsNoWrongSize) {
  // The leader turns (2 m/s^2) and the follower repeats its path 0.7 s later, 8 m behind: the relative path bends
  // against the fit's model, whose chi-square then refuses it. The track keeps the configured size.
  const Path circling = [](double t) {
    return Eigen::Vector3d(8.0 * std::cos(0.5 * t), 12.0 + 8.0 * std::sin(0.5 * t), 10.0);
  };
  const Path lagging = [&](double t) { return Eigen::Vector3d(circling(t - 0.7) - Eigen::Vector3d(0.0, 8.0, 0.0)); };
  for (const double true_scale : {0.7, 1.3}) {
    const auto [s, sigma] = fly(circling, lagging, true_scale, 20.0, 7);
    std::printf("[ measured ] leader turning at 2 m/s^2, follower 0.7 s behind, true scale %.2f: %.3f +- %.3f\n",
                true_scale, s, sigma);
    EXPECT_TRUE(std::abs(s - true_scale) < 0.05 * true_scale || (s == 1.0 && sigma >= 0.25))
        << "true scale " << true_scale << ": a wrong size adopted";
  }
}

TEST(SizeEstimator, OffByDefaultItIsTheConfiguredSizeAndTheTrackerIsUnchanged) {
  TrackerOptions off;
  EXPECT_FALSE(off.size.enabled);
  Tracker a(off);
  SizeEstimator e(off.size);
  e.add(kT0, {1, 2, 3}, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  EXPECT_EQ(e.estimate().scale, 1.0);
  EXPECT_EQ(e.estimate().sigma, 0.0);
  std::mt19937 rng(6);
  for (int k = 0; k < 30; ++k)
    a.update(kT0 + k * 100'000, {detect(kStraightLeader(k * kDt), kWeavingFollower(k * kDt), 1.3, rng)});
  const auto out = a.confirmed(kT0 + 29 * 100'000);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].size_scale, 1.0);
  EXPECT_EQ(out[0].size_scale_sigma, 0.0);
}

TEST(SizeEstimator, TooFewDetectionsGiveThePrior) {
  SizeEstimatorOptions on;
  on.enabled = true;
  SizeEstimator e(on);
  for (int k = 0; k < 5; ++k)
    e.add(kT0 + k * 100'000, {10.0 + k, 0, 0}, 0.01 * Eigen::Matrix3d::Identity(), {0.0 + k, 1.0 * k, 0});
  const SizeEstimate s = e.estimate();
  EXPECT_FALSE(s.from_data);
  EXPECT_EQ(s.scale, 1.0);
  EXPECT_EQ(s.sigma, SizeEstimatorOptions{}.prior_rel);
}

TEST(SizeEstimator, OptionsOutsideTheirRangeAreNamed) {
  TrackerOptions o;
  o.size.prior_rel = 0;
  o.size.window_s = std::nan("");
  o.size.min_detections = 2;
  std::string all;
  for (const auto& p : o.validate()) all += p + "\n";
  EXPECT_NE(all.find("tracker.size_prior_rel"), std::string::npos) << all;
  EXPECT_NE(all.find("tracker.size_window_s"), std::string::npos) << all;
  EXPECT_NE(all.find("tracker.size_min_detections"), std::string::npos) << all;
}

}  // namespace
}  // namespace wingman::localizer
