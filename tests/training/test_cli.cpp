// SPDX-License-Identifier: MIT
// The `wingman` verbs train, val and import-halmstad as processes: exit codes, output, errors on stderr.
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>
#include <wingman/training/train_options.hpp>

#include "hand_case.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace wingman::training {
namespace {

namespace fs = std::filesystem;

testing::RunResult wingman(const std::vector<std::string>& args, int timeout_s = 60) {
  std::vector<std::string> argv = {testing::bin_path("wingman")};
  argv.insert(argv.end(), args.begin(), args.end());
  return testing::run(argv, std::chrono::seconds(timeout_s));
}

TEST(WingmanVal, JsonOfSavedPredictionsHasTheHandComputedAp) {
  testing::TempDir dir;
  write_hand_case(dir);
  const auto r = wingman({"val", "--data", dir.file("data.yaml"), "--predictions", dir.file("pred"), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("images"), 3) << r.out;
  EXPECT_EQ(j.at("iou").at("criterion"), "iou") << r.out;
  EXPECT_EQ(j["iou"].at("all").at("truths"), 3) << r.out;
  EXPECT_EQ(j["iou"]["all"].at("detections"), 5) << r.out;
  EXPECT_EQ(j["iou"]["all"].at("true_positives"), 2) << r.out;
  EXPECT_NEAR(j["iou"]["all"].at("ap").get<double>(), 2.0 / 3.0, 1e-12) << r.out;
  // --json - is the same as --json alone (as for wingman eval).
  const auto dash = wingman({"val", "--data", dir.file("data.yaml"), "--predictions", dir.file("pred"), "--json", "-"});
  ASSERT_EQ(dash.exit_code, 0) << dash.err;
  EXPECT_EQ(dash.out, r.out);
  const auto table =
      wingman({"val", "--data", dir.file("data.yaml"), "--predictions", dir.file("pred"), "--conf", "0.05"});
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_NE(table.out.find("match centre in truth box"), std::string::npos) << table.out;
  EXPECT_NE(table.out.find("not found at confidence >= 0.05: 1 of 3 truths (0 missed: no detection overlaps them; 1 "
                           "loose: overlapped, not matched)\n"),
            std::string::npos)
      << table.out;
  EXPECT_NE(table.out.find("a.png truth 10x10 at (150, 50): loose, best 30x30 at (150, 52) IoU 0.11 confidence 0.60\n"),
            std::string::npos)
      << table.out;
  bool loose = false;
  for (const nlohmann::json& u : j["iou"].at("unmatched")) loose |= u.at("reason") == "loose";
  EXPECT_TRUE(loose) << r.out;
  const auto unlisted = wingman(
      {"val", "--data", dir.file("data.yaml"), "--predictions", dir.file("pred"), "--list", "0", "--edge-margin", "2"});
  ASSERT_EQ(unlisted.exit_code, 0) << unlisted.err;
  EXPECT_EQ(unlisted.out.find("a.png truth"), std::string::npos) << unlisted.out;
  const auto bad_margin =
      wingman({"val", "--data", dir.file("data.yaml"), "--predictions", dir.file("pred"), "--edge-margin", "-3"});
  EXPECT_NE(bad_margin.exit_code, 0);
  EXPECT_NE(bad_margin.err.find("edge_margin_px = -3"), std::string::npos) << bad_margin.err;
}

// Issue 34: one default per flag: without --weights or --predictions `wingman val` runs the shipped model, as `wingman
// predict` does, on the backend auto chooses (as predict and the detector process).
TEST(WingmanVal, WithoutWeightsOrPredictionsRunsTheShippedModel) {
  testing::TempDir dir;
  write_hand_case(dir);
  const auto r = wingman({"val", "--data", dir.file("data.yaml"), "--json", "-"}, 180);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"images\": 3"), std::string::npos) << r.out;
  const auto help = wingman({"val", "--help"});
  EXPECT_NE(help.out.find("--backend TEXT=auto "), std::string::npos) << help.out;
}

// Issue 32: the help shows the defaults of the options struct the options are bound to, not hand-typed ones.
TEST(WingmanTrain, HelpShowsTheTrainOptionsDefaults) {
  const TrainOptions d;
  const auto help = wingman({"train", "--help"});
  ASSERT_EQ(help.exit_code, 0) << help.err;
  for (const std::string& shown :
       {"--checkpoint-interval INT=" + std::to_string(d.checkpoint_interval),
        "--weights-interval INT=" + std::to_string(d.weights_interval), "--out TEXT=" + d.out_dir,
        "--batch INT=" + std::to_string(d.batch), "--max-batches INT=" + std::to_string(d.max_batches)})
    EXPECT_TRUE(help.out.find(shown + " ") != std::string::npos || help.out.find(shown + "\n") != std::string::npos)
        << shown << "\n"
        << help.out;
  EXPECT_EQ(help.out.find("(default"), std::string::npos) << help.out;
}

