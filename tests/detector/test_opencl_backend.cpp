// SPDX-License-Identifier: MIT
// OpenClBackend against a plain C++ reference and against OpenCV DNN (CpuBackend), layer by layer on odd
// sizes and for the whole thesis network.
//
// Tolerance: max_i |a_i - b_i| <= 1e-3 * max(1, max_i |b_i|), b the reference. Both sides sum in fp32 in
// different orders (and BN is folded into the weights on our side), so differences are ~1e-6 relative
// per layer; 1e-3 leaves room for the thesis network's 9 convolutions while catching any indexing bug,
// which gives O(1) errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "wingman/detector/cpu_backend.hpp"
#include "wingman/detector/darknet_cfg.hpp"
#include "wingman/detector/darknet_weights.hpp"
#include "wingman/detector/opencl_backend.hpp"
#include "wingman/detector/opencl_device.hpp"

namespace wingman::detector {
namespace {

constexpr double kRelativeTolerance = 1e-3;

/// Plain NCHW reference of one image through the model, Darknet semantics (BN eps 1e-6 inside the sqrt,
/// as OpenCV's importer). Returns what InferenceBackend::forward() returns for one image: the input of
/// every [region]/[yolo] head in order, or without heads the last layer's output.
std::vector<float> reference_forward(const DarknetModel& model, const float* image) {
  std::vector<std::vector<float>> outs(model.layers.size());
  std::vector<float> input(image, image + static_cast<size_t>(model.net.channels) * model.net.height * model.net.width);
  const std::vector<float>* x = &input;
  std::vector<float> result;
  for (size_t i = 0; i < model.layers.size(); ++i) {
    const Layer& l = model.layers[i];
    std::vector<float>& y = outs[i];
    y.assign(static_cast<size_t>(l.output.size()), 0.0f);
    const int C = l.input.c, H = l.input.h, W = l.input.w, K = l.output.c, OH = l.output.h, OW = l.output.w;
    switch (l.type) {
      case LayerType::kConvolutional: {
        const int S = l.size;
        for (int k = 0; k < K; ++k) {
          double scale = 1.0, bias = l.biases[k];
          if (l.batch_normalize) {
            scale = l.scales[k] / std::sqrt(static_cast<double>(l.rolling_variance[k]) + 1e-6);
            bias = l.biases[k] - l.rolling_mean[k] * scale;
          }
          for (int oy = 0; oy < OH; ++oy)
            for (int ox = 0; ox < OW; ++ox) {
              double acc = 0.0;
              for (int c = 0; c < C; ++c)
                for (int ky = 0; ky < S; ++ky) {
                  const int iy = oy * l.stride - l.padding + ky;
                  if (iy < 0 || iy >= H) continue;
                  for (int kx = 0; kx < S; ++kx) {
                    const int ix = ox * l.stride - l.padding + kx;
                    if (ix < 0 || ix >= W) continue;
                    acc += static_cast<double>(l.weights[((static_cast<size_t>(k) * C + c) * S + ky) * S + kx]) *
                           (*x)[(static_cast<size_t>(c) * H + iy) * W + ix];
                  }
                }
              double v = acc * scale + bias;
              if (l.activation == Activation::kLeaky) v = v > 0 ? v : 0.1 * v;
              if (l.activation == Activation::kLogistic) v = 1.0 / (1.0 + std::exp(-v));
              y[(static_cast<size_t>(k) * OH + oy) * OW + ox] = static_cast<float>(v);
            }
        }
        break;
      }
      case LayerType::kMaxpool:
        for (int c = 0; c < C; ++c)
          for (int oy = 0; oy < OH; ++oy)
            for (int ox = 0; ox < OW; ++ox) {
              float m = -std::numeric_limits<float>::infinity();
              for (int dy = 0; dy < l.pool_size; ++dy)
                for (int dx = 0; dx < l.pool_size; ++dx) {
                  const int iy = oy * l.pool_stride - l.pool_padding / 2 + dy;
                  const int ix = ox * l.pool_stride - l.pool_padding / 2 + dx;
                  if (iy >= 0 && iy < H && ix >= 0 && ix < W)
                    m = std::max(m, (*x)[(static_cast<size_t>(c) * H + iy) * W + ix]);
                }
              y[(static_cast<size_t>(c) * OH + oy) * OW + ox] = m;
            }
        break;
      case LayerType::kUpsample:
        for (int c = 0; c < K; ++c)
          for (int oy = 0; oy < OH; ++oy)
            for (int ox = 0; ox < OW; ++ox)
              y[(static_cast<size_t>(c) * OH + oy) * OW + ox] =
                  (*x)[(static_cast<size_t>(c) * H + oy / l.upsample_stride) * W + ox / l.upsample_stride];
        break;
      case LayerType::kRoute: {
        size_t offset = 0;
        for (int r : l.route_layers) {
          std::copy(outs[r].begin(), outs[r].end(), y.begin() + offset);
          offset += outs[r].size();
        }
        break;
      }
      case LayerType::kRegion:
      case LayerType::kYolo:
        y = *x;
        result.insert(result.end(), x->begin(), x->end());
        break;
    }
    x = &y;
  }
  if (model.heads().empty()) result = *x;
  return result;
}

std::vector<float> random_images(const Shape& s, int batch, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<float> v(static_cast<size_t>(s.size()) * batch);
  for (auto& f : v) f = u(rng);
  return v;
}

/// "" when max|a-b| <= tol * max(1, max|b|), else a one-line description of the worst element. `shape`:
/// one output tensor per image (several outputs: the location is given as a flat index).
std::string compare(const std::vector<float>& actual, const std::vector<float>& expected, const Shape& shape) {
  if (actual.size() != expected.size())
    return "size " + std::to_string(actual.size()) + " != expected " + std::to_string(expected.size());
  double max_ref = 0.0, max_err = 0.0;
  size_t worst = 0;
  for (size_t i = 0; i < expected.size(); ++i) {
    max_ref = std::max(max_ref, static_cast<double>(std::fabs(expected[i])));
    const double err = std::fabs(static_cast<double>(actual[i]) - expected[i]);
    if (!(err <= max_err)) {  // also catches NaN
      max_err = err;
      worst = i;
    }
  }
  if (max_err <= kRelativeTolerance * std::max(1.0, max_ref)) return "";
  const size_t plane = static_cast<size_t>(shape.h) * shape.w;
  const size_t image = plane * shape.c;
  std::ostringstream s;
  s << "max |error| " << max_err << " > " << kRelativeTolerance << " * max(1, " << max_ref << ") at n " << worst / image
    << " c " << (worst % image) / plane << " y " << (worst % plane) / shape.w << " x " << worst % shape.w << ": got "
    << actual[worst] << ", expected " << expected[worst] << " (output " << shape.c << "x" << shape.h << "x" << shape.w
    << ")";
  return s.str();
}

bool have_opencl() { return !list_opencl_devices().empty(); }

OpenClOptions options_for_batch(int max_batch) {
  OpenClOptions o;
  o.max_batch = max_batch;
  return o;
}

/// Runs `cfg` (random weights and images, seeded) through OpenCL, the plain reference and OpenCV DNN.
void check_network(const std::string& cfg, const std::string& description, int batch, bool with_reference = true,
                   bool with_opencv = true) {
  SCOPED_TRACE(description);
  DarknetModel model = parse_darknet_cfg_string(cfg, description);
  randomize_weights(model, 1234);
  OpenClBackend backend(model, options_for_batch(batch));
  const Shape in = backend.input_shape();
  const std::vector<Shape> outs = backend.output_shapes();
  // For messages: the one output's shape, or all outputs of an image as one flat tensor.
  const Shape out = outs.size() == 1 ? outs[0] : Shape{1, 1, static_cast<int>(output_size(outs))};
  const auto images = random_images(in, batch, 99);
  std::vector<float> got;
  backend.forward(images.data(), batch, got);
  ASSERT_EQ(got.size(), static_cast<size_t>(output_size(outs)) * batch);
  if (with_reference) {
    std::vector<float> expected;
    for (int n = 0; n < batch; ++n) {
      const auto one = reference_forward(model, images.data() + static_cast<size_t>(n) * in.size());
      expected.insert(expected.end(), one.begin(), one.end());
    }
    EXPECT_EQ(compare(got, expected, out), "") << description << " vs plain reference, batch " << batch;
  }
  if (with_opencv) {
    CpuBackend cpu(model, batch);
    ASSERT_EQ(cpu.output_shapes(), outs);
    std::vector<float> expected;
    cpu.forward(images.data(), batch, expected);
    EXPECT_EQ(compare(got, expected, out), "") << description << " vs OpenCV DNN, batch " << batch;
  }
}

std::string net_section(int c, int h, int w) {
  return "[net]\nwidth=" + std::to_string(w) + "\nheight=" + std::to_string(h) + "\nchannels=" + std::to_string(c) +
         "\n\n";
}

std::string conv_section(int filters, int size, int stride, bool bn, const std::string& activation, int pad = 1) {
  std::ostringstream s;
  s << "[convolutional]\n";
  if (bn) s << "batch_normalize=1\n";
  s << "filters=" << filters << "\nsize=" << size << "\nstride=" << stride << "\npad=" << pad
    << "\nactivation=" << activation << "\n\n";
  return s.str();
}

std::string maxpool_section(int size, int stride) {
  return "[maxpool]\nsize=" + std::to_string(size) + "\nstride=" + std::to_string(stride) + "\n\n";
}

std::string thesis_cfg(int size) {
  std::string cfg = net_section(3, size, size);
  const int filters[] = {16, 32, 64, 128, 256, 512};
  for (int i = 0; i < 6; ++i) cfg += conv_section(filters[i], 3, 1, true, "leaky") + maxpool_section(2, i < 5 ? 2 : 1);
  cfg += conv_section(1024, 3, 1, true, "leaky") + conv_section(1024, 3, 1, true, "leaky") +
         conv_section(30, 1, 1, false, "linear");
  cfg +=
      "[region]\nanchors = 1.08,1.19, 3.42,4.41, 6.63,11.38, 9.42,5.11, 16.62,10.52\nclasses=1\ncoords=4\nnum=5\n"
      "softmax=1\n";
  return cfg;
}

#define REQUIRE_OPENCL() \
  if (!have_opencl()) GTEST_SKIP() << "no OpenCL platform on this machine"

TEST(OpenClOptions, DefaultsAreValid) { EXPECT_TRUE(OpenClOptions{}.validate().empty()); }

TEST(OpenClOptions, ValidateNamesTheKey) {
  OpenClOptions o;
  o.max_batch = 0;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NE(p[0].find("opencl.max_batch"), std::string::npos) << p[0];
}

TEST(OpenClDevices, ListsAtLeastOneDevice) {
  REQUIRE_OPENCL();
  for (const auto& line : list_opencl_devices()) std::cout << line << "\n";
}

TEST(OpenClDevices, UnknownDeviceErrorListsTheAvailableOnes) {
  REQUIRE_OPENCL();
  DarknetModel model = parse_darknet_cfg_string(net_section(3, 7, 5) + conv_section(4, 3, 1, false, "linear"));
  randomize_weights(model, 1);
  OpenClOptions o;
  o.device = "no-such-device-xyz";
  try {
    OpenClBackend backend(model, o);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("opencl.device = 'no-such-device-xyz'"), std::string::npos) << msg;
    EXPECT_NE(msg.find(list_opencl_devices().front()), std::string::npos) << msg;
  }
  o.device = "";
  o.platform = "17";
  EXPECT_THROW(OpenClBackend(model, o), std::runtime_error);
  o.platform = "0";
  o.device = "0";
  EXPECT_NO_THROW(OpenClBackend(model, o));
}

TEST(OpenClBackend, RejectsBadBatchAndMissingWeights) {
  REQUIRE_OPENCL();
  DarknetModel model = parse_darknet_cfg_string(net_section(3, 7, 5) + conv_section(4, 3, 1, true, "leaky"));
  EXPECT_THROW(OpenClBackend(model, OpenClOptions{}), std::invalid_argument);  // weights never loaded
  randomize_weights(model, 1);
  OpenClBackend backend(model, options_for_batch(2));
  EXPECT_EQ(backend.max_batch(), 2);
  EXPECT_EQ(backend.output_shapes(), (std::vector<Shape>{{4, 7, 5}}));
  std::vector<float> images(3 * 7 * 5 * 3, 0.5f), out;
  EXPECT_THROW(backend.forward(images.data(), 3, out), std::invalid_argument);
  EXPECT_THROW(backend.forward(images.data(), 0, out), std::invalid_argument);
}

struct ConvCase {
  int c, h, w, filters, size, stride;
  bool bn;
  const char* activation;
};

TEST(OpenClConvolution, MatchesReferenceAndOpenCvOnOddShapes) {
  REQUIRE_OPENCL();
  const ConvCase cases[] = {
      {3, 13, 11, 5, 3, 1, true, "leaky"},      // RGB-like first layer, 1 partial block
      {37, 11, 29, 21, 3, 1, true, "leaky"},    // 3 input blocks, 2 output blocks, 3 tiles of 13
      {20, 9, 30, 33, 1, 1, false, "linear"},   // 1x1, width 30: tile 15
      {5, 13, 11, 7, 3, 2, true, "logistic"},   // stride 2
      {16, 14, 26, 16, 3, 1, false, "leaky"},   // exact blocks, two tiles of 13
      {1, 7, 5, 3, 3, 1, true, "linear"},       // single channel
      {19, 6, 41, 17, 3, 1, true, "logistic"},  // width 41: prime
      {3, 5, 301, 5, 3, 1, true, "leaky"},      // planar input, wide: 24 tiles of 13, the last with 2 columns
      {16, 3, 97, 40, 3, 1, true, "leaky"},     // 16 planes planar, 3 output blocks (second pair half empty)
  };
  for (const auto& k : cases) {
    std::ostringstream d;
    d << "conv " << k.c << "x" << k.h << "x" << k.w << " -> " << k.filters << " size " << k.size << " stride "
      << k.stride << (k.bn ? " bn " : " ") << k.activation;
    const std::string cfg = net_section(k.c, k.h, k.w) + conv_section(k.filters, k.size, k.stride, k.bn, k.activation);
    check_network(cfg, d.str(), 1);
    check_network(cfg, d.str(), 3);
  }
}

TEST(OpenClConvolution, WinogradLayersMatchReferenceAndOpenCvOnOddShapes) {
  REQUIRE_OPENCL();
  // 3x3 stride-1 convolutions on many input channels run as Winograd F(2x2, 3x3) (asserted below, so these
  // cases keep covering it): odd sizes give partial 2x2 tiles on the right and bottom.
  const ConvCase cases[] = {
      {256, 11, 9, 40, 3, 1, true, "leaky"},      // 6 x 5 tiles, 3 output blocks (second pair half empty)
      {300, 7, 13, 17, 3, 1, false, "logistic"},  // last input block partly filled, 2 output blocks
      {272, 2, 3, 16, 3, 1, true, "linear"},      // one output block, 2 x 3 image
      {256, 1, 1, 5, 3, 1, true, "leaky"},        // a single pixel: one tile, three quarters outside
  };
  for (const auto& k : cases) {
    std::ostringstream d;
    d << "conv " << k.c << "x" << k.h << "x" << k.w << " -> " << k.filters << (k.bn ? " bn " : " ") << k.activation;
    const std::string cfg = net_section(k.c, k.h, k.w) + conv_section(k.filters, k.size, k.stride, k.bn, k.activation);
    DarknetModel model = parse_darknet_cfg_string(cfg, d.str());
    randomize_weights(model, 3);
    const std::vector<std::string> commands = OpenClBackend(model, options_for_batch(1)).commands();
    EXPECT_TRUE(std::any_of(commands.begin(), commands.end(),
                            [](const std::string& c) { return c.find("winograd: 16 products") != std::string::npos; }))
        << d.str() << " does not run as Winograd";
    check_network(cfg, d.str(), 1);
    check_network(cfg, d.str(), 3);
  }
}

TEST(OpenClMaxpool, MatchesReferenceAndOpenCvOnOddShapes) {
  REQUIRE_OPENCL();
  const int cases[][5] = {
      // c, h, w, size, stride
      {5, 13, 11, 2, 2},
      {5, 13, 11, 2, 1},  // Darknet padding 1 on the right/bottom keeps 13x11
      {19, 9, 10, 3, 2},
      {17, 8, 7, 3, 1},
  };
  for (const auto& k : cases) {
    std::ostringstream d;
    d << "conv " << k[0] << "x" << k[1] << "x" << k[2] << " then maxpool size " << k[3] << " stride " << k[4];
    // A convolution first so that negative values (leaky) reach the pooling.
    const std::string cfg =
        net_section(3, k[1], k[2]) + conv_section(k[0], 3, 1, true, "leaky") + maxpool_section(k[3], k[4]);
    check_network(cfg, d.str(), 2);
  }
  // A network starting with a pooling: the input goes through the pack kernel instead of straight to a
  // planar convolution input.
  check_network(net_section(5, 13, 11) + maxpool_section(2, 2) + conv_section(7, 3, 1, true, "leaky"),
                "maxpool 2/2 first on 5x13x11, then conv ->7", 2);
}

TEST(OpenClMaxpool, FusedIntoTheConvolutionOnOddShapes) {
  REQUIRE_OPENCL();
  // 2x2 stride-2 pooling after a convolution whose width an even tile covers with little waste is fused
  // (asserted, so these cases keep covering it); odd sizes leave a last pooled row and column of one.
  const int cases[][4] = {
      // input channels, h, w, filters
      {3, 13, 23, 5},   // planar input, one output block, 12 x 7 pooled
      {20, 9, 47, 19},  // two output blocks (the second partly filled), 24 x 5 pooled
      {16, 7, 24, 40},  // three output blocks (second pair half empty), even width
  };
  for (const auto& k : cases) {
    std::ostringstream d;
    d << "conv " << k[0] << "x" << k[1] << "x" << k[2] << " -> " << k[3] << " leaky, maxpool 2/2 fused";
    const std::string cfg =
        net_section(k[0], k[1], k[2]) + conv_section(k[3], 3, 1, true, "leaky") + maxpool_section(2, 2);
    DarknetModel model = parse_darknet_cfg_string(cfg, d.str());
    randomize_weights(model, 4);
    const std::vector<std::string> commands = OpenClBackend(model, options_for_batch(1)).commands();
    EXPECT_TRUE(std::any_of(commands.begin(), commands.end(),
                            [](const std::string& c) { return c.find("fused") != std::string::npos; }))
        << d.str() << " is not fused";
    check_network(cfg, d.str(), 1);
    check_network(cfg, d.str(), 3);
  }
}

TEST(OpenClRoute, ConcatenatesChannelsAtUnalignedOffsets) {
  REQUIRE_OPENCL();
  // Every layer feeds the next (OpenCV DNN wants a single unconnected output).
  const std::string cfg = net_section(5, 13, 11) + conv_section(7, 3, 1, true, "leaky") + maxpool_section(2, 1) +
                          "[route]\nlayers=-1,-2\n\n" + conv_section(3, 1, 1, false, "linear");
  check_network(cfg, "conv 5->7, maxpool 2/1, route -1,-2 (14 ch), conv 1x1 ->3 (13x11)", 2);
  const std::string cfg2 = net_section(3, 13, 11) + conv_section(7, 3, 1, true, "leaky") +
                           conv_section(9, 3, 1, true, "leaky") + "[route]\nlayers=-1,-2\n\n" +
                           conv_section(5, 3, 1, true, "leaky");
  check_network(cfg2, "conv 3->7, conv 7->9, route -1,-2, conv 3x3 ->5 (13x11)", 1);
}

TEST(OpenClRoute, CopiesWholeBlocksAtAlignedOffsetsAndMixesBothCopies) {
  REQUIRE_OPENCL();
  // 16 + 32 channels: both inputs whole blocks at block offsets 0 and 1 (the vector copy); a single-input route.
  const std::string cfg = net_section(3, 13, 11) + conv_section(16, 3, 1, true, "leaky") +
                          conv_section(32, 3, 1, true, "leaky") + "[route]\nlayers=-1,-2\n\n" +
                          "[route]\nlayers=-1\n\n" + conv_section(5, 3, 1, true, "leaky");
  auto copies = [](const std::string& c) {
    DarknetModel model = parse_darknet_cfg_string(c);
    randomize_weights(model, 3);
    std::vector<std::string> kinds;
    for (const std::string& line : OpenClBackend(model, options_for_batch(1)).commands())
      if (line.find("[route]") != std::string::npos) kinds.push_back(line.substr(line.find(" copy: ") + 7));
    return kinds;
  };
  EXPECT_EQ(copies(cfg), (std::vector<std::string>{"whole blocks", "whole blocks", "whole blocks"}));
  check_network(cfg, "conv 3->16, conv 16->32, route -1,-2 (48 ch), route -1, conv 3x3 ->5 (13x11)", 2);
  // 7 + 16: a partial block, then a whole one at offset 7 (not a block boundary: channel by channel); then 16 + 7:
  // a whole block at offset 0 (the vector copy) and a partial one at offset 16. Every layer feeds a later one.
  const std::string mixed = net_section(3, 9, 12) + conv_section(16, 3, 1, true, "leaky") +
                            conv_section(7, 3, 1, true, "leaky") + "[route]\nlayers=-1,-2\n\n" +
                            conv_section(16, 3, 1, true, "leaky") + "[route]\nlayers=-1,1\n\n" +
                            conv_section(4, 1, 1, false, "linear");
  EXPECT_EQ(copies(mixed), (std::vector<std::string>{"channel by channel", "channel by channel", "whole blocks",
                                                     "channel by channel"}));
  check_network(mixed, "conv 3->16, conv 16->7, route -1,-2 (7+16 ch), conv ->16, route -1,1 (16+7 ch), conv 1x1 ->4",
                2);
}

TEST(OpenClUpsample, RepeatsNearestNeighbours) {
  REQUIRE_OPENCL();
  const std::string cfg = net_section(5, 7, 9) + conv_section(7, 3, 1, true, "leaky") + "[upsample]\nstride=2\n\n" +
                          conv_section(3, 3, 1, true, "leaky");
  check_network(cfg, "conv 5->7 7x9, upsample 2 -> 14x18, conv 7->3", 2);
}

TEST(OpenClNetwork, TinyYoloV3LikeNetworkWithTwoHeads) {
  REQUIRE_OPENCL();
  // Shapes as in yolov3-tiny, scaled down: two [yolo] heads, a route back, upsample and concat.
  std::string cfg = net_section(3, 52, 52) + conv_section(8, 3, 1, true, "leaky") + maxpool_section(2, 2) +
                    conv_section(16, 3, 1, true, "leaky") + maxpool_section(2, 2) +
                    conv_section(32, 3, 1, true, "leaky") + maxpool_section(2, 1) +
                    conv_section(18, 1, 1, false, "linear") +
                    "[yolo]\nmask=3,4,5\nanchors=10,14, 23,27, 37,58, 81,82, 135,169, 344,319\nclasses=1\nnum=6\n\n" +
                    "[route]\nlayers=-3\n\n" + conv_section(8, 1, 1, true, "leaky") + "[upsample]\nstride=2\n\n" +
                    "[route]\nlayers=-1,2\n\n" + conv_section(18, 1, 1, false, "linear") +
                    "[yolo]\nmask=0,1,2\nanchors=10,14, 23,27, 37,58, 81,82, 135,169, 344,319\nclasses=1\nnum=6\n";
  // Both backends return the raw inputs of the two heads (18x13x13 then 18x26x26) per image.
  check_network(cfg, "tiny-yolov3-like 52x52, two yolo heads", 2);
}

TEST(OpenClNetwork, ThesisNetworkMatchesOpenCvAt416) {
  REQUIRE_OPENCL();
  check_network(thesis_cfg(416), "thesis network 416x416, batch 2 vs OpenCV DNN", 2, /*with_reference=*/false);
}

TEST(OpenClNetwork, ThesisNetworkMatchesReferenceAt160) {
  REQUIRE_OPENCL();
  // 160: widths 160, 80, 40, 20, 10, 5 are not multiples of 13 (other tile widths).
  check_network(thesis_cfg(160), "thesis network 160x160, batch 1", 1);
}

TEST(OpenClNetwork, RepeatedForwardIsDeterministic) {
  REQUIRE_OPENCL();
  DarknetModel model = parse_darknet_cfg_string(thesis_cfg(96));
  randomize_weights(model, 5);
  OpenClBackend backend(model, options_for_batch(3));
  const auto images = random_images(backend.input_shape(), 3, 7);
  std::vector<float> a, b, single;
  backend.forward(images.data(), 3, a);
  backend.forward(images.data(), 3, b);
  EXPECT_EQ(a, b);
  // Image 1 alone gives the same as inside the batch.
  backend.forward(images.data() + backend.input_shape().size(), 1, single);
  const size_t o = output_size(backend.output_shapes());
  EXPECT_TRUE(std::equal(single.begin(), single.end(), a.begin() + o));
}

}  // namespace
}  // namespace wingman::detector
