// SPDX-License-Identifier: MIT
// Darknet .cfg / .weights: thesis network shapes and FLOPs, round trips, and errors that name the problem.
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>

#include "test_support.hpp"
#include "thesis_model.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <functional>

namespace wingman::detector {
namespace {

using test::thesis;

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const DarknetFormatError& e) {
    return e.what();
  }
  return "(no DarknetFormatError)";
}

TEST(DarknetCfg, ThesisNetworkShapes) {
  const DarknetModel m = thesis();
  ASSERT_EQ(m.layers.size(), 16u);
  EXPECT_EQ(m.net.width, 416);
  EXPECT_EQ(m.net.height, 416);
  EXPECT_EQ(m.net.channels, 3);
  EXPECT_EQ(m.layers[0].output, (Shape{16, 416, 416}));
  EXPECT_EQ(m.layers[1].output, (Shape{16, 208, 208}));
  EXPECT_EQ(m.layers[9].output, (Shape{256, 13, 13}));
  // Maxpool size 2 stride 1 with Darknet's padding keeps 13 x 13.
  EXPECT_EQ(m.layers[11].type, LayerType::kMaxpool);
  EXPECT_EQ(m.layers[11].pool_padding, 1);
  EXPECT_EQ(m.layers[11].output, (Shape{512, 13, 13}));
  EXPECT_EQ(m.layers[14].output, (Shape{30, 13, 13}));
  EXPECT_EQ(m.layers[14].activation, Activation::kLinear);
  EXPECT_FALSE(m.layers[14].batch_normalize);
  const Layer& region = m.layers[15];
  EXPECT_EQ(region.type, LayerType::kRegion);
  EXPECT_EQ(region.num, 5);
  EXPECT_EQ(region.classes, 1);
  ASSERT_EQ(region.anchors.size(), 10u);
  EXPECT_FLOAT_EQ(region.anchors[4], 6.63f);
  EXPECT_EQ(m.net.other.at("batch"), "64");
  EXPECT_EQ(m.net.other.at("subdivisions"), "8");
  EXPECT_EQ(m.net.other.at("learning_rate"), "0.001");
}

TEST(DarknetCfg, ThesisFlopsAre6Point94Giga) {
  // The thesis quotes 6.94 GFLOP per 416 x 416 frame (Darknet's count: 2 x multiply-adds of the convolutions).
  EXPECT_NEAR(thesis().flops() / 1e9, 6.94, 0.005);
}

TEST(DarknetCfg, ThesisWeightCount) {
  const DarknetModel m = thesis();
  int64_t expected = 0;
  int c = 3;
  for (int f : {16, 32, 64, 128, 256, 512, 1024, 1024}) {
    expected += 4 * f + static_cast<int64_t>(f) * c * 9;
    c = f;
  }
  expected += 30 + 30 * 1024;
  EXPECT_EQ(m.weight_count(), expected);
}

TEST(DarknetCfg, WriteThenParseRoundTrips) {
  const DarknetModel a = thesis();
  const std::string text = write_darknet_cfg(a);
  const DarknetModel b = parse_darknet_cfg_string(text, "written.cfg");
  EXPECT_EQ(write_darknet_cfg(b), text);
  ASSERT_EQ(a.layers.size(), b.layers.size());
  for (size_t i = 0; i < a.layers.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(a.layers[i].type, b.layers[i].type);
    EXPECT_EQ(a.layers[i].input, b.layers[i].input);
    EXPECT_EQ(a.layers[i].output, b.layers[i].output);
    EXPECT_EQ(a.layers[i].anchors, b.layers[i].anchors);
    EXPECT_EQ(a.layers[i].padding, b.layers[i].padding);
    EXPECT_EQ(a.layers[i].activation, b.layers[i].activation);
  }
  EXPECT_EQ(a.net.other, b.net.other);
}

