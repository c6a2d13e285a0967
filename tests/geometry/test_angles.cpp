// SPDX-License-Identifier: MIT
// The angle wrap into (-pi, pi]: the ends of the interval, multiples of 2 pi, large angles, and non-finite input.
#include <gtest/gtest.h>
#include <wingman/geometry/angles.hpp>

#include <cmath>
#include <limits>

namespace wingman::geometry {
namespace {

TEST(WrapPi, ThePiEndIsInAndTheMinusPiEndIsNot) {
  EXPECT_EQ(wrap_pi(M_PI), M_PI);
  EXPECT_EQ(wrap_pi(-M_PI), M_PI);
  // 3 pi rounds to a double a little off the odd multiple: the result is within 1e-15 of pi or of -pi.
  EXPECT_NEAR(std::abs(wrap_pi(3.0 * M_PI)), M_PI, 1e-15);
  EXPECT_NEAR(std::abs(wrap_pi(-3.0 * M_PI)), M_PI, 1e-15);
  EXPECT_EQ(wrap_pi(0.0), 0.0);
  EXPECT_EQ(wrap_pi(2.0 * M_PI), 0.0);
  EXPECT_EQ(wrap_pi(-2.0 * M_PI), 0.0);
}

TEST(WrapPi, EveryResultIsInTheIntervalAndDiffersByAMultipleOfTwoPi) {
  // 1e-9 rad: the rounding of a 2 pi multiple of angles up to 1000 rad.
  for (double a = -1000.0; a <= 1000.0; a += 0.37) {
    const double w = wrap_pi(a);
    ASSERT_GT(w, -M_PI) << "a = " << a;
    ASSERT_LE(w, M_PI) << "a = " << a;
    const double turns = (a - w) / (2.0 * M_PI);
    ASSERT_NEAR(turns, std::round(turns), 1e-9) << "a = " << a;
  }
  EXPECT_NEAR(wrap_pi(M_PI + 1e-12), -M_PI + 1e-12, 1e-15);  // just past pi: just above -pi
  EXPECT_NEAR(wrap_pi(-M_PI + 1e-12), -M_PI + 1e-12, 1e-15);
}

TEST(WrapPi, NonFiniteInputGivesNaN) {
  EXPECT_TRUE(std::isnan(wrap_pi(std::numeric_limits<double>::quiet_NaN())));
  EXPECT_TRUE(std::isnan(wrap_pi(std::numeric_limits<double>::infinity())));
  EXPECT_TRUE(std::isnan(wrap_pi(-std::numeric_limits<double>::infinity())));
}

}  // namespace
}  // namespace wingman::geometry
