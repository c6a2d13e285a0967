// SPDX-License-Identifier: MIT
// The PID of eq. 34-37 pinned against hand-computed terms: P, I with its clamp, D on irregular message times.
#include "wingman/follower_ctrl/pid.hpp"

#include "follower_test_helpers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace {

using wingman::follower_ctrl::Pid;
using wingman::follower_ctrl::PidGains;
using wingman::follower_ctrl::PidTerms;

using wingman::follower_ctrl::test::kT0;
using wingman::follower_ctrl::test::kTol;

const PidGains kThesis{26.0, 2.0, 2.0, 0.1};  // K_P, K_I, K_D, e_I,max

struct Step {
  double t_s, e;                     // input: time since kT0, error
  double p, integral, i, d, output;  // by hand
};

TEST(Pid, ThesisGainsOverSixStepsWithIrregularDtMatchHandComputedTerms) {
  // dt = 0.1, 0.15, 0.05, 0.2, 0.1 s. The integral is a right Riemann sum clamped to +-0.1.
  const Step steps[] = {
      {0.00, 0.2, 5.2, 0.0, 0.0, 0.0, 5.2},                                // first sample: P only
      {0.10, 0.3, 7.8, 0.03, 0.06, 2.0, 9.86},                             // D = 2 (0.1) / 0.1
      {0.25, 0.4, 10.4, 0.09, 0.18, 2.0 * 0.1 / 0.15, 10.58 + 4.0 / 3.0},  // D = 2 (0.1) / 0.15
      {0.30, 0.1, 2.6, 0.095, 0.19, -12.0, -9.21},                         // D = 2 (-0.3) / 0.05
      {0.50, 0.4, 10.4, 0.1, 0.2, 3.0, 13.6},                              // 0.095 + 0.08 clamped to 0.1
      {0.60, -0.4, -10.4, 0.06, 0.12, -16.0, -26.28},                      // unwinds at once: 0.1 - 0.04
  };
  Pid pid(kThesis);
  for (const Step& s : steps) {
    SCOPED_TRACE(testing::Message() << "t = " << s.t_s << " s, e = " << s.e);
    const PidTerms t = pid.update(s.e, kT0 + static_cast<int64_t>(s.t_s * 1e6 + 0.5));
    EXPECT_NEAR(t.p, s.p, kTol);
    EXPECT_NEAR(t.integral, s.integral, kTol);
    EXPECT_NEAR(t.i, s.i, kTol);
    EXPECT_NEAR(t.d, s.d, kTol);
    EXPECT_NEAR(t.output(), s.output, kTol);
  }
}

TEST(Pid, IntegralIsClampedOnBothSidesSoTheITermNeverExceedsKiTimesTheClamp) {
  Pid pid(kThesis);
  const double expected_integral[] = {0.0, -0.05, -0.1, -0.1, -0.1};
  for (int k = 0; k < 5; ++k) {
    const PidTerms t = pid.update(-0.5, kT0 + k * 100000);
    EXPECT_NEAR(t.integral, expected_integral[k], kTol) << "step " << k;
    EXPECT_NEAR(t.i, 2.0 * expected_integral[k], kTol) << "step " << k;
    EXPECT_NEAR(t.d, 0.0, kTol) << "constant error: no derivative";
  }
  EXPECT_NEAR(pid.integral(), -0.1, kTol);
}

TEST(Pid, ResetForgetsTheIntegralAndThePreviousError) {
  Pid pid(kThesis);
  pid.update(0.3, kT0);
  pid.update(0.3, kT0 + 100000);
  EXPECT_GT(pid.integral(), 0.0);
  pid.reset();
  EXPECT_FALSE(pid.started());
  const PidTerms t = pid.update(-0.1, kT0 + 200000);
  EXPECT_NEAR(t.output(), 26.0 * -0.1, kTol) << "P only after a reset: no I, no derivative kick from 0.3 to -0.1";
  EXPECT_EQ(t.dt_s, 0.0);
}

TEST(Pid, SampleAtTheSameUtimeKeepsTheIntegralAndRepeatsTheDerivative) {
  Pid pid(kThesis);
  pid.update(0.1, kT0);
  const PidTerms a = pid.update(0.2, kT0 + 100000);  // integral 0.02, D = 2
  const PidTerms b = pid.update(0.4, kT0 + 100000);  // same time
  EXPECT_NEAR(b.p, 10.4, kTol);
  EXPECT_NEAR(b.integral, a.integral, kTol);
  EXPECT_NEAR(b.d, a.d, kTol);
  const PidTerms c = pid.update(0.4, kT0 + 200000);  // derivative from the newest error at that time: 0
  EXPECT_NEAR(c.d, 0.0, kTol);
  EXPECT_NEAR(c.integral, 0.02 + 0.04, kTol);
}

TEST(Pid, SampleBeforeThePreviousOneThrowsAndLeavesTheStateAlone) {
  Pid pid(kThesis);
  pid.update(0.1, kT0 + 100000);
  EXPECT_THROW(pid.update(0.2, kT0), std::invalid_argument);
  const PidTerms t = pid.update(0.2, kT0 + 200000);
  EXPECT_NEAR(t.d, 2.0 * 0.1 / 0.1, kTol);
  EXPECT_NEAR(t.integral, 0.02, kTol);
}

TEST(Pid, NonFiniteGainsAndANegativeClampAreRefused) {
  EXPECT_THROW(Pid(PidGains{std::nan(""), 0, 0, 0}), std::invalid_argument);
  EXPECT_THROW(Pid(PidGains{1, 0, 0, -0.1}), std::invalid_argument);
}

}  // namespace
