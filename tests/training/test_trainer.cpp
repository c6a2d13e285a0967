// SPDX-License-Identifier: MIT
// The trainer on a tiny synthetic set: the loss falls, the export loads in the detector and runs there as in
// libtorch, a stopped and resumed run equals an uninterrupted one, and bad resumes are refused with a reason.
#include <wingman/detector/cpu_backend.hpp>
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>
#include <wingman/detector/detection_pipeline.hpp>
#include <wingman/detector/model_loader.hpp>
#include <wingman/training/darknet_torch.hpp>
#include <wingman/training/trainer.hpp>
#include <wingman/training/yolo_dataset.hpp>

#include "test_support.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <torch/torch.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

namespace wingman::training {
namespace {

namespace fs = std::filesystem;

/// `n` 96 x 80 sky images, each with one dark drone-like blob of 10-24 px (seeded), in a YOLO folder layout.
void write_synthetic_set(const std::string& root, const std::string& split, int n, uint32_t seed) {
  std::mt19937 rng(seed);
  for (int i = 0; i < n; ++i) {
    cv::Mat img(80, 96, CV_8UC3);
    for (int y = 0; y < img.rows; ++y) img.row(y).setTo(cv::Scalar(200 - y / 2, 170 - y / 3, 140 - y / 4));
    const int w = 10 + static_cast<int>(rng() % 15), h = 6 + static_cast<int>(rng() % 10);
    const int x = static_cast<int>(rng() % static_cast<uint32_t>(img.cols - w));
    const int y = static_cast<int>(rng() % static_cast<uint32_t>(img.rows - h));
    cv::ellipse(img, cv::Point(x + w / 2, y + h / 2), cv::Size(w / 2, h / 2), 0, 0, 360, cv::Scalar(30, 35, 40),
                cv::FILLED);
    const std::string stem = fmt::format("{}_{:03d}", split, i);
    fs::create_directories(fs::path(root) / "images" / split);
    ASSERT_TRUE(cv::imwrite((fs::path(root) / "images" / split / (stem + ".png")).string(), img));
    write_yolo_labels((fs::path(root) / "labels" / split / (stem + ".txt")).string(),
                      {{0, (x + w / 2.0f) / img.cols, (y + h / 2.0f) / img.rows, static_cast<float>(w) / img.cols,
                        static_cast<float>(h) / img.rows}});
  }
}

/// A small [region] network for 64 x 64 input: a 4 x 4 grid, two anchors.
constexpr const char* kRegionCfg = R"([net]
width=64
height=64
channels=3
batch=8
subdivisions=2
learning_rate=0.01
momentum=0.9
decay=0.0005
burn_in=10
max_batches=120
policy=steps
steps=100
scales=.1
hue=.05
saturation=1.2
exposure=1.2
[convolutional]
batch_normalize=1
filters=8
size=3
stride=1
pad=1
activation=leaky
[maxpool]
size=2
stride=2
[convolutional]
batch_normalize=1
filters=16
size=3
stride=1
pad=1
activation=leaky
[maxpool]
size=2
stride=2
[convolutional]
batch_normalize=1
filters=32
size=3
stride=1
pad=1
activation=leaky
[maxpool]
size=2
stride=2
[convolutional]
batch_normalize=1
filters=32
size=3
stride=1
pad=1
activation=leaky
[maxpool]
size=2
stride=2
[convolutional]
size=1
stride=1
pad=1
filters=12
activation=linear
[region]
anchors=0.8,0.6, 1.4,0.9
classes=1
coords=4
num=2
softmax=1
jitter=.1
rescore=1
object_scale=5
noobject_scale=1
class_scale=1
coord_scale=1
thresh=.6
)";

/// The same idea with two [yolo] heads (4 x 4 and 8 x 8).
constexpr const char* kYoloCfg = R"([net]
width=64
height=64
channels=3
batch=8
subdivisions=1
learning_rate=0.005
momentum=0.9
decay=0.0005
burn_in=10
max_batches=50
policy=constant
[convolutional]
batch_normalize=1
filters=8
size=3
stride=1
pad=1
activation=leaky
[maxpool]
size=2
stride=2
[convolutional]
batch_normalize=1
filters=16
size=3
stride=1
pad=1
activation=leaky
[maxpool]
size=2
stride=2
[convolutional]
batch_normalize=1
filters=32
size=3
stride=1
pad=1
activation=leaky
[maxpool]
size=2
stride=2
[convolutional]
batch_normalize=1
filters=32
size=3
stride=1
pad=1
activation=leaky
[maxpool]
size=2
stride=2
[convolutional]
size=1
stride=1
pad=1
filters=12
activation=linear
[yolo]
mask=2,3
anchors=6,4, 10,7, 14,9, 20,12
classes=1
num=4
jitter=.1
ignore_thresh=.7
[route]
layers=-3
[upsample]
stride=2
[route]
layers=-1,6
[convolutional]
size=1
stride=1
pad=1
filters=12
activation=linear
[yolo]
mask=0,1
anchors=6,4, 10,7, 14,9, 20,12
classes=1
num=4
jitter=.1
ignore_thresh=.7
)";

