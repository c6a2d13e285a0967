// SPDX-License-Identifier: MIT
// The libtorch network from a .cfg against the detector's CPU backend (OpenCV DNN) on the same random weights,
// Darknet's maxpool padding, and bit-identical weight round trips through the Darknet writer and reader.
#include <wingman/detector/cpu_backend.hpp>
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>
#include <wingman/training/darknet_torch.hpp>

#include "test_support.hpp"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

namespace wingman::training {
namespace {

using detector::DarknetModel;

std::vector<float> random_input(const DarknetModel& m, int batch, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<float> v(static_cast<size_t>(batch) * m.net.channels * m.net.height * m.net.width);
  for (float& x : v) x = static_cast<float>(rng() % 256) / 255.0f;
  return v;
}

/// Torch forward (eval mode) vs CpuBackend forward, every head, within 1e-3 relative as the detector's own
/// OpenCL-vs-OpenCV comparisons: max |a - b| <= 1e-3 * max(1, max |b|).
void expect_torch_matches_opencv(DarknetModel m, uint32_t seed, int batch) {
  detector::randomize_weights(m, seed);
  DarknetNet net(m);
  net->load_weights(m);
  net->eval();
  const std::vector<float> input = random_input(m, batch, seed + 1);
  torch::NoGradGuard no_grad;
  const torch::Tensor x = torch::from_blob(const_cast<float*>(input.data()),
                                           {batch, m.net.channels, m.net.height, m.net.width}, torch::kFloat32);
  const std::vector<torch::Tensor> outs = net->forward(x);

  detector::CpuBackend cpu(m, batch);
  std::vector<float> ref;
  cpu.forward(input.data(), batch, ref);
  const std::vector<detector::Shape> shapes = cpu.output_shapes();
  ASSERT_EQ(outs.size(), shapes.size()) << m.cfg_path;
  const int64_t per_image = detector::output_size(shapes);
  int64_t offset = 0;  // of the current head within one image's outputs
  for (size_t h = 0; h < outs.size(); ++h) {
    const detector::Shape& s = shapes[h];
    ASSERT_EQ(outs[h].sizes(), (std::vector<int64_t>{batch, s.c, s.h, s.w})) << m.cfg_path << " head " << h;
    const torch::Tensor t = outs[h].contiguous();
    double max_ref = 0.0, max_diff = 0.0;
    for (int n = 0; n < batch; ++n) {
      const float* a = t.data_ptr<float>() + n * s.size();
      const float* b = ref.data() + n * per_image + offset;
      for (int64_t i = 0; i < s.size(); ++i) {
        max_ref = std::max(max_ref, static_cast<double>(std::fabs(b[i])));
        max_diff = std::max(max_diff, static_cast<double>(std::fabs(a[i] - b[i])));
      }
    }
    EXPECT_LE(max_diff, 1e-3 * std::max(1.0, max_ref))
        << m.cfg_path << " head " << h << " (" << s.c << "x" << s.h << "x" << s.w << "), batch " << batch
        << ": max |torch - opencv| = " << max_diff << ", max |opencv| = " << max_ref;
    EXPECT_GT(max_ref, 1e-3) << "degenerate output";
    offset += s.size();
  }
}

TEST(DarknetNet, ThesisNetworkMatchesOpenCvDnnOnRandomWeights) {
  torch::set_num_threads(2);
  expect_torch_matches_opencv(detector::parse_darknet_cfg(testing::source_path("models/tiny-yolo-thesis.cfg")), 2024,
                              2);
}

TEST(DarknetNet, ProposedSmallNetworkMatchesOpenCvDnnOnRandomWeights) {
  const DarknetModel m = detector::parse_darknet_cfg(testing::source_path("models/wingman-small.cfg"));
  // 640x352 input: heads 40x22 (stride 16), 80x44 (stride 8) and, grown on them, 20x11 (stride 32, large drones).
  EXPECT_NEAR(m.flops() / 1e9, 1.083, 0.005);
  ASSERT_EQ(m.heads().size(), 3u);
  EXPECT_EQ(m.layers[9].input, (detector::Shape{18, 22, 40}));
  EXPECT_EQ(m.layers[16].input, (detector::Shape{18, 44, 80}));
  EXPECT_EQ(m.layers[23].input, (detector::Shape{18, 11, 20}));
  expect_torch_matches_opencv(m, 31, 1);
}

// Odd, non-square sizes; maxpool 2/2 on an odd size (Darknet rounds up), maxpool 2/1, route of two layers,
// upsample, a convolution without batch normalisation, a logistic activation, stride 2 and two [yolo] heads
// (9 x 13 and 18 x 26).
constexpr const char* kTwoHeadCfg = R"([net]
width=104
height=72
channels=3
[convolutional]
batch_normalize=1
filters=8
size=3
stride=2
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
filters=24
size=3
stride=1
pad=1
activation=leaky
[maxpool]
size=2
stride=1
[convolutional]
filters=16
size=1
stride=1
pad=1
activation=logistic
[convolutional]
size=1
stride=1
pad=1
filters=12
activation=linear
[yolo]
mask=2,3
anchors=4,5, 8,9, 14,12, 30,20
classes=1
num=4
[route]
layers=-3
[upsample]
stride=2
[route]
layers=-1,2
[convolutional]
batch_normalize=1
filters=8
size=3
stride=1
pad=1
activation=leaky
[convolutional]
size=1
stride=1
pad=1
filters=12
activation=linear
[yolo]
mask=0,1
anchors=4,5, 8,9, 14,12, 30,20
classes=1
num=4
)";

TEST(DarknetNet, RouteUpsampleMaxpoolAndTwoYoloHeadsMatchOpenCvDnn) {
  const DarknetModel m = detector::parse_darknet_cfg_string(kTwoHeadCfg, "two_heads.cfg");
  ASSERT_EQ(m.layers[5].output, (detector::Shape{24, 9, 13}));  // maxpool 2/1 keeps 9 x 13
  ASSERT_EQ(m.layers[11].output, (detector::Shape{32, 18, 26}));
  ASSERT_EQ(m.layers[14].input, (detector::Shape{12, 18, 26}));
  expect_torch_matches_opencv(m, 7, 3);
}

TEST(DarknetNet, MaxpoolPadsRightAndBottomAsDarknet) {
  // One 2x2 stride-1 maxpool on a 3 x 3 image: the last row and column see only themselves.
  const DarknetModel m = detector::parse_darknet_cfg_string(
      "[net]\nwidth=3\nheight=3\nchannels=1\n[maxpool]\nsize=2\nstride=1\n", "p.cfg");
  DarknetNet net(m);
  const torch::Tensor x = torch::tensor({-1.f, -5.f, -2.f, -7.f, -3.f, -9.f, -4.f, -8.f, -6.f}).view({1, 1, 3, 3});
  const torch::Tensor y = net->forward(x)[0];
  const torch::Tensor expected =
      torch::tensor({-1.f, -2.f, -2.f, -3.f, -3.f, -6.f, -4.f, -6.f, -6.f}).view({1, 1, 3, 3});
  EXPECT_TRUE(torch::equal(y, expected)) << y;
  // Stride 2 on an odd size rounds up: 5 -> 3.
  const DarknetModel m2 = detector::parse_darknet_cfg_string(
      "[net]\nwidth=5\nheight=5\nchannels=1\n[maxpool]\nsize=2\nstride=2\n", "q.cfg");
  DarknetNet net2(m2);
  EXPECT_EQ(net2->forward(torch::arange(25, torch::kFloat).view({1, 1, 5, 5}))[0].sizes(),
            (std::vector<int64_t>{1, 1, 3, 3}));
}

TEST(DarknetNet, WeightsRoundTripThroughTheDarknetFormatBitIdentically) {
  DarknetModel m = detector::parse_darknet_cfg(testing::source_path("models/tiny-yolo-thesis.cfg"));
  detector::randomize_weights(m, 99);
  const std::vector<char> original = detector::serialize_darknet_weights(m);
  DarknetNet net(m);
  net->load_weights(m);
  DarknetModel out = detector::parse_darknet_cfg(testing::source_path("models/tiny-yolo-thesis.cfg"));
  net->store_weights(out);
  EXPECT_EQ(detector::serialize_darknet_weights(out), original);
  // And through a file, into a second network.
  testing::TempDir dir;
  detector::save_darknet_weights(out, dir.file("a.weights"));
  DarknetModel back = detector::parse_darknet_cfg(testing::source_path("models/tiny-yolo-thesis.cfg"));
  detector::load_darknet_weights(back, dir.file("a.weights"));
  DarknetNet net2(back);
  net2->load_weights(back);
  DarknetModel again = back;
  net2->store_weights(again);
  EXPECT_EQ(detector::serialize_darknet_weights(again), original);
}

TEST(DarknetNet, MismatchedWeightsAreNamed) {
  DarknetModel m = detector::parse_darknet_cfg_string(kTwoHeadCfg, "two_heads.cfg");
  DarknetNet net(m);
  try {
    net->load_weights(m);  // never randomized: empty vectors
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("two_heads.cfg:5: [convolutional] (layer 0) weights: 0 values, expected 216"),
              std::string::npos)
        << e.what();
  }
  const DarknetModel other = detector::parse_darknet_cfg(testing::source_path("models/tiny-yolo-thesis.cfg"));
  EXPECT_THROW(net->load_weights(other), std::invalid_argument);
}