TEST(DarknetCfg, ModernTinyLayersRouteUpsampleYolo) {
  // Odd sizes on purpose: 45 x 37 input.
  const std::string cfg = R"([net]
width=45
height=37
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
filters=18
size=1
stride=1
pad=1
activation=linear
[yolo]
mask=0,1,2
anchors=10,14, 23,27, 37,58
classes=1
num=3
[route]
layers=-3
[upsample]
stride=2
[route]
layers=-2,1
)";
  const DarknetModel m = parse_darknet_cfg_string(cfg, "tiny.cfg");
  ASSERT_EQ(m.layers.size(), 7u);
  EXPECT_EQ(m.layers[0].output, (Shape{8, 19, 23}));  // (37 + 2 - 3) / 2 + 1 = 19, (45 + 2 - 3) / 2 + 1 = 23
  EXPECT_EQ(m.layers[1].output, (Shape{8, 10, 12}));  // (19 + 1 - 2) / 2 + 1 = 10, (23 + 1 - 2) / 2 + 1 = 12
  EXPECT_EQ(m.layers[2].output, (Shape{18, 10, 12}));
  EXPECT_EQ(m.layers[3].num, 3);
  EXPECT_EQ(m.layers[4].route_layers, std::vector<int>{1});
  EXPECT_EQ(m.layers[5].output, (Shape{8, 20, 24}));
  EXPECT_EQ(m.layers[6].output, (Shape{16, 10, 12}));
  EXPECT_EQ(parse_darknet_cfg_string(write_darknet_cfg(m)).layers[6].route_layers, (std::vector<int>{4, 1}));
}