TrainOptions options_for(const testing::TempDir& dir, const char* cfg_text, const std::string& out) {
  const std::string cfg = dir.file("tiny.cfg");
  std::ofstream(cfg) << cfg_text;
  TrainOptions o = train_options_from_model(detector::parse_darknet_cfg(cfg), cfg);
  o.data = dir.file("data");
  o.out_dir = dir.file(out);
  o.threads = 2;
  o.seed = 5;
  o.checkpoint_interval = 1000;
  o.weights_interval = 0;
  return o;
}

std::vector<char> file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The exported weights run in the detector (OpenCV DNN) as in libtorch (eval mode), within 1e-3 relative.
void expect_detector_runs_export(const std::string& cfg, const std::string& weights) {
  const detector::DarknetModel m = detector::load_model(cfg, weights);
  DarknetNet net(m);
  net->load_weights(m);
  net->eval();
  cv::Mat img = cv::imread(cfg.substr(0, cfg.rfind('/')) + "/data/images/train/train_000.png", cv::IMREAD_COLOR);
  ASSERT_FALSE(img.empty());
  cv::resize(img, img, cv::Size(m.net.width, m.net.height));
  std::vector<float> input(3 * static_cast<size_t>(m.net.width * m.net.height));
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x)
      for (int c = 0; c < 3; ++c)
        input[(static_cast<size_t>(c) * img.rows + y) * img.cols + x] = img.at<cv::Vec3b>(y, x)[2 - c] / 255.0f;
  torch::NoGradGuard no_grad;
  const auto outs = net->forward(torch::from_blob(input.data(), {1, 3, m.net.height, m.net.width}));
  detector::CpuBackend cpu(m, 1);
  std::vector<float> ref;
  cpu.forward(input.data(), 1, ref);
  size_t offset = 0;
  for (const torch::Tensor& o : outs) {
    const torch::Tensor t = o.contiguous();
    double max_ref = 0, max_diff = 0;
    for (int64_t i = 0; i < t.numel(); ++i) {
      max_ref = std::max(max_ref, static_cast<double>(std::fabs(ref[offset + i])));
      max_diff = std::max(max_diff, static_cast<double>(std::fabs(t.data_ptr<float>()[i] - ref[offset + i])));
    }
    EXPECT_LE(max_diff, 1e-3 * std::max(1.0, max_ref)) << weights;
    offset += static_cast<size_t>(t.numel());
  }
  EXPECT_EQ(offset, ref.size());
  // And the whole detector pipeline accepts the network.
  detector::DetectionPipeline pipeline(detector::DetectorPipelineOptions{},
                                       std::make_unique<detector::CpuBackend>(m, 1), m);
  pipeline.detect(cv::imread(cfg.substr(0, cfg.rfind('/')) + "/data/images/train/train_001.png", cv::IMREAD_COLOR));
}

class TrainerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    write_synthetic_set(dir_.file("data"), "train", 16, 1);
    write_synthetic_set(dir_.file("data"), "val", 8, 2);
  }
  testing::TempDir dir_;
};

TEST_F(TrainerTest, RegionNetworkLossFallsAndTheExportRunsInTheDetector) {
  Trainer trainer(options_for(dir_, kRegionCfg, "out"));
  EXPECT_EQ(trainer.train_images(), 16u);
  std::vector<double> losses;
  std::vector<double> rates;
  const TrainSummary s = trainer.run([&](const TrainProgress& p) {
    losses.push_back(p.loss);
    rates.push_back(p.learning_rate);
    EXPECT_LE(p.truths, 8);  // one box per image; the crop jitter (0.1) may cut one away now and then
    EXPECT_GE(p.truths, 6);
    EXPECT_NE(p.one_line().find(fmt::format("iter {}/120", p.iteration)), std::string::npos);
  });
  ASSERT_EQ(losses.size(), 120u);
  EXPECT_FALSE(s.interrupted);
  EXPECT_EQ(s.iteration, 120);
  // Warm-up to 0.01, then 0.001 from iteration 100.
  EXPECT_LT(rates[0], 1e-5);
  EXPECT_DOUBLE_EQ(rates[30], 0.01);
  EXPECT_DOUBLE_EQ(rates[110], 0.001);
  double first = 0, last = 0;
  for (int i = 0; i < 5; ++i) first += losses[i] / 5, last += losses[115 + i] / 5;
  EXPECT_LT(last, 0.6 * first) << "first " << first << ", last " << last;  // measured: 0.37 -> 0.12
  EXPECT_TRUE(fs::is_regular_file(dir_.file("out/tiny_final.weights")));
  EXPECT_TRUE(fs::is_regular_file(dir_.file("out/tiny_last.weights")));
  EXPECT_TRUE(fs::is_regular_file(dir_.file("out/checkpoint.pt")));
  EXPECT_TRUE(fs::is_regular_file(dir_.file("out/tiny.cfg")));
  // It has learnt to find the blobs, on the 8 unseen val images and on its 16 training images (measured: AP 1.0
  // with the centre criterion on both; 0.875 and 0.55 at IoU >= 0.5, strict for 7-16 px blobs after 120 steps).
  ASSERT_TRUE(s.validation.has_value());
  EXPECT_EQ(s.validation->images, 8);
  EXPECT_EQ(s.validation->truths, 8);
  EXPECT_GT(s.validation->centre.all.ap, 0.7) << s.validation->report();
  EXPECT_GT(s.validation->iou.all.ap, 0.4) << s.validation->report();
  const DetectionMetrics fit = trainer.validate("train");
  EXPECT_GT(fit.centre.all.ap, 0.8) << fit.report();
  expect_detector_runs_export(dir_.file("tiny.cfg"), s.weights);
  // The .weights header counts the images seen.
  detector::DarknetModel m = detector::parse_darknet_cfg(dir_.file("tiny.cfg"));
  detector::load_darknet_weights(m, s.weights);
  EXPECT_EQ(m.seen, 120u * 8u);
}

TEST_F(TrainerTest, YoloNetworkLossFallsAndTheExportRunsInTheDetector) {
  Trainer trainer(options_for(dir_, kYoloCfg, "out"));
  std::vector<double> losses;
  const TrainSummary s = trainer.run([&](const TrainProgress& p) { losses.push_back(p.loss); });
  ASSERT_EQ(losses.size(), 50u);
  const double first = (losses[0] + losses[1] + losses[2]) / 3, last = (losses[47] + losses[48] + losses[49]) / 3;
  EXPECT_LT(last, 0.5 * first) << "first " << first << ", last " << last;
  expect_detector_runs_export(dir_.file("tiny.cfg"), s.weights);
}