TEST(WingmanVal, BadOptionsAndFilesAreNamed) {
  testing::TempDir dir;
  write_hand_case(dir);
  // Both a model and saved predictions: one of them, named.
  const auto both = wingman({"val", "--data", dir.file("data.yaml"), "--weights", "builtin:wingman-small",
                             "--predictions", dir.file("pred")});
  EXPECT_EQ(both.exit_code, 2);
  EXPECT_NE(both.err.find("give exactly one"), std::string::npos) << both.err;
  // One "wingman val:" prefix: the library names itself (run_val), the verb adds its own.
  EXPECT_EQ(both.err.rfind("wingman val: error: run_val: invalid options:", 0), 0u) << both.err;
  EXPECT_EQ(both.err.find("wingman val:", 1), std::string::npos) << both.err;
  std::ofstream(dir.file("labels/val/b.txt")) << "0 0.5 0.5 0.1 7\n";
  const auto bad = wingman({"val", "--data", dir.file("data.yaml"), "--predictions", dir.file("pred")});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("labels/val/b.txt:1: field h = 7"), std::string::npos) << bad.err;
}

TEST(WingmanModel, WidenClassesWritesAFourClassModelOfTheShippedOne) {
  testing::TempDir dir;
  const auto r = wingman({"model", "widen-classes", "--iou-loss", "ciou", "--iou-normalizer", "3", "--out-cfg",
                          dir.file("wide/wide.cfg"), "--out-weights", dir.file("wide/wide.weights")});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("3 heads at 4 classes"), std::string::npos) << r.out;
  detector::DarknetModel wide = detector::parse_darknet_cfg(dir.file("wide/wide.cfg"));
  detector::load_darknet_weights(wide, dir.file("wide/wide.weights"));  // the right length for the cfg
  for (const int h : wide.heads()) {
    EXPECT_EQ(wide.layers[static_cast<size_t>(h)].classes, 4);
    EXPECT_EQ(wide.layers[static_cast<size_t>(h)].iou_loss, "ciou");
    EXPECT_FLOAT_EQ(wide.layers[static_cast<size_t>(h)].iou_normalizer, 3.0f);
    EXPECT_EQ(wide.layers[static_cast<size_t>(h - 1)].filters, 27);
  }
  // Bad input: one line naming what is wrong, exit 2 for a bad option, 1 for an unreadable file.
  const auto bad_loss = wingman({"model", "widen-classes", "--iou-loss", "l1", "--out-cfg", dir.file("a.cfg"),
                                 "--out-weights", dir.file("a.weights")});
  EXPECT_EQ(bad_loss.exit_code, 2);
  EXPECT_NE(bad_loss.err.find("wingman model widen-classes: error: --iou-loss 'l1'"), std::string::npos)
      << bad_loss.err;
  const auto missing = wingman({"model", "widen-classes", "--weights", dir.file("absent.weights"), "--out-cfg",
                                dir.file("b.cfg"), "--out-weights", dir.file("b.weights")});
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.err.find("absent.weights"), std::string::npos) << missing.err;
  const auto fewer = wingman({"model", "widen-classes", "--classes", "0", "--out-cfg", dir.file("c.cfg"),
                              "--out-weights", dir.file("c.weights")});
  EXPECT_EQ(fewer.exit_code, 2);
  EXPECT_NE(fewer.err.find("classes = 0"), std::string::npos) << fewer.err;
}