TEST(DarknetCfg, HeadTrainingKeysRoundTrip) {
  // The thesis [region]: object_scale=5 noobject_scale=1 class_scale=1 coord_scale=1 rescore=1 bias_match=1
  // absolute=1 thresh=.6 jitter=.2 random=1.
  const DarknetModel a = thesis();
  const Layer& r = a.layers.back();
  EXPECT_FLOAT_EQ(r.object_scale, 5.0f);
  EXPECT_FLOAT_EQ(r.noobject_scale, 1.0f);
  EXPECT_EQ(r.rescore, 1);
  EXPECT_EQ(r.bias_match, 1);
  EXPECT_EQ(r.absolute, 1);
  EXPECT_FLOAT_EQ(r.thresh, 0.6f);
  EXPECT_FLOAT_EQ(r.random, 1.0f);
  // Values away from every default, on a [region] and a [yolo], survive write -> read.
  const std::string cfg =
      "[net]\nwidth=64\nheight=64\n[convolutional]\nfilters=18\nsize=1\n[region]\nanchors=1,2\nnum=1\n"
      "classes=13\nobject_scale=4.5\nnoobject_scale=0.25\nclass_scale=2\ncoord_scale=3\nrescore=1\n"
      "bias_match=1\nabsolute=1\nthresh=.7\njitter=.3\nrandom=1\n"
      "[convolutional]\nfilters=18\nsize=1\n[yolo]\nmask=1,2,3\nanchors=1,2,3,4,5,6,7,8\nclasses=1\n"
      "scale_x_y=1.05\nignore_thresh=.7\ntruth_thresh=.9\njitter=.1\nrandom=1.5\niou_loss=ciou\niou_normalizer=0.5\n";
  const DarknetModel m = parse_darknet_cfg_string(cfg, "keys.cfg");
  const DarknetModel n = parse_darknet_cfg_string(write_darknet_cfg(m), "written.cfg");
  for (const DarknetModel* x : {&m, &n}) {
    SCOPED_TRACE(x == &m ? "read" : "written and read back");
    const Layer& region = x->layers[1];
    EXPECT_FLOAT_EQ(region.object_scale, 4.5f);
    EXPECT_FLOAT_EQ(region.noobject_scale, 0.25f);
    EXPECT_FLOAT_EQ(region.class_scale, 2.0f);
    EXPECT_FLOAT_EQ(region.coord_scale, 3.0f);
    EXPECT_EQ(region.rescore, 1);
    EXPECT_EQ(region.bias_match, 1);
    EXPECT_EQ(region.absolute, 1);
    EXPECT_FLOAT_EQ(region.thresh, 0.7f);
    EXPECT_FLOAT_EQ(region.jitter, 0.3f);
    EXPECT_FLOAT_EQ(region.random, 1.0f);
    const Layer& yolo = x->layers[3];
    EXPECT_EQ(yolo.mask, (std::vector<int>{1, 2, 3}));
    EXPECT_FLOAT_EQ(yolo.scale_x_y, 1.05f);
    EXPECT_FLOAT_EQ(yolo.ignore_thresh, 0.7f);
    EXPECT_FLOAT_EQ(yolo.truth_thresh, 0.9f);
    EXPECT_FLOAT_EQ(yolo.jitter, 0.1f);
    EXPECT_FLOAT_EQ(yolo.random, 1.5f);
    EXPECT_EQ(yolo.iou_loss, "ciou");
    EXPECT_FLOAT_EQ(yolo.iou_normalizer, 0.5f);
  }
  // Without the keys: YOLOv3's squared error (and AlexeyAB Darknet's normalizer default), and none written.
  const DarknetModel plain = parse_darknet_cfg_string(
      "[net]\n[convolutional]\nfilters=6\nsize=1\n[yolo]\nanchors=1,1\nmask=0\nclasses=1\n", "plain.cfg");
  EXPECT_EQ(plain.layers[1].iou_loss, "mse");
  EXPECT_FLOAT_EQ(plain.layers[1].iou_normalizer, 0.75f);
  EXPECT_EQ(write_darknet_cfg(plain).find("iou_"), std::string::npos);
  // An unknown box loss, or a normalizer that is not positive, names the key and what is expected.
  const std::string loss = message_of([] {
    parse_darknet_cfg_string("[net]\n[convolutional]\nfilters=6\n[yolo]\nanchors=1,1\nmask=0\niou_loss=eiou\n",
                             "l.cfg");
  });
  EXPECT_NE(loss.find("l.cfg:7"), std::string::npos) << loss;
  EXPECT_NE(loss.find("'iou_loss' = 'eiou': expected mse, giou, diou or ciou"), std::string::npos) << loss;
  const std::string norm = message_of([] {
    parse_darknet_cfg_string(
        "[net]\n[convolutional]\nfilters=6\n[yolo]\nanchors=1,1\nmask=0\niou_loss=giou\niou_normalizer=0\n", "n.cfg");
  });
  EXPECT_NE(norm.find("iou_normalizer"), std::string::npos) << norm;
  // A bad number names the key, and scale_x_y below 1 is refused.
  const std::string bad = message_of([] {
    parse_darknet_cfg_string("[net]\n[convolutional]\nfilters=6\n[region]\nanchors=1,1\nnum=1\nobject_scale=x\n",
                             "o.cfg");
  });
  EXPECT_NE(bad.find("o.cfg:7"), std::string::npos) << bad;
  EXPECT_NE(bad.find("object_scale"), std::string::npos) << bad;
  const std::string low = message_of([] {
    parse_darknet_cfg_string("[net]\n[convolutional]\nfilters=6\n[yolo]\nanchors=1,1\nmask=0\nscale_x_y=0.5\n",
                             "y.cfg");
  });
  EXPECT_NE(low.find("scale_x_y"), std::string::npos) << low;
}

TEST(DarknetCfg, UnsupportedKeyNamesFileLineAndKey) {
  const std::string cfg = "[net]\nwidth=32\nheight=32\n\n[convolutional]\nfilters=4\nsize=3\ndilation=2\n";
  const std::string msg = message_of([&] { parse_darknet_cfg_string(cfg, "bad.cfg"); });
  EXPECT_NE(msg.find("bad.cfg:8"), std::string::npos) << msg;
  EXPECT_NE(msg.find("dilation"), std::string::npos) << msg;
}