/// kYoloCfg grown by a third head (a 3x3 convolution and a 1x1 output on the second head's input, one new anchor):
/// its first convolutional layers are kYoloCfg's, so kYoloCfg's .weights are its partial weights.
std::string grown_yolo_cfg() {
  std::string cfg = kYoloCfg;
  for (size_t at = 0; (at = cfg.find("anchors=6,4, 10,7, 14,9, 20,12", at)) != std::string::npos;)
    cfg.replace(at, 30, "anchors=6,4, 10,7, 14,9, 20,12, 30,20"), at += 30;
  for (size_t at = 0; (at = cfg.find("num=4", at)) != std::string::npos;) cfg.replace(at, 5, "num=5");
  return cfg +
         "[route]\nlayers=-2\n"
         "[convolutional]\nbatch_normalize=1\nfilters=8\nsize=3\nstride=1\npad=1\nactivation=leaky\n"
         "[convolutional]\nsize=1\nstride=1\npad=1\nfilters=6\nactivation=linear\n"
         "[yolo]\nmask=4\nanchors=6,4, 10,7, 14,9, 20,12, 30,20\nclasses=1\nnum=5\njitter=.1\nignore_thresh=.7\n";
}

TEST_F(TrainerTest, PartialWeightsLoadTheTrainedLayersAndTheGrownNetworkTrains) {
  TrainOptions base = options_for(dir_, kYoloCfg, "base");
  base.max_batches = 2;
  base.val_split = "";
  const std::string base_weights = Trainer(base).run().weights;
  const detector::DarknetModel trained = [&] {
    detector::DarknetModel m = detector::parse_darknet_cfg_string(kYoloCfg, "base.cfg");
    detector::load_darknet_weights(m, base_weights);
    return m;
  }();
  int base_convs = 0;
  for (const auto& l : trained.layers) base_convs += l.type == detector::LayerType::kConvolutional;

  const std::string grown = grown_yolo_cfg();
  TrainOptions o = options_for(dir_, grown.c_str(), "grown");
  o.max_batches = 20;
  o.val_split = "";
  o.init_weights = base_weights;
  // Without init_partial the file is the wrong length for the grown network.
  EXPECT_THROW(Trainer{o}, detector::DarknetFormatError);
  o.init_partial = true;
  Trainer t(o);
  EXPECT_EQ(t.init_layers(), base_convs);
  t.save_weights(dir_.file("grown0.weights"));
  detector::DarknetModel start = detector::parse_darknet_cfg(dir_.file("tiny.cfg"));
  detector::load_darknet_weights(start, dir_.file("grown0.weights"));
  int conv = 0;
  for (size_t i = 0; i < start.layers.size(); ++i) {
    if (start.layers[i].type != detector::LayerType::kConvolutional) continue;
    if (conv++ < base_convs) {
      EXPECT_EQ(start.layers[i].weights, trained.layers[i].weights) << "layer " << i;
      EXPECT_EQ(start.layers[i].biases, trained.layers[i].biases) << "layer " << i;
    } else {
      float sum = 0;
      for (float w : start.layers[i].weights) sum += std::fabs(w);
      EXPECT_GT(sum, 0.0f) << "appended layer " << i << " starts random, not zero";
    }
  }
  EXPECT_EQ(conv, base_convs + 2);
  const TrainSummary s = t.run();
  expect_detector_runs_export(dir_.file("tiny.cfg"), s.weights);  // three heads, in OpenCV DNN as in libtorch

  o.init_weights = "";
  try {
    Trainer bad(o);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("init_partial"), std::string::npos) << e.what();
  }
}

