// SPDX-License-Identifier: MIT
// Training options from a .cfg's [net] section and heads; validation names the field.
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/training/train_options.hpp>

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace wingman::training {
namespace {

std::string invalid_argument_of(const std::string& cfg) {
  try {
    train_options_from_model(detector::parse_darknet_cfg_string(cfg, "t.cfg"), "t.cfg");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no std::invalid_argument)";
}

TEST(TrainOptions, ThesisCfgGivesTable2) {
  const std::string path = testing::source_path("models/tiny-yolo-thesis.cfg");
  const detector::DarknetModel m = detector::parse_darknet_cfg(path);
  const TrainOptions o = train_options_from_model(m, path);
  EXPECT_EQ(o.cfg, path);
  EXPECT_EQ(o.batch, 64);
  EXPECT_EQ(o.subdivisions, 8);
  EXPECT_EQ(o.max_batches, 40000);
  EXPECT_DOUBLE_EQ(o.momentum, 0.9);
  EXPECT_DOUBLE_EQ(o.decay, 0.0005);
  EXPECT_DOUBLE_EQ(o.lr.base, 0.001);
  EXPECT_EQ(o.lr.burn_in, 1000);
  EXPECT_EQ(o.lr.steps, (std::vector<int>{10000, 20000, 30000}));
  EXPECT_EQ(o.lr.scales, (std::vector<double>{0.5, 0.2, 0.5}));
  EXPECT_DOUBLE_EQ(o.augment.hue, 0.1);
  EXPECT_DOUBLE_EQ(o.augment.saturation, 1.5);
  EXPECT_DOUBLE_EQ(o.augment.exposure, 1.5);
  EXPECT_DOUBLE_EQ(o.augment.jitter, 0.2);
  EXPECT_DOUBLE_EQ(o.augment.flip, 0.5);
  TrainOptions with_data = o;
  with_data.data = "somewhere";
  EXPECT_TRUE(with_data.validate().empty());
  // The thesis's [region] asks for multi-scale training (random=1), which the trainer does not do: said once.
  EXPECT_NE(multi_scale_note(m).find("random=1"), std::string::npos) << multi_scale_note(m);
}

TEST(TrainOptions, JitterComesFromTheHeadWithoutANetKey) {
  const std::string cfg =
      "[net]\nwidth=32\nheight=32\n[convolutional]\nfilters=6\nsize=1\nactivation=linear\n[region]\nanchors=1,1\n"
      "classes=1\nnum=1\njitter=.3\n";
  const TrainOptions o = train_options_from_model(detector::parse_darknet_cfg_string(cfg, "t.cfg"), "t.cfg");
  EXPECT_FLOAT_EQ(static_cast<float>(o.augment.jitter), 0.3f);
}

TEST(TrainOptions, BadNetKeysAreNamed) {
  const std::string head =
      "\n[convolutional]\nfilters=6\nsize=1\nactivation=linear\n[region]\nanchors=1,1\nclasses=1\nnum=1\n";
  EXPECT_NE(invalid_argument_of("[net]\nlearning_rate=fast" + head).find("t.cfg: [net] key 'learning_rate' = 'fast'"),
            std::string::npos);
  EXPECT_NE(invalid_argument_of("[net]\npolicy=poly" + head).find("key 'policy' = 'poly': supported are steps"),
            std::string::npos);
  EXPECT_NE(invalid_argument_of("[net]\nangle=7" + head).find("key 'angle' = '7'"), std::string::npos);
  EXPECT_NE(invalid_argument_of("[net]\nsteps=10,x" + head).find("'x' is not a number"), std::string::npos);
}

TEST(TrainOptions, ValidateNamesEachBadField) {
  TrainOptions o;
  o.cfg = "a.cfg";
  o.data = "d";
  o.batch = 10;
  o.subdivisions = 3;
  o.momentum = 1.0;
  o.threads = 0;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 3u);
  EXPECT_NE(p[0].find("subdivisions = 3: must be >= 1 and divide batch = 10"), std::string::npos) << p[0];
  EXPECT_NE(p[1].find("momentum = 1"), std::string::npos) << p[1];
  EXPECT_NE(p[2].find("threads = 0"), std::string::npos) << p[2];
}

TEST(WeightAverageOptions, DecayRampsUpToTheGivenValue) {
  WeightAverageOptions ema;
  EXPECT_FALSE(ema.enabled());  // off by default
  EXPECT_TRUE(ema.validate().empty());
  ema.decay = 0.99;
  ema.ramp = 10;
  EXPECT_TRUE(ema.enabled());
  EXPECT_NEAR(ema.decay_at(1), 0.99 * (1 - std::exp(-0.1)), 1e-12);  // 0.0942: the first updates follow the weights
  EXPECT_NEAR(ema.decay_at(10), 0.99 * (1 - std::exp(-1.0)), 1e-12);
  EXPECT_NEAR(ema.decay_at(1000), 0.99, 1e-12);
  for (int64_t i = 1; i < 100; ++i) EXPECT_LT(ema.decay_at(i), ema.decay_at(i + 1)) << i;
}

TEST(WeightAverageOptions, ValidateNamesEachBadFieldInTheTrainOptions) {
  TrainOptions o;
  o.cfg = "a.cfg";
  o.data = "d";
  o.ema.decay = 1.0;
  o.ema.ramp = 0;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 2u);
  EXPECT_NE(p[0].find("ema_decay = 1: must be in [0, 1)"), std::string::npos) << p[0];
  EXPECT_NE(p[1].find("ema_ramp = 0: must be > 0"), std::string::npos) << p[1];
  o.ema.decay = -0.5;
  o.ema.ramp = 5;
  ASSERT_EQ(o.validate().size(), 1u);
}

}  // namespace
}  // namespace wingman::training