TEST(DarknetCfg, UnsupportedSectionAndBadValueAreErrors) {
  EXPECT_NE(message_of([] { parse_darknet_cfg_string("[net]\n[shortcut]\nfrom=-3\n", "s.cfg"); }).find("s.cfg:2"),
            std::string::npos);
  const std::string msg =
      message_of([] { parse_darknet_cfg_string("[net]\n[convolutional]\nfilters=4\nactivation=mish\n", "a.cfg"); });
  EXPECT_NE(msg.find("a.cfg:4"), std::string::npos) << msg;
  EXPECT_NE(msg.find("mish"), std::string::npos) << msg;
  // A region whose input channels do not match num x (5 + classes).
  const std::string region = message_of([] {
    parse_darknet_cfg_string("[net]\nwidth=32\nheight=32\n[convolutional]\nfilters=29\n[region]\nanchors=1,1\nnum=1\n",
                             "r.cfg");
  });
  EXPECT_NE(region.find("r.cfg:6"), std::string::npos) << region;
}

TEST(DarknetWeights, WriteThenReadIsBitIdentical) {
  testing::TempDir dir;
  DarknetModel a = thesis();
  a.seen = 123456789012ull;
  randomize_weights(a, 7);
  save_darknet_weights(a, dir.file("w.weights"));
  DarknetModel b = thesis();
  load_darknet_weights(b, dir.file("w.weights"));
  EXPECT_EQ(b.seen, a.seen);
  EXPECT_EQ(b.major, a.major);
  EXPECT_EQ(b.minor, a.minor);
  for (size_t i = 0; i < a.layers.size(); ++i) {
    SCOPED_TRACE(i);
    const Layer& x = a.layers[i];
    const Layer& y = b.layers[i];
    for (auto [p, q] : {std::pair{&x.biases, &y.biases},
                        {&x.scales, &y.scales},
                        {&x.rolling_mean, &y.rolling_mean},
                        {&x.rolling_variance, &y.rolling_variance},
                        {&x.weights, &y.weights}}) {
      ASSERT_EQ(p->size(), q->size());
      if (p->empty()) continue;  // no data(): memcmp must not see a null pointer even for 0 bytes
      EXPECT_EQ(std::memcmp(p->data(), q->data(), p->size() * 4), 0);
    }
  }
  EXPECT_EQ(serialize_darknet_weights(a), serialize_darknet_weights(b));
  std::ifstream f(dir.file("w.weights"), std::ios::binary | std::ios::ate);
  EXPECT_EQ(static_cast<int64_t>(f.tellg()), 20 + 4 * a.weight_count());
}

TEST(DarknetWeights, OldHeaderHas32BitSeen) {
  DarknetModel m = parse_darknet_cfg_string("[net]\nwidth=9\nheight=7\n[convolutional]\nfilters=3\nsize=3\n");
  m.major = 0;
  m.minor = 1;
  m.seen = 77;
  randomize_weights(m, 3);
  const std::vector<char> bytes = serialize_darknet_weights(m);
  EXPECT_EQ(static_cast<int64_t>(bytes.size()), 16 + 4 * m.weight_count());
  DarknetModel n = parse_darknet_cfg_string("[net]\nwidth=9\nheight=7\n[convolutional]\nfilters=3\nsize=3\n");
  load_darknet_weights_from_buffer(n, bytes, "old.weights");
  EXPECT_EQ(n.seen, 77u);
  EXPECT_EQ(n.layers[0].weights, m.layers[0].weights);
}

