// SPDX-License-Identifier: MIT
// widen_classes(): a trained network's [yolo] heads grown to more classes compute the same old channels (against the
// unwidened network on the CPU backend), the new classes start at their bias, and what cannot be widened is refused.
#include <wingman/detector/class_widening.hpp>
#include <wingman/detector/cpu_backend.hpp>
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>
#include <wingman/detector/region_decode.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

namespace wingman::detector {
namespace {

/// Two [yolo] heads (strides 32 and 16) of `classes` classes on a 128 x 96 input; `route_head` makes the second
/// head's [route] read the first head's [convolutional] (which then cannot grow).
std::string two_heads(int classes, bool route_head = false) {
  const std::string f = std::to_string(3 * (5 + classes));
  const std::string yolo =
      "mask=MASK\nanchors=4,5, 8,9, 12,10, 20,22, 30,28, 50,40\nclasses=" + std::to_string(classes) + "\nnum=6\n\n";
  auto head = [&](const char* mask) {
    std::string y = yolo;
    y.replace(y.find("MASK"), 4, mask);
    return "[convolutional]\nfilters=" + f + "\nsize=1\nstride=1\npad=1\nactivation=linear\n\n[yolo]\n" + y;
  };
  return "[net]\nwidth=128\nheight=96\nchannels=3\n\n"
         "[convolutional]\nbatch_normalize=1\nfilters=8\nsize=3\nstride=1\npad=1\nactivation=leaky\n\n"   // 0
         "[maxpool]\nsize=2\nstride=2\n\n[maxpool]\nsize=2\nstride=2\n\n[maxpool]\nsize=2\nstride=2\n\n"  // 1-3
         "[convolutional]\nbatch_normalize=1\nfilters=8\nsize=3\nstride=1\npad=1\nactivation=leaky\n\n"   // 4
         "[maxpool]\nsize=2\nstride=2\n\n"                                                                // 5
         "[convolutional]\nbatch_normalize=1\nfilters=8\nsize=3\nstride=1\npad=1\nactivation=leaky\n\n"   // 6
         "[maxpool]\nsize=2\nstride=2\n\n" +                                                              // 7
         head("3,4,5") +                                                                                  // 8-9
         (route_head ? "[route]\nlayers=8\n\n" : "[route]\nlayers=7\n\n") +                               // 10
         "[convolutional]\nbatch_normalize=1\nfilters=4\nsize=1\nstride=1\npad=1\nactivation=leaky\n\n"   // 11
         "[upsample]\nstride=2\n\n[route]\nlayers=-1,5\n\n" +                                             // 12-13
         head("0,1,2");                                                                                   // 14-15
}

std::vector<float> forward(const DarknetModel& m, const std::vector<float>& input) {
  CpuBackend backend(m, 1);
  std::vector<float> out;
  backend.forward(input.data(), 1, out);
  return out;
}

TEST(ClassWidening, KeepsEveryOldChannelAndStartsNewClassesAtTheirBias) {
  DarknetModel narrow = parse_darknet_cfg_string(two_heads(1), "narrow.cfg");
  randomize_weights(narrow, 7);
  const DarknetModel wide = widen_classes(narrow, 4);
  // The widened network is a valid model of the 4-class cfg: same layers, same weight count as that cfg's.
  const DarknetModel reference_cfg = parse_darknet_cfg_string(two_heads(4), "wide.cfg");
  ASSERT_EQ(wide.weight_count(), reference_cfg.weight_count());
  for (const int h : wide.heads()) EXPECT_EQ(wide.layers[static_cast<size_t>(h)].classes, 4);
  // It round-trips through the .cfg writer and the .weights format.
  DarknetModel reread = parse_darknet_cfg_string(write_darknet_cfg(wide), "rewritten.cfg");
  load_darknet_weights_from_buffer(reread, serialize_darknet_weights(wide), "wide.weights");

  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<float> input(3 * 96 * 128);
  for (float& v : input) v = u(rng);
  const std::vector<float> a = forward(narrow, input), b = forward(reread, input);
  // Heads in order: 3 x 6 x 3 x 4 and 3 x 6 x 6 x 8 narrow; 3 x 9 x ... wide.
  size_t off_a = 0, off_b = 0;
  for (const int h : narrow.heads()) {
    const Shape s = narrow.layers[static_cast<size_t>(h)].input;
    const int plane = s.h * s.w;
    for (int anchor = 0; anchor < 3; ++anchor) {
      for (int j = 0; j < 6; ++j)
        for (int p = 0; p < plane; ++p)
          ASSERT_NEAR(a[off_a + static_cast<size_t>((anchor * 6 + j) * plane + p)],
                      b[off_b + static_cast<size_t>((anchor * 9 + j) * plane + p)], 1e-5f)
              << "head at layer " << h << ", anchor " << anchor << ", channel " << j << ", cell " << p;
      for (int j = 6; j < 9; ++j)
        for (int p = 0; p < plane; ++p)
          ASSERT_FLOAT_EQ(b[off_b + static_cast<size_t>((anchor * 9 + j) * plane + p)], kNewClassBias);
    }
    // Decoded: the same boxes, all drones, with the same confidence and drone score.
    std::vector<Box> boxes_a, boxes_b;
    decode_yolo(a.data() + off_a, s, narrow.layers[static_cast<size_t>(h)], 128, 96, 0.0f, boxes_a);
    const Layer& wide_head = reread.layers[static_cast<size_t>(h)];
    decode_yolo(b.data() + off_b, wide_head.input, wide_head, 128, 96, 0.0f, boxes_b);
    ASSERT_EQ(boxes_a.size(), boxes_b.size());
    for (size_t i = 0; i < boxes_a.size(); ++i) {
      EXPECT_NEAR(boxes_a[i].cx, boxes_b[i].cx, 1e-3f);
      EXPECT_NEAR(boxes_a[i].w, boxes_b[i].w, 1e-3f);
      EXPECT_NEAR(boxes_a[i].drone_score, boxes_b[i].drone_score, 1e-5f);
      if (boxes_b[i].class_id == 0) {
        EXPECT_NEAR(boxes_a[i].confidence, boxes_b[i].confidence, 1e-5f);
      }
      EXPECT_EQ(boxes_a[i].class_id, 0);
    }
    off_a += static_cast<size_t>(s.c) * plane;
    off_b += static_cast<size_t>(wide_head.input.c) * plane;
  }
  EXPECT_EQ(off_a, a.size());
  EXPECT_EQ(off_b, b.size());
}

TEST(ClassWidening, RefusesWhatCannotGrow) {
  DarknetModel narrow = parse_darknet_cfg_string(two_heads(2), "two-class.cfg");
  randomize_weights(narrow, 3);
  EXPECT_THROW(widen_classes(narrow, 0), std::invalid_argument);
  EXPECT_THROW(widen_classes(narrow, 2, std::nanf("")), std::invalid_argument);
  try {
    widen_classes(narrow, 1);  // fewer classes than the heads have
    FAIL() << "narrowing was accepted";
  } catch (const DarknetFormatError& e) {
    EXPECT_NE(std::string(e.what()).find("two-class.cfg"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("would drop classes"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(widen_classes(narrow, 2));  // the same count: a copy

  DarknetModel routed = parse_darknet_cfg_string(two_heads(1, true), "routed.cfg");
  randomize_weights(routed, 3);
  try {
    widen_classes(routed, 4);
    FAIL() << "a head convolution read by a [route] was widened";
  } catch (const DarknetFormatError& e) {
    EXPECT_NE(std::string(e.what()).find("[route]"), std::string::npos) << e.what();
  }

  DarknetModel unloaded = parse_darknet_cfg_string(two_heads(1), "unloaded.cfg");
  EXPECT_THROW(widen_classes(unloaded, 4), DarknetFormatError);

  DarknetModel region = parse_darknet_cfg_string(
      "[net]\nwidth=64\nheight=64\nchannels=3\n\n[convolutional]\nfilters=30\nsize=1\nstride=1\npad=1\n"
      "activation=linear\n\n[region]\nanchors=1,1, 2,2, 3,3, 4,4, 5,5\nclasses=1\nnum=5\n\n",
      "region.cfg");
  randomize_weights(region, 1);
  EXPECT_THROW(widen_classes(region, 4), DarknetFormatError);
}

}  // namespace
}  // namespace wingman::detector
