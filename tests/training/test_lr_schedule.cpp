// SPDX-License-Identifier: MIT
// Learning-rate schedule: warm-up, then the thesis's steps (Table 2: 1e-3, 5e-4, 1e-4, 5e-5).
#include <wingman/training/lr_schedule.hpp>

#include <gtest/gtest.h>

namespace wingman::training {
namespace {

TEST(LearningRateSchedule, DefaultsGiveTable2AfterWarmUp) {
  const LearningRateSchedule s;
  EXPECT_TRUE(s.validate().empty());
  EXPECT_DOUBLE_EQ(s.at(1000), 1e-3);
  EXPECT_DOUBLE_EQ(s.at(9999), 1e-3);
  EXPECT_DOUBLE_EQ(s.at(10000), 5e-4);
  EXPECT_DOUBLE_EQ(s.at(19999), 5e-4);
  EXPECT_NEAR(s.at(20000), 1e-4, 1e-18);
  EXPECT_NEAR(s.at(30000), 5e-5, 1e-18);
  EXPECT_NEAR(s.at(39999), 5e-5, 1e-18);
}

TEST(LearningRateSchedule, WarmUpIsPolynomial) {
  LearningRateSchedule s;
  s.burn_in = 10;
  s.power = 4;
  EXPECT_DOUBLE_EQ(s.at(0), 1e-3 * 1e-4);                   // (1/10)^4
  EXPECT_DOUBLE_EQ(s.at(4), 1e-3 * 0.5 * 0.5 * 0.5 * 0.5);  // (5/10)^4
  EXPECT_DOUBLE_EQ(s.at(9), 1e-3);
  s.burn_in = 0;
  EXPECT_DOUBLE_EQ(s.at(0), 1e-3);
}

TEST(LearningRateSchedule, InvalidFieldsAreNamed) {
  LearningRateSchedule s;
  s.steps = {100, 50};
  s.scales = {0.5};
  s.base = 0;
  const auto p = s.validate();
  ASSERT_EQ(p.size(), 3u);
  EXPECT_NE(p[0].find("learning_rate = 0"), std::string::npos);
  EXPECT_NE(p[1].find("steps has 2 entries, scales 1"), std::string::npos);
  EXPECT_NE(p[2].find("steps[1] = 50"), std::string::npos);
}

}  // namespace
}  // namespace wingman::training