TEST(WingmanImportHalmstad, MissingDatasetIsNamed) {
  testing::TempDir dir;
  const auto r = wingman({"import-halmstad", dir.path(), dir.file("out")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("clips.csv: cannot read the clip list"), std::string::npos) << r.err;
  const auto bad = wingman({"import-halmstad", dir.path(), dir.file("out"), "--frame-step", "0"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("frame_step = 0"), std::string::npos) << bad.err;
}

/// A tiny [region] network and 8 synthetic images for `wingman train`.
void write_tiny_training_set(const testing::TempDir& dir) {
  std::ofstream(dir.file("tiny.cfg"))
      << "[net]\nwidth=32\nheight=32\nchannels=3\nbatch=8\nsubdivisions=1\nlearning_rate=0.01\nburn_in=2\n"
         "max_batches=100\npolicy=constant\n[convolutional]\nbatch_normalize=1\nfilters=8\nsize=3\nstride=1\npad=1\n"
         "activation=leaky\n[maxpool]\nsize=2\nstride=2\n[convolutional]\nbatch_normalize=1\nfilters=8\nsize=3\n"
         "stride=1\npad=1\nactivation=leaky\n[maxpool]\nsize=2\nstride=2\n[convolutional]\nsize=1\nstride=1\npad=1\n"
         "filters=6\nactivation=linear\n[region]\nanchors=1,1\nclasses=1\ncoords=4\nnum=1\nsoftmax=1\nobject_scale=5\n"
         "rescore=1\n";
  for (int i = 0; i < 8; ++i)
    for (const char* split : {"train", "val"}) {
      cv::Mat img(40, 48, CV_8UC3, cv::Scalar(200, 180, 150));
      cv::circle(img, {8 + 4 * i, 20}, 4, cv::Scalar(20, 20, 20), cv::FILLED);
      const fs::path p = fs::path(dir.file("data/images")) / split / (std::to_string(i) + ".png");
      fs::create_directories(p.parent_path());
      ASSERT_TRUE(cv::imwrite(p.string(), img));
      fs::create_directories(dir.file(std::string("data/labels/") + split));
      std::ofstream(dir.file(std::string("data/labels/") + split + "/" + std::to_string(i) + ".txt"))
          << "0 " << (8.5 + 4 * i) / 48.0 << " " << 20.5 / 40.0 << " " << 9.0 / 48.0 << " " << 9.0 / 40.0 << "\n";
    }
}

#if WINGMAN_TEST_HAVE_TRAINER
TEST(WingmanTrain, TrainsWithOverridesThenResumes) {
  testing::TempDir dir;
  write_tiny_training_set(dir);
  const std::vector<std::string> base = {
      "train",   "--cfg", dir.file("tiny.cfg"), "--data", dir.file("data"), "--out", dir.file("out"),
      "--batch", "4",     "--subdivisions",     "2",      "--threads",      "1"};
  auto args = base;
  args.insert(args.end(), {"--max-batches", "3"});
  const auto r = wingman(args, 120);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("8 training images, batch 4 in 2 subdivisions, 3 iterations from 0"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("iter 3/3"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("done at iteration 3/3"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("match IoU >= 0.5"), std::string::npos) << r.out;  // validated on val at the end
  ASSERT_TRUE(fs::is_regular_file(dir.file("out/tiny_final.weights")));
  detector::DarknetModel m = detector::parse_darknet_cfg(dir.file("tiny.cfg"));
  detector::load_darknet_weights(m, dir.file("out/tiny_final.weights"));
  EXPECT_EQ(m.seen, 12u);  // 3 iterations x 4 images (the --batch override)

  args = base;
  args.insert(args.end(), {"--max-batches", "5", "--resume"});
  const auto resumed = wingman(args, 120);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("5 iterations from 3"), std::string::npos) << resumed.err;
  std::ifstream csv(dir.file("out/progress.csv"));
  int lines = 0;
  for (std::string l; std::getline(csv, l);) ++lines;
  EXPECT_EQ(lines, 1 + 5);  // header + iterations 1..5 over both runs

  args = base;
  args.insert(args.end(), {"--seed", "9", "--resume"});
  const auto refused = wingman(args);
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_NE(refused.err.find("made with seed 1"), std::string::npos) << refused.err;
}

TEST(WingmanTrain, UnreadableCfgIsNamedOnOneLine) {
  testing::TempDir dir;
  write_tiny_training_set(dir);
  std::ofstream(dir.file("bad.cfg")) << "[net]\nwidth=64\nheight=64\nchannels=3\n\n[convolutional]\nfilters=x\n";
  const auto r = wingman({"train", "--cfg", dir.file("bad.cfg"), "--data", dir.file("data"), "--out", dir.file("out")});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(r.err.rfind("wingman train: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("bad.cfg"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("filters"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir.file("out/progress.csv")));
  const auto missing =
      wingman({"train", "--cfg", dir.file("none.cfg"), "--data", dir.file("data"), "--out", dir.file("out")});
  EXPECT_EQ(missing.exit_code, 1) << missing.err;
  EXPECT_NE(missing.err.find("none.cfg"), std::string::npos) << missing.err;
}

TEST(WingmanTrain, GrowsANetworkOnPartialWeights) {
  testing::TempDir dir;
  write_tiny_training_set(dir);
  const std::vector<std::string> common = {
      "--data", dir.file("data"), "--batch", "4", "--subdivisions", "2", "--threads", "1", "--max-batches", "2"};
  auto args = std::vector<std::string>{"train", "--cfg", dir.file("tiny.cfg"), "--out", dir.file("out")};
  args.insert(args.end(), common.begin(), common.end());
  const auto first = wingman(args, 120);
  ASSERT_EQ(first.exit_code, 0) << first.err;
  // tiny.cfg's three convolutions, then a new 1x1 one before its [region] head.
  std::ifstream in(dir.file("tiny.cfg"));
  std::string cfg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string head = "[region]";
  ASSERT_NE(cfg.find(head), std::string::npos);
  cfg.insert(cfg.find(head), "[convolutional]\nsize=1\nstride=1\npad=1\nfilters=6\nactivation=linear\n");
  std::ofstream(dir.file("grown.cfg")) << cfg;

  args = {"train",
          "--cfg",
          dir.file("grown.cfg"),
          "--out",
          dir.file("grown"),
          "--weights",
          dir.file("out/tiny_final.weights")};
  args.insert(args.end(), common.begin(), common.end());
  const auto whole = wingman(args, 120);  // without --partial-weights the file is too short for grown.cfg
  EXPECT_EQ(whole.exit_code, 1) << whole.err;
  EXPECT_NE(whole.err.find("tiny_final.weights"), std::string::npos) << whole.err;

  args.push_back("--partial-weights");
  const auto grown = wingman(args, 120);
  ASSERT_EQ(grown.exit_code, 0) << grown.err;
  EXPECT_NE(grown.err.find("the first 3 convolutional layers from " + dir.file("out/tiny_final.weights") +
                           "; the others start random"),
            std::string::npos)
      << grown.err;
  detector::DarknetModel m = detector::parse_darknet_cfg(dir.file("grown.cfg"));
  detector::load_darknet_weights(m, dir.file("grown/grown_final.weights"));
  EXPECT_EQ(m.seen, 8u);  // 2 iterations x 4 images: the count restarts for the grown network

  args = {"train", "--cfg", dir.file("tiny.cfg"), "--data", dir.file("data"), "--partial-weights"};
  const auto alone = wingman(args);  // --partial-weights needs --weights
  EXPECT_EQ(alone.exit_code, 2) << alone.err;
  EXPECT_NE(alone.err.find("init_partial"), std::string::npos) << alone.err;
}

TEST(WingmanTrain, EmaDecayExportsTheAverageAndKeepsTheTrainedWeights) {
  testing::TempDir dir;
  write_tiny_training_set(dir);
  auto args = std::vector<std::string>{"train",
                                       "--cfg",
                                       dir.file("tiny.cfg"),
                                       "--data",
                                       dir.file("data"),
                                       "--out",
                                       dir.file("out"),
                                       "--batch",
                                       "4",
                                       "--subdivisions",
                                       "2",
                                       "--threads",
                                       "1",
                                       "--max-batches",
                                       "3",
                                       "--val-split",
                                       "",
                                       "--ema-decay",
                                       "0.9",
                                       "--ema-ramp",
                                       "1"};
  const auto r = wingman(args, 120);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("trained weights (not averaged): " + dir.file("out/tiny_raw_final.weights")), std::string::npos)
      << r.out;
  std::ifstream a(dir.file("out/tiny_final.weights"), std::ios::binary),
      b(dir.file("out/tiny_raw_final.weights"), std::ios::binary);
  const std::string averaged{std::istreambuf_iterator<char>(a), {}}, trained{std::istreambuf_iterator<char>(b), {}};
  EXPECT_EQ(averaged.size(), trained.size());
  EXPECT_NE(averaged, trained);
  args.back() = "0";  // --ema-ramp 0
  const auto bad = wingman(args);
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("ema_ramp = 0: must be > 0"), std::string::npos) << bad.err;
}

#else
TEST(WingmanTrain, SaysHowToGetTheTrainer) {
  testing::TempDir dir;
  write_tiny_training_set(dir);
  const auto r = wingman({"train", "--cfg", dir.file("tiny.cfg"), "--data", dir.file("data")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("WINGMAN_WITH_TRAINING"), std::string::npos) << r.err;
}
#endif

}  // namespace
}  // namespace wingman::training