/// Every float of the network's Darknet export (weights and batch-norm statistics), in file order.
std::vector<float> exported_floats(const DarknetNet& net) {
  DarknetModel m = net->model();
  net->store_weights(m);
  std::vector<float> v;
  for (const auto& l : m.layers)
    for (const auto* part : {&l.biases, &l.scales, &l.rolling_mean, &l.rolling_variance, &l.weights})
      v.insert(v.end(), part->begin(), part->end());
  return v;
}

TEST(WeightAverage, UpdatesMatchAPlainReference) {
  const DarknetModel m = detector::parse_darknet_cfg_string(kTwoHeadCfg, "two_heads.cfg");
  torch::manual_seed(3);
  DarknetNet current(m);
  DarknetNet average(m);
  copy_weights(*average, *current);
  std::vector<float> expected = exported_floats(average);
  ASSERT_EQ(expected, exported_floats(current));
  ASSERT_GT(expected.size(), 1000u);
  // Three steps, each after the weights and batch-norm statistics moved (a forward in training mode and a step).
  const std::vector<double> decays = {0.0, 0.5, 0.9};
  for (size_t k = 0; k < decays.size(); ++k) {
    {
      torch::NoGradGuard no_grad;
      for (torch::Tensor& p : current->parameters()) p.add_(torch::randn_like(p) * 0.1);
    }
    current->forward(torch::from_blob(random_input(m, 2, 11 + static_cast<uint32_t>(k)).data(),
                                      {2, m.net.channels, m.net.height, m.net.width})
                         .clone());
    const std::vector<float> now = exported_floats(current);
    update_weight_average(*average, *current, decays[k]);
    for (size_t i = 0; i < expected.size(); ++i)
      expected[i] = static_cast<float>(decays[k] * expected[i] + (1.0 - decays[k]) * now[i]);
    const std::vector<float> got = exported_floats(average);
    ASSERT_EQ(got.size(), expected.size());
    for (size_t i = 0; i < got.size(); ++i)
      ASSERT_NEAR(got[i], expected[i], 1e-6f * std::max(1.0f, std::fabs(expected[i])))
          << "step " << k << " float " << i;
  }
  // The integer batch counts are copied, not averaged.
  for (size_t i = 0; i < average->buffers().size(); ++i) {
    if (!average->buffers()[i].is_floating_point()) {
      EXPECT_TRUE(torch::equal(average->buffers()[i], current->buffers()[i])) << "buffer " << i;
    }
  }
}

TEST(WeightAverage, AnotherNetworkOrABadDecayIsRefused) {
  const DarknetModel a = detector::parse_darknet_cfg_string(kTwoHeadCfg, "two_heads.cfg");
  const DarknetModel b = detector::parse_darknet_cfg(testing::source_path("models/tiny-yolo-thesis.cfg"));
  DarknetNet x(a), y(b);
  try {
    copy_weights(*x, *y);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("weight average:"), std::string::npos) << e.what();
  }
  EXPECT_THROW(update_weight_average(*x, *y, 0.5), std::invalid_argument);
  DarknetNet z(a);
  try {
    update_weight_average(*x, *z, 1.5);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("decay 1.5 not in [0, 1]"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace wingman::training
