// SPDX-License-Identifier: MIT
// `wingman val` on a dataset: saved predictions give the hand-computed metrics; the detector path runs end to end.
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>
#include <wingman/training/val.hpp>
#include <wingman/training/yolo_dataset.hpp>

#include "hand_case.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace wingman::training {
namespace {

namespace fs = std::filesystem;

TEST(Val, DefaultsAreValidOnceDataAndWeightsAreGiven) {
  ValOptions o;
  o.data = "d";
  o.weights = "w";
  EXPECT_TRUE(o.validate().empty());
  EXPECT_DOUBLE_EQ(o.detection.p_thresh, 0.005);
  EXPECT_DOUBLE_EQ(o.metrics.conf_thresh, 0.2);
  o.predictions = "p";
  ASSERT_EQ(o.validate().size(), 1u);
  EXPECT_NE(o.validate()[0].find("exactly one"), std::string::npos);
}

TEST(Val, SavedPredictionsGiveTheHandComputedMetrics) {
  testing::TempDir dir;
  write_hand_case(dir);
  ValOptions o;
  o.data = dir.file("data.yaml");
  o.predictions = dir.file("pred");
  size_t calls = 0;
  const DetectionMetrics m = run_val(o, [&](size_t done, size_t total) {
    ++calls;
    EXPECT_EQ(total, 3u);
    EXPECT_EQ(done, calls);
  });
  EXPECT_EQ(calls, 3u);
  EXPECT_EQ(m.images, 3);
  EXPECT_EQ(m.truths, 3);  // the class-1 box is not evaluated
  EXPECT_EQ(m.iou.all.true_positives, 2);
  EXPECT_EQ(m.iou.all.false_positives, 3);
  EXPECT_NEAR(m.iou.all.ap, 2.0 / 3.0, 1e-9);
  EXPECT_NEAR(m.iou.all.mean_iou, (360.0 / 440.0 + 1520.0 / 1680.0) / 2, 1e-4);
  EXPECT_EQ(m.centre.all.true_positives, 3);
  EXPECT_NEAR(m.centre.all.ap, 1.0, 1e-9);
  // The one truth not found under IoU (T2: P2's box is three times too wide) is named by its image's path.
  ASSERT_EQ(m.iou.unmatched.size(), 1u);
  EXPECT_EQ(fs::path(m.iou.unmatched[0].image_name).lexically_normal(), fs::path(dir.file("images/val/a.png")));
  EXPECT_EQ(m.iou.unmatched[0].reason, "loose");
  EXPECT_EQ(m.iou.edge_truths, 0);  // no truth reaches the 400 x 400 images' edges
  EXPECT_TRUE(m.centre.unmatched.empty());
}

TEST(Val, PredictionsOfOtherClassesAreReadAndSkipped) {
  // A multi-class model's distractor line (class 3, a helicopter) in a dataset that names fewer classes: skipped, the
  // metrics are those of the hand case.
  testing::TempDir dir;
  write_hand_case(dir);
  std::ofstream(dir.file("pred/a.txt"), std::ios::app) << "3 0.5 0.5 0.2 0.2 0.95\n";
  ValOptions o;
  o.data = dir.file("data.yaml");
  o.predictions = dir.file("pred");
  const DetectionMetrics m = run_val(o);
  EXPECT_EQ(m.iou.all.true_positives, 2);
  EXPECT_EQ(m.iou.all.false_positives, 3);
  EXPECT_NEAR(m.iou.all.ap, 2.0 / 3.0, 1e-9);
}

TEST(Val, MissingPredictionFileIsNamed) {
  testing::TempDir dir;
  write_hand_case(dir);
  fs::remove(dir.file("pred/b.txt"));
  ValOptions o;
  o.data = dir.file("data.yaml");
  o.predictions = dir.file("pred");
  try {
    run_val(o);
    FAIL() << "no exception";
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("pred/b.txt: no prediction file"), std::string::npos) << e.what();
  }
}

TEST(Val, RunsTheDetectorOnEveryImage) {
  testing::TempDir dir;
  write_hand_case(dir);
  // A small [region] network with seeded random weights: the numbers are meaningless, the path is not.
  const std::string cfg =
      "[net]\nwidth=64\nheight=64\nchannels=3\n[convolutional]\nbatch_normalize=1\nfilters=8\nsize=3\nstride=1\npad=1\n"
      "activation=leaky\n[maxpool]\nsize=2\nstride=2\n[convolutional]\nbatch_normalize=1\nfilters=16\nsize=3\n"
      "stride=1\npad=1\nactivation=leaky\n[maxpool]\nsize=2\nstride=2\n[convolutional]\nsize=1\nstride=1\npad=1\n"
      "filters=12\nactivation=linear\n[region]\nanchors=1,1,3,3\nclasses=1\ncoords=4\nnum=2\nsoftmax=1\n";
  std::ofstream(dir.file("net.cfg")) << cfg;
  detector::DarknetModel m = detector::parse_darknet_cfg(dir.file("net.cfg"));
  detector::randomize_weights(m, 5);
  detector::save_darknet_weights(m, dir.file("net.weights"));
  ValOptions o;
  o.data = dir.file("data.yaml");
  o.cfg = dir.file("net.cfg");
  o.weights = dir.file("net.weights");
  std::string log;
  const DetectionMetrics r = run_val(o, {}, [&](const std::string& s) { log += s; });
  EXPECT_EQ(r.images, 3);
  EXPECT_EQ(r.truths, 3);
  EXPECT_GT(r.predictions, 0);
  EXPECT_NE(log.find("cpu"), std::string::npos) << log;
}

}  // namespace
}  // namespace wingman::training