TEST(DarknetWeights, WrongLengthNamesExpectedAndActualSize) {
  testing::TempDir dir;
  DarknetModel a = thesis();
  randomize_weights(a, 1);
  std::vector<char> bytes = serialize_darknet_weights(a);
  const size_t expected = bytes.size();
  bytes.resize(bytes.size() - 8);
  {
    std::ofstream out(dir.file("short.weights"), std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  DarknetModel b = thesis();
  const std::string msg = message_of([&] { load_darknet_weights(b, dir.file("short.weights")); });
  EXPECT_NE(msg.find("short.weights"), std::string::npos) << msg;
  EXPECT_NE(msg.find("expected " + std::to_string(expected) + " bytes"), std::string::npos) << msg;
  EXPECT_NE(msg.find("got " + std::to_string(expected - 8) + " bytes"), std::string::npos) << msg;
}

// Issue 33, finding 5: a 1 KB .cfg with 11 KB of weights allocated many GB; a .weights file was read whole before its
// length was compared.
TEST(DarknetBounds, ANetworkNeedingMoreThanAGibibyteIsRefusedAtParseNamingTheLayer) {
  // 16 x 8192 x 8192 = 2^30 values in the first layer's output: over the 2^28 bound, under the per-layer one.
  const std::string huge = "[net]\nwidth=8192\nheight=8192\n[convolutional]\nfilters=16\nsize=1\n";
  const std::string msg = message_of([&] { parse_darknet_cfg_string(huge, "huge.cfg"); });
  EXPECT_NE(msg.find("huge.cfg:4: [convolutional] (layer 0) the layers up to this one output 1073741824 values in "
                     "all: more than 268435456"),
            std::string::npos)
      << msg;
  // The shipped size of network parses.
  EXPECT_NO_THROW(
      parse_darknet_cfg_string("[net]\nwidth=640\nheight=352\n[convolutional]\nfilters=16\nsize=3\n", "ok.cfg"));
}

TEST(DarknetBounds, AWeightsFileLargerThanTheNetworkCanHoldIsRefusedBeforeItIsRead) {
  testing::TempDir dir;
  DarknetModel m = parse_darknet_cfg_string(
      "[net]\nwidth=16\nheight=16\n[convolutional]\nbatch_normalize=1\nfilters=4\nsize=3\n", "small.cfg");
  {
    std::ofstream out(dir.file("big.weights"), std::ios::binary);
    out.seekp(64 * 1024 * 1024 - 1);  // 64 MiB, sparse: nothing is allocated by the test either
    out.put('\0');
  }
  std::string msg = message_of([&] { load_darknet_weights(m, dir.file("big.weights")); });
  EXPECT_NE(msg.find("big.weights: 67108864 bytes: larger than any .weights file of small.cfg can be (516 bytes"),
            std::string::npos)
      << msg;
  msg = message_of([&] { load_darknet_weights(m, dir.path()); });
  EXPECT_NE(msg.find(": not a regular file"), std::string::npos) << msg;
  msg = message_of([&] { load_darknet_weights(m, "/dev/zero"); });
  EXPECT_NE(msg.find("/dev/zero: not a regular file"), std::string::npos) << msg;
}

/// A two-layer network and the same with two layers appended (a [maxpool] and a second [convolutional]).
const char* kBase =
    "[net]\nwidth=16\nheight=16\n[convolutional]\nbatch_normalize=1\nfilters=4\nsize=3\n"
    "[convolutional]\nfilters=6\nsize=1\n";
const char* kExtension = "[maxpool]\nsize=2\nstride=2\n[convolutional]\nbatch_normalize=1\nfilters=5\nsize=3\n";

void write_bytes(const std::string& path, const std::vector<char>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

TEST(DarknetWeights, PrefixLoadsTheLayersAFileHoldsAndLeavesTheRest) {
  testing::TempDir dir;
  DarknetModel base = parse_darknet_cfg_string(kBase, "base.cfg");
  base.seen = 4242;
  randomize_weights(base, 11);
  save_darknet_weights(base, dir.file("base.weights"));

  DarknetModel grown = parse_darknet_cfg_string(std::string(kBase) + kExtension, "grown.cfg");
  randomize_weights(grown, 12);
  const std::vector<float> appended = grown.layers[3].weights;
  ASSERT_EQ(load_darknet_weights_prefix(grown, dir.file("base.weights")), 2);
  EXPECT_EQ(grown.seen, 4242u);
  EXPECT_EQ(grown.layers[0].weights, base.layers[0].weights);
  EXPECT_EQ(grown.layers[0].rolling_variance, base.layers[0].rolling_variance);
  EXPECT_EQ(grown.layers[1].biases, base.layers[1].biases);
  EXPECT_EQ(grown.layers[1].weights, base.layers[1].weights);
  EXPECT_EQ(grown.layers[3].weights, appended);  // untouched
  // The strict reader refuses the same file, and a whole-network file loads completely with the prefix reader.
  DarknetModel strict = parse_darknet_cfg_string(std::string(kBase) + kExtension, "grown.cfg");
  EXPECT_NE(message_of([&] { load_darknet_weights(strict, dir.file("base.weights")); }).find("wrong .weights length"),
            std::string::npos);
  save_darknet_weights(grown, dir.file("grown.weights"));
  DarknetModel again = parse_darknet_cfg_string(std::string(kBase) + kExtension, "grown.cfg");
  EXPECT_EQ(load_darknet_weights_prefix(again, dir.file("grown.weights")), 3);
  EXPECT_EQ(again.layers[3].weights, appended);
}

TEST(DarknetWeights, PrefixRefusesPartLayersLongerFilesAndHeadersAlone) {
  testing::TempDir dir;
  DarknetModel base = parse_darknet_cfg_string(kBase, "base.cfg");
  randomize_weights(base, 13);
  const std::vector<char> whole = serialize_darknet_weights(base);
  DarknetModel grown = parse_darknet_cfg_string(std::string(kBase) + kExtension, "grown.cfg");
  // Cut inside layer 1: the error names the file, its size and the layers that fit.
  std::vector<char> cut(whole.begin(), whole.end() - 8);
  write_bytes(dir.file("cut.weights"), cut);
  std::string msg = message_of([&] { load_darknet_weights_prefix(grown, dir.file("cut.weights")); });
  EXPECT_NE(msg.find("cut.weights: " + std::to_string(cut.size()) + " bytes"), std::string::npos) << msg;
  EXPECT_NE(msg.find("the first 1 fit in"), std::string::npos) << msg;
  // A header with no layer.
  write_bytes(dir.file("header.weights"), std::vector<char>(whole.begin(), whole.begin() + 20));
  EXPECT_NE(message_of([&] { load_darknet_weights_prefix(grown, dir.file("header.weights")); }).find("header.weights"),
            std::string::npos);
  // Longer than the whole network.
  std::vector<char> longer = serialize_darknet_weights([&] {
    DarknetModel g = parse_darknet_cfg_string(std::string(kBase) + kExtension, "grown.cfg");
    randomize_weights(g, 14);
    return g;
  }());
  longer.resize(longer.size() + 4);
  write_bytes(dir.file("long.weights"), longer);
  msg = message_of([&] { load_darknet_weights_prefix(grown, dir.file("long.weights")); });
  EXPECT_NE(msg.find("long.weights"), std::string::npos) << msg;
  EXPECT_NE(msg.find("the first 3 fit in"), std::string::npos) << msg;
  EXPECT_NE(message_of([&] {
              load_darknet_weights_prefix(grown, dir.file("missing.weights"));
            }).find("missing.weights: cannot open"),
            std::string::npos);
}

TEST(DarknetWeights, RandomizeIsDeterministicAndRealistic) {
  DarknetModel a = thesis();
  DarknetModel b = thesis();
  randomize_weights(a, 42);
  randomize_weights(b, 42);
  EXPECT_EQ(serialize_darknet_weights(a), serialize_darknet_weights(b));
  for (const Layer& l : a.layers) {
    if (l.type != LayerType::kConvolutional) continue;
    for (float v : l.rolling_variance) EXPECT_GT(v, 0.0f);
    for (float g : l.scales) EXPECT_NEAR(g, 1.0f, 0.21f);
  }
  EXPECT_THROW(serialize_darknet_weights(thesis()), DarknetFormatError);  // never loaded
}

}  // namespace
}  // namespace wingman::detector
