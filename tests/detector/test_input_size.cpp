// SPDX-License-Identifier: MIT
// model.input_size: parsing, auto's fitting rule, and SizedDetector building one real (CPU backend) pipeline per
// input size, checked against a DetectionPipeline built by hand at that size.
#include <wingman/detector/cpu_backend.hpp>
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>
#include <wingman/detector/detector_options.hpp>
#include <wingman/detector/input_size.hpp>
#include <wingman/detector/sized_detector.hpp>

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

namespace wingman::detector {
namespace {

TEST(InputSize, ParsesAutoCfgAndSizes) {
  ASSERT_TRUE(InputSize::parse("auto"));
  EXPECT_EQ(InputSize::parse("auto")->mode, InputSize::Mode::kAuto);
  EXPECT_EQ(InputSize::parse("cfg")->mode, InputSize::Mode::kCfg);
  const auto fixed = InputSize::parse("640x512");
  ASSERT_TRUE(fixed);
  EXPECT_EQ(fixed->mode, InputSize::Mode::kFixed);
  EXPECT_EQ(fixed->fixed, cv::Size(640, 512));
  EXPECT_EQ(fixed->to_string(), "640x512");
  EXPECT_EQ(InputSize::parse("auto")->to_string(), "auto");
  EXPECT_EQ(InputSize::parse("cfg")->to_string(), "cfg");
  EXPECT_EQ(InputSize::parse("32x4096")->fixed, cv::Size(32, 4096));
}

TEST(InputSize, RejectsOtherTextSayingWhatWasExpected) {
  for (const std::string bad : {"", "Auto", "640", "641x512", "640x500", "0x32", "-32x32", "640x512x3", "x512", "640x",
                                "4128x32", "640 x 512", "+64x64", "1e3x32"}) {
    std::string error;
    EXPECT_FALSE(InputSize::parse(bad, &error)) << bad;
    EXPECT_NE(error.find("'" + bad + "': expected auto, cfg or WxH"), std::string::npos) << error;
  }
  EXPECT_FALSE(InputSize::parse("nope"));  // no error string asked for
}

TEST(InputSize, FitKeepsTheLongerSideAndFollowsTheAspect) {
  const cv::Size cfg(640, 352);
  EXPECT_EQ(fit_input_size(cfg, {1280, 720}), cv::Size(640, 352));  // 360 rounds to 352
  EXPECT_EQ(fit_input_size(cfg, {640, 512}), cv::Size(640, 512));   // Halmstad's frames, unsqueezed
  EXPECT_EQ(fit_input_size(cfg, {720, 720}), cv::Size(640, 640));   // a subsquare region
  EXPECT_EQ(fit_input_size(cfg, {720, 1280}), cv::Size(352, 640));  // portrait
  EXPECT_EQ(fit_input_size(cfg, {1920, 1080}), cv::Size(640, 352));
  EXPECT_EQ(fit_input_size(cfg, {10000, 10}), cv::Size(640, 32));          // never below 32
  EXPECT_EQ(fit_input_size({416, 416}, {1280, 720}), cv::Size(416, 224));  // 234 rounds to 224
  EXPECT_EQ(fit_input_size({352, 640}, {1280, 720}), cv::Size(640, 352));  // the longer side, whichever it is
  EXPECT_THROW(fit_input_size(cfg, {0, 720}), std::invalid_argument);
  EXPECT_THROW(fit_input_size({0, 352}, {1280, 720}), std::invalid_argument);
}

TEST(InputSize, DetectorOptionsNameABadValue) {
  DetectorOptions o;
  EXPECT_EQ(o.input_size, "auto");
  EXPECT_TRUE(o.validate().empty());
  o.input_size = "640x500";
  const std::vector<std::string> p = o.validate();
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NE(p[0].find("model.input_size"), std::string::npos) << p[0];
  EXPECT_NE(p[0].find("640x500"), std::string::npos) << p[0];
}

/// A two-head tiny network at 128 x 64 (stride-32 head, then a stride-16 one), random weights.
DarknetModel small_two_head_model() {
  const std::string yolo =
      "[yolo]\nmask={}\nanchors=4,3, 6,5, 9,8, 13,13, 21,16, 34,27\nclasses=1\nnum=6\nignore_thresh=.7\n\n";
  auto head = [&](const char* mask) {
    std::string s = yolo;
    s.replace(s.find("{}"), 2, mask);
    return s;
  };
  const std::string conv =
      "[convolutional]\nbatch_normalize=1\nfilters=8\nsize=3\nstride=1\npad=1\nactivation=leaky\n\n";
  const std::string out = "[convolutional]\nfilters=18\nsize=1\nstride=1\npad=1\nactivation=linear\n\n";
  const std::string pool = "[maxpool]\nsize=2\nstride=2\n\n";
  const std::string cfg = "[net]\nwidth=128\nheight=64\nchannels=3\n\n" + conv + pool + pool + pool + pool +  // 0-4
                          conv + pool + out + head("3,4,5") +                                                 // 5-8
                          "[route]\nlayers=-4\n\n[route]\nlayers=-1\n\n" + out + head("0,1,2");               // 9-12
  DarknetModel m = parse_darknet_cfg_string(cfg, "small-two-head.cfg");
  randomize_weights(m, 21);
  return m;
}

/// DetectionPipeline built by hand at `net`: the reference SizedDetector must match.
std::vector<Box> reference_detect(const DarknetModel& model, const DetectorPipelineOptions& o, cv::Size net,
                                  const cv::Mat& image) {
  DarknetModel sized = model;
  sized.net.width = net.width;
  sized.net.height = net.height;
  compute_shapes(sized);
  DetectionPipeline p(o, std::make_unique<CpuBackend>(sized, 1), sized);
  return p.detect(image);
}

cv::Mat noise(int width, int height, int seed) {
  cv::Mat img(height, width, CV_8UC3);
  cv::RNG rng(static_cast<uint64_t>(seed));
  rng.fill(img, cv::RNG::UNIFORM, 0, 255);
  return img;
}

DetectorPipelineOptions keep_many() {
  DetectorPipelineOptions o;
  o.p_thresh = 0.0;  // random weights: keep the most confident 50 of every cell and anchor
  o.max_detections = 50;
  return o;
}

TEST(SizedDetector, AutoBuildsOnePipelinePerAspectAndMatchesAHandBuiltOne) {
  const DarknetModel model = small_two_head_model();
  std::vector<std::pair<cv::Size, cv::Size>> built;  // (net, image)
  SizedDetector d(
      keep_many(), model, *InputSize::parse("auto"),
      [](const DarknetModel& m) { return std::make_unique<CpuBackend>(m, 1); },
      [&](cv::Size net, cv::Size image) { built.emplace_back(net, image); });
  ASSERT_EQ(d.builds(), 1);  // the cfg's size, at construction
  ASSERT_EQ(built.size(), 1u);
  EXPECT_EQ(built[0].first, cv::Size(128, 64));
  EXPECT_TRUE(built[0].second.empty());

  const cv::Mat wide = noise(1280, 720, 1);  // 128 x 72 -> the cfg's 128 x 64: no new build
  const cv::Mat tall4 = noise(640, 512, 2);  // 128 x 102 -> 128 x 96
  EXPECT_EQ(d.net_size_for(wide.size()), cv::Size(128, 64));
  EXPECT_EQ(d.net_size_for(tall4.size()), cv::Size(128, 96));

  const std::vector<Box> wide_boxes = d.detect(wide);
  EXPECT_EQ(d.builds(), 1);
  const std::vector<Box> tall_boxes = d.detect(tall4);
  EXPECT_EQ(d.builds(), 2);
  ASSERT_EQ(built.size(), 2u);
  EXPECT_EQ(built[1].first, cv::Size(128, 96));
  EXPECT_EQ(built[1].second, cv::Size(640, 512));
  EXPECT_EQ(d.pipeline_for(tall4.size()).backend().input_shape(), (Shape{3, 96, 128}));

  // The same boxes as a pipeline built by hand at those sizes; 50 each.
  for (const auto& [img, boxes, net] :
       {std::tuple{&wide, &wide_boxes, cv::Size(128, 64)}, std::tuple{&tall4, &tall_boxes, cv::Size(128, 96)}}) {
    const std::vector<Box> want = reference_detect(model, keep_many(), net, *img);
    ASSERT_EQ(boxes->size(), want.size());
    EXPECT_FALSE(want.empty());
    for (size_t i = 0; i < want.size(); ++i) {
      EXPECT_FLOAT_EQ((*boxes)[i].cx, want[i].cx);
      EXPECT_FLOAT_EQ((*boxes)[i].cy, want[i].cy);
      EXPECT_FLOAT_EQ((*boxes)[i].w, want[i].w);
      EXPECT_FLOAT_EQ((*boxes)[i].h, want[i].h);
      EXPECT_FLOAT_EQ((*boxes)[i].confidence, want[i].confidence);
    }
  }
  // Alternating sizes reuse the kept pipelines.
  d.detect(wide);
  d.detect(tall4);
  EXPECT_EQ(d.builds(), 2);
}

TEST(SizedDetector, CoarsePassBuildsItsBackendAtHalfTheInputAndMatchesAHandBuiltPipeline) {
  const DarknetModel model = small_two_head_model();
  DetectorPipelineOptions o = keep_many();
  o.coarse_pass = true;
  o.coarse_min_size = 0;           // random weights: keep the coarse boxes of every size
  std::vector<cv::Size> backends;  // the network input of every backend made
  SizedDetector d(o, model, *InputSize::parse("auto"), [&](const DarknetModel& m) {
    backends.emplace_back(m.net.width, m.net.height);
    return std::make_unique<CpuBackend>(m, 1);
  });
  // The coarse backend first (the nested pipeline is built before the one holding it), at 64 x 32.
  EXPECT_EQ(backends, (std::vector<cv::Size>{{64, 32}, {128, 64}}));
  EXPECT_EQ(d.builds(), 1);
  const cv::Mat wide = noise(1280, 720, 3);
  DetectionPipeline& p = d.pipeline_for(wide.size());
  ASSERT_NE(p.coarse(), nullptr);
  EXPECT_EQ(p.coarse()->backend().input_shape(), (Shape{3, 32, 64}));
  EXPECT_FALSE(p.coarse()->options().coarse_pass);
  const std::vector<Box> boxes = d.detect(wide);

  DarknetModel coarse_model = model;
  coarse_model.net.width = 64;
  coarse_model.net.height = 32;
  compute_shapes(coarse_model);
  DetectionPipeline reference(o, std::make_unique<CpuBackend>(model, 1), model,
                              std::make_unique<DetectionPipeline>(
                                  coarse_pass_options(o), std::make_unique<CpuBackend>(coarse_model, 1), coarse_model));
  const std::vector<Box> want = reference.detect(wide);
  ASSERT_EQ(boxes.size(), want.size());
  EXPECT_FALSE(want.empty());
  for (size_t i = 0; i < want.size(); ++i) {
    EXPECT_FLOAT_EQ(boxes[i].cx, want[i].cx);
    EXPECT_FLOAT_EQ(boxes[i].w, want[i].w);
    EXPECT_FLOAT_EQ(boxes[i].confidence, want[i].confidence);
  }
  // Not the full-size pass alone: the coarse boxes joined and halved the confidences of the boxes one pass found.
  const std::vector<Box> alone = reference_detect(model, keep_many(), {128, 64}, wide);
  bool differs = alone.size() != want.size();
  for (size_t i = 0; !differs && i < want.size(); ++i) differs = alone[i].confidence != want[i].confidence;
  EXPECT_TRUE(differs);
}

TEST(SizedDetector, KeepsTheLastFewSizesAndRebuildsAnEvictedOne) {
  SizedDetector d(keep_many(), small_two_head_model(), *InputSize::parse("auto"),
                  [](const DarknetModel& m) { return std::make_unique<CpuBackend>(m, 1); });
  // 128x64 (construction), then 128x96, 128x128, 96x128, 64x128: five sizes, four kept.
  for (const cv::Size image : {cv::Size(640, 512), cv::Size(300, 300), cv::Size(480, 640), cv::Size(360, 720)})
    d.detect(noise(image.width, image.height, 3));
  EXPECT_EQ(d.builds(), 5);
  d.detect(noise(640, 512, 4));  // still kept
  EXPECT_EQ(d.builds(), 5);
  d.detect(noise(1280, 720, 5));  // 128x64 was the least recently used: evicted, rebuilt
  EXPECT_EQ(d.builds(), 6);
}

TEST(SizedDetector, CfgAndFixedSizesIgnoreTheImagesAspect) {
  auto cpu = [](const DarknetModel& m) { return std::make_unique<CpuBackend>(m, 1); };
  SizedDetector cfg(keep_many(), small_two_head_model(), *InputSize::parse("cfg"), cpu);
  cfg.detect(noise(640, 512, 6));
  cfg.detect(noise(300, 600, 7));
  EXPECT_EQ(cfg.builds(), 1);
  EXPECT_EQ(cfg.pipeline_for({640, 512}).backend().input_shape(), (Shape{3, 64, 128}));

  SizedDetector fixed(keep_many(), small_two_head_model(), *InputSize::parse("64x64"), cpu);
  EXPECT_EQ(fixed.pipeline_for({1280, 720}).backend().input_shape(), (Shape{3, 64, 64}));
  fixed.detect(noise(640, 512, 8));
  EXPECT_EQ(fixed.builds(), 1);

  // subsquare: auto fits the square region, not the whole frame.
  DetectorPipelineOptions square = keep_many();
  square.subsquare = true;
  SizedDetector sub(square, small_two_head_model(), *InputSize::parse("auto"), cpu);
  EXPECT_EQ(sub.net_size_for({1280, 720}), cv::Size(128, 128));
}

TEST(SizedDetector, RejectsBadImagesAndAnEmptyFactory) {
  SizedDetector d(keep_many(), small_two_head_model(), *InputSize::parse("auto"),
                  [](const DarknetModel& m) { return std::make_unique<CpuBackend>(m, 1); });
  EXPECT_THROW(d.detect(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(d.detect(cv::Mat(10, 10, CV_8UC1)), std::invalid_argument);
  EXPECT_THROW(SizedDetector(keep_many(), small_two_head_model(), *InputSize::parse("auto"), {}),
               std::invalid_argument);
}

// Issue 33, finding 6: input.max_image_width: 2147483647 was accepted and overflowed the byte limit.
TEST(InputSize, DetectorOptionsRefuseImageLimitsThatWouldOverflow) {
  DetectorOptions o;
  o.max_image_width = 2147483647;
  o.max_image_height = 65537;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 2u);
  EXPECT_NE(p[0].find("input.max_image_width = 2147483647: must be in 1..65536"), std::string::npos) << p[0];
  EXPECT_NE(p[1].find("input.max_image_height = 65537: must be in 1..65536"), std::string::npos) << p[1];
  o.max_image_width = 65536;
  o.max_image_height = 65536;
  EXPECT_TRUE(o.validate().empty());
}

}  // namespace
}  // namespace wingman::detector