TEST_F(TrainerTest, StoppedAndResumedRunEqualsAnUninterruptedOne) {
  TrainOptions o = options_for(dir_, kRegionCfg, "one_go");
  o.max_batches = 8;
  o.augment.mosaic = 0.5;  // exercise every seeded path
  o.augment.blur = 0.3;
  o.augment.noise = 0.3;
  o.val_split = "";
  Trainer one_go(o);
  const TrainSummary a = one_go.run();
  EXPECT_EQ(a.iteration, 8);

  o.out_dir = dir_.file("halves");
  std::atomic<bool> stop{false};
  {
    Trainer first_half(o);
    const TrainSummary b = first_half.run(
        [&](const TrainProgress& p) {
          if (p.iteration == 4) stop = true;
        },
        &stop);
    EXPECT_TRUE(b.interrupted);
    EXPECT_EQ(b.iteration, 4);
  }
  o.resume = true;
  Trainer second_half(o);
  EXPECT_EQ(second_half.iteration(), 4);
  const TrainSummary c = second_half.run();
  EXPECT_EQ(c.start_iteration, 4);
  EXPECT_EQ(c.iteration, 8);
  // Same seeded data order, augmentation, momentum and batch-norm statistics: the same weights. libtorch's CPU
  // kernels are deterministic for a fixed thread count, so the files are expected to be bit-identical; the check
  // allows float rounding (1e-5 relative) in case a kernel's reduction order differs between runs.
  const std::vector<char> wa = file_bytes(dir_.file("one_go/tiny_final.weights"));
  const std::vector<char> wc = file_bytes(dir_.file("halves/tiny_final.weights"));
  ASSERT_EQ(wa.size(), wc.size());
  const size_t header = 20;
  size_t differing = 0;
  for (size_t i = header; i + 4 <= wa.size(); i += 4) {
    float x, y;
    std::memcpy(&x, &wa[i], 4);
    std::memcpy(&y, &wc[i], 4);
    if (x != y) ++differing;
    ASSERT_NEAR(x, y, 1e-5 * std::max(1.0f, std::fabs(x))) << "float " << (i - header) / 4;
  }
  RecordProperty("differing_floats", static_cast<int>(differing));
  EXPECT_NEAR(a.loss_avg, c.loss_avg, 1e-6 * std::max(1.0, a.loss_avg));
}

/// The floats of a .weights file after its 20-byte header.
std::vector<float> weight_floats(const std::string& path) {
  const std::vector<char> bytes = file_bytes(path);
  std::vector<float> v((bytes.size() - 20) / 4);
  std::memcpy(v.data(), bytes.data() + 20, v.size() * 4);
  return v;
}

