// SPDX-License-Identifier: MIT
// CpuBackend (OpenCV DNN): the thesis network with seeded random weights, and networks ending in any layer.
#include <wingman/detector/cpu_backend.hpp>
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace wingman::detector {
namespace {

std::vector<float> random_input(const Shape& s, int batch, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<float> v(static_cast<size_t>(s.size()) * batch);
  for (float& x : v) x = static_cast<float>(rng() % 256) / 255.0f;
  return v;
}

TEST(CpuBackend, ThesisNetworkOutputsRawRegionInput) {
  DarknetModel m = parse_darknet_cfg(testing::source_path("models/tiny-yolo-thesis.cfg"));
  randomize_weights(m, 2024);
  CpuBackend backend(m, 2);
  EXPECT_EQ(backend.input_shape(), (Shape{3, 416, 416}));
  EXPECT_EQ(backend.output_shapes(), (std::vector<Shape>{{30, 13, 13}})) << backend.output_layer_names().front();
  const std::vector<float> input = random_input(backend.input_shape(), 2, 5);
  std::vector<float> out;
  backend.forward(input.data(), 2, out);
  ASSERT_EQ(out.size(), 2u * 30 * 13 * 13);
  // Random weights of realistic scale keep the raw outputs bounded and not degenerate.
  double sum_sq = 0.0;
  for (float v : out) {
    ASSERT_TRUE(std::isfinite(v));
    sum_sq += static_cast<double>(v) * v;
  }
  const double rms = std::sqrt(sum_sq / out.size());
  EXPECT_GT(rms, 1e-3) << "layer " << backend.output_layer_names().front();
  EXPECT_LT(rms, 1e3) << "layer " << backend.output_layer_names().front();
  // Batch of one gives the first image's output of the batch of two.
  std::vector<float> single;
  backend.forward(input.data(), 1, single);
  ASSERT_EQ(single.size(), 30u * 13 * 13);
  for (size_t i = 0; i < single.size(); ++i) ASSERT_NEAR(single[i], out[i], 1e-3 * (1.0 + std::fabs(out[i]))) << i;
  EXPECT_THROW(backend.forward(input.data(), 3, out), std::invalid_argument);
}

TEST(CpuBackend, SingleConvolutionMatchesPlainReference) {
  // 5 x 7 input, 3 channels -> 4 filters 3 x 3, pad 1, batch-normalized, leaky: a hand-written reference.
  DarknetModel m = parse_darknet_cfg_string(
      "[net]\nwidth=7\nheight=5\nchannels=3\n[convolutional]\nbatch_normalize=1\nfilters=4\nsize=3\nstride=1\npad=1\n"
      "activation=leaky\n",
      "conv.cfg");
  randomize_weights(m, 11);
  CpuBackend backend(m, 1);
  const std::vector<float> input = random_input(backend.input_shape(), 1, 3);
  std::vector<float> out;
  backend.forward(input.data(), 1, out);
  const Layer& l = m.layers[0];
  ASSERT_EQ(out.size(), 4u * 5 * 7);
  for (int o = 0; o < 4; ++o)
    for (int y = 0; y < 5; ++y)
      for (int x = 0; x < 7; ++x) {
        double acc = 0.0;
        for (int c = 0; c < 3; ++c)
          for (int ky = 0; ky < 3; ++ky)
            for (int kx = 0; kx < 3; ++kx) {
              const int iy = y + ky - 1, ix = x + kx - 1;
              if (iy < 0 || iy >= 5 || ix < 0 || ix >= 7) continue;
              acc += l.weights[((o * 3 + c) * 3 + ky) * 3 + kx] * input[(c * 5 + iy) * 7 + ix];
            }
        // Darknet's batch norm: (x - mean) / sqrt(var + 1e-6)... OpenCV uses eps 1e-6 for Darknet too.
        double v = (acc - l.rolling_mean[o]) / std::sqrt(l.rolling_variance[o] + 1e-6) * l.scales[o] + l.biases[o];
        if (v < 0) v *= 0.1;
        EXPECT_NEAR(out[(o * 5 + y) * 7 + x], v, 1e-4) << "o=" << o << " y=" << y << " x=" << x;
      }
}

TEST(CpuBackend, NetworksMayEndInMaxpoolRouteOrUpsample) {
  const std::string head =
      "[net]\nwidth=11\nheight=9\nchannels=3\n[convolutional]\nfilters=5\nsize=3\npad=1\n"
      "activation=linear\n";
  struct Case {
    std::string tail;
    Shape expected;
  };
  for (const Case& c :
       {Case{"[maxpool]\nsize=2\nstride=1\n", {5, 9, 11}}, Case{"[maxpool]\nsize=2\nstride=2\n", {5, 5, 6}},
        Case{"[upsample]\nstride=2\n", {5, 18, 22}}, Case{"[route]\nlayers=-1,0\n", {10, 9, 11}}}) {
    SCOPED_TRACE(c.tail);
    DarknetModel m = parse_darknet_cfg_string(head + c.tail, "tail.cfg");
    randomize_weights(m, 9);
    CpuBackend backend(m, 1);
    EXPECT_EQ(backend.output_shapes(), (std::vector<Shape>{c.expected}));
    const std::vector<float> input = random_input(backend.input_shape(), 1, 4);
    std::vector<float> out;
    backend.forward(input.data(), 1, out);
    EXPECT_EQ(static_cast<int64_t>(out.size()), c.expected.size()) << backend.output_layer_names().front();
  }
}

TEST(CpuBackend, TwoYoloHeadsGiveBothRawHeadInputsPerImage) {
  // yolov3-tiny's shape, scaled down: a 13 x 13 head, a route back, upsample, concat and a 26 x 26 head.
  const std::string yolo = "[yolo]\nmask={}\nanchors=10,14, 23,27, 37,58, 81,82, 135,169, 344,319\nclasses=2\nnum=6\n";
  auto head = [&](const char* mask) {
    std::string s = yolo;
    return s.replace(s.find("{}"), 2, mask);
  };
  const std::string cfg =
      "[net]\nwidth=52\nheight=52\nchannels=3\n"
      "[convolutional]\nbatch_normalize=1\nfilters=8\nsize=3\npad=1\nactivation=leaky\n"
      "[maxpool]\nsize=2\nstride=2\n"
      "[convolutional]\nbatch_normalize=1\nfilters=16\nsize=3\npad=1\nactivation=leaky\n"
      "[maxpool]\nsize=2\nstride=2\n"
      "[convolutional]\nfilters=21\nsize=1\npad=1\nactivation=linear\n" +
      head("3,4,5") +
      "[route]\nlayers=-3\n"
      "[upsample]\nstride=2\n"
      "[route]\nlayers=-1,2\n"
      "[convolutional]\nfilters=21\nsize=1\npad=1\nactivation=linear\n" +
      head("0,1,2");
  DarknetModel m = parse_darknet_cfg_string(cfg, "two-heads.cfg");
  randomize_weights(m, 21);
  CpuBackend backend(m, 2);
  ASSERT_EQ(backend.output_shapes(), (std::vector<Shape>{{21, 13, 13}, {21, 26, 26}}));
  EXPECT_EQ(backend.output_layer_names(), (std::vector<std::string>{"identity_5", "identity_10"}));
  const std::vector<float> input = random_input(backend.input_shape(), 2, 8);
  std::vector<float> both, first, second;
  backend.forward(input.data(), 2, both);
  backend.forward(input.data(), 1, first);
  backend.forward(input.data() + backend.input_shape().size(), 1, second);
  const size_t per_image = 21 * 13 * 13 + 21 * 26 * 26;
  ASSERT_EQ(both.size(), 2 * per_image);
  ASSERT_EQ(first.size(), per_image);
  // Image after image, each with its 13 x 13 then its 26 x 26 tensor.
  for (size_t i = 0; i < per_image; ++i) {
    ASSERT_NEAR(both[i], first[i], 1e-4 * (1.0 + std::fabs(first[i]))) << i;
    ASSERT_NEAR(both[per_image + i], second[i], 1e-4 * (1.0 + std::fabs(second[i]))) << i;
  }
  // The heads' inputs are the outputs of layers 4 and 9, as a network ending there computes them.
  DarknetModel upto4 = m;
  upto4.layers.resize(5);
  CpuBackend b4(upto4, 1);
  std::vector<float> o4;
  b4.forward(input.data(), 1, o4);
  ASSERT_EQ(o4.size(), 21u * 13 * 13);
  for (size_t i = 0; i < o4.size(); ++i) ASSERT_NEAR(first[i], o4[i], 1e-4 * (1.0 + std::fabs(o4[i]))) << i;
}

}  // namespace
}  // namespace wingman::detector