TEST_F(TrainerTest, WeightAverageIsThePlainAverageOfEachIterationsWeightsAndResumesExactly) {
  // Reference run without the average: its weights before the first update and after each of the 6.
  TrainOptions o = options_for(dir_, kRegionCfg, "plain");
  o.max_batches = 6;
  o.val_split = "";
  o.weights_interval = 1;
  {
    Trainer plain(o);
    plain.save_weights(dir_.file("plain/tiny_0.weights"));
    plain.run();
  }
  // With the average: the training itself must not change (the raw weights equal the plain run's), and the
  // exported weights must be the average computed here in plain floats.
  o.out_dir = dir_.file("averaged");
  o.weights_interval = 4;
  o.ema.decay = 0.8;
  o.ema.ramp = 2;
  const TrainSummary s = Trainer(o).run();
  EXPECT_EQ(s.weights, dir_.file("averaged/tiny_final.weights"));
  EXPECT_EQ(s.raw_weights, dir_.file("averaged/tiny_raw_final.weights"));
  EXPECT_NE(s.report().find("tiny_raw_final.weights"), std::string::npos) << s.report();
  const std::vector<float> raw = weight_floats(s.raw_weights);
  const std::vector<float> plain_final = weight_floats(dir_.file("plain/tiny_final.weights"));
  ASSERT_EQ(raw.size(), plain_final.size());
  for (size_t i = 0; i < raw.size(); ++i)
    ASSERT_NEAR(raw[i], plain_final[i], 1e-5f * std::max(1.0f, std::fabs(plain_final[i]))) << "float " << i;
  std::vector<double> expected(raw.size());
  {
    const std::vector<float> w0 = weight_floats(dir_.file("plain/tiny_0.weights"));
    std::copy(w0.begin(), w0.end(), expected.begin());
  }
  for (int i = 1; i <= 6; ++i) {
    const std::vector<float> w = weight_floats(dir_.file(fmt::format("plain/tiny_{}.weights", i)));
    const double d = o.ema.decay_at(i);
    for (size_t k = 0; k < expected.size(); ++k) expected[k] = d * expected[k] + (1 - d) * w[k];
  }
  const std::vector<float> averaged = weight_floats(s.weights);
  size_t differs_from_raw = 0;
  for (size_t i = 0; i < averaged.size(); ++i) {
    ASSERT_NEAR(averaged[i], expected[i], 1e-5 * std::max(1.0, std::fabs(expected[i]))) << "float " << i;
    differs_from_raw += averaged[i] != raw[i];
  }
  EXPECT_GT(differs_from_raw, averaged.size() / 2);  // the average is not the last weights
  // At the weights interval both are kept: iteration 4's trained weights are the plain run's.
  const std::vector<float> raw4 = weight_floats(dir_.file("averaged/tiny_raw_4.weights"));
  const std::vector<float> plain4 = weight_floats(dir_.file("plain/tiny_4.weights"));
  ASSERT_EQ(raw4.size(), plain4.size());
  for (size_t i = 0; i < raw4.size(); ++i)
    ASSERT_NEAR(raw4[i], plain4[i], 1e-5f * std::max(1.0f, std::fabs(plain4[i]))) << "float " << i;
  EXPECT_NE(weight_floats(dir_.file("averaged/tiny_4.weights")), raw4);
  expect_detector_runs_export(dir_.file("tiny.cfg"), s.weights);

  // Stopped after 3 iterations and resumed: the same average.
  o.out_dir = dir_.file("halves");
  std::atomic<bool> stop{false};
  Trainer(o).run(
      [&](const TrainProgress& p) {
        if (p.iteration == 3) stop = true;
      },
      &stop);
  o.resume = true;
  const TrainSummary c = Trainer(o).run();
  EXPECT_EQ(c.start_iteration, 3);
  const std::vector<float> resumed = weight_floats(c.weights);
  ASSERT_EQ(resumed.size(), averaged.size());
  for (size_t i = 0; i < resumed.size(); ++i)
    ASSERT_NEAR(resumed[i], averaged[i], 1e-5f * std::max(1.0f, std::fabs(averaged[i]))) << "float " << i;

  // A checkpoint with an average is not resumed without it or with another one, nor one without it with it.
  auto refusal = [&](const TrainOptions& bad) -> std::string {
    try {
      Trainer t(bad);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "(no exception)";
  };
  TrainOptions other = o;
  other.ema.decay = 0;
  EXPECT_NE(refusal(other).find("made with a weight average"), std::string::npos) << refusal(other);
  other.ema.decay = 0.9;
  EXPECT_NE(refusal(other).find("made with --ema-decay 0.8 --ema-ramp 2"), std::string::npos) << refusal(other);
  other = o;
  other.out_dir = dir_.file("plain");
  EXPECT_NE(refusal(other).find("made without a weight average"), std::string::npos) << refusal(other);
}

TEST_F(TrainerTest, BadResumesAreRefusedWithAReason) {
  TrainOptions o = options_for(dir_, kRegionCfg, "out");
  o.resume = true;
  try {
    Trainer t(o);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no checkpoint to resume from"), std::string::npos) << e.what();
  }
  o.resume = false;
  o.max_batches = 1;
  o.val_split = "";
  Trainer(o).run();
  o.resume = true;
  o.seed = 6;
  try {
    Trainer t(o);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("made with seed 5"), std::string::npos) << e.what();
  }
}

TEST_F(TrainerTest, InvalidOptionsAndDataAreNamed) {
  TrainOptions o = options_for(dir_, kRegionCfg, "out");
  o.batch = 6;
  o.subdivisions = 4;
  try {
    Trainer t(o);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("subdivisions = 4"), std::string::npos) << e.what();
  }
  o = options_for(dir_, kRegionCfg, "out");
  std::ofstream(dir_.file("data/labels/train/train_003.txt")) << "0 0.5 0.5 0.1\n";
  try {
    Trainer t(o);
    FAIL() << "no exception";
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("train_003.txt:1: expected 5 fields"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace wingman::training
