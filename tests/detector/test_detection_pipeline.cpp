// SPDX-License-Identifier: MIT
// Algorithm 2 geometry with a fake backend returning crafted [region] tensors, region decode on a hand cell,
// options, and the whole pipeline on the CPU backend.
#include <wingman/detector/cpu_backend.hpp>
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>
#include <wingman/detector/detection_pipeline.hpp>
#include <wingman/detector/region_decode.hpp>

#include <wingman/common/config.hpp>

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace wingman::detector {
namespace {

constexpr float kCell = 32.0f;  // 416 / 13 network pixels per grid cell

DarknetModel thesis() { return parse_darknet_cfg(testing::source_path("models/tiny-yolo-thesis.cfg")); }

float sigmoid(float x) { return 1.0f / (1.0f + std::exp(-x)); }
float logit(float p) { return std::log(p / (1.0f - p)); }

/// One grid cell's raw values for the crafted tensor.
struct Cell {
  int anchor, row, col;
  float tx, ty, tw, th, confidence;
};

/// InferenceBackend returning scripted [region] tensors: call k, image i gets the cells script[k][i];
/// every other cell has confidence ~0. Records the batch size of every call.
class FakeBackend : public InferenceBackend {
 public:
  FakeBackend(std::vector<std::vector<std::vector<Cell>>> script, int max_batch, std::vector<int>* batches)
      : script_(std::move(script)), max_batch_(max_batch), batches_(batches) {}
  std::string name() const override { return "fake"; }
  Shape input_shape() const override { return {3, 416, 416}; }
  Shape output_shape() const override { return {30, 13, 13}; }
  int max_batch() const override { return max_batch_; }
  void forward(const float*, int batch, std::vector<float>& output) override {
    const int plane = 13 * 13;
    output.assign(static_cast<size_t>(batch) * 30 * plane, 0.0f);
    for (int i = 0; i < batch; ++i) {
      float* o = output.data() + static_cast<size_t>(i) * 30 * plane;
      for (int a = 0; a < 5; ++a)
        for (int p = 0; p < plane; ++p) o[(a * 6 + 4) * plane + p] = -30.0f;
      if (call_ < script_.size() && static_cast<size_t>(i) < script_[call_].size())
        for (const Cell& c : script_[call_][i]) {
          const int p = c.row * 13 + c.col;
          float* base = o + static_cast<size_t>(c.anchor) * 6 * plane;
          base[p] = c.tx;
          base[plane + p] = c.ty;
          base[2 * plane + p] = c.tw;
          base[3 * plane + p] = c.th;
          base[4 * plane + p] = logit(c.confidence);
        }
    }
    if (batches_) batches_->push_back(batch);
    ++call_;
  }

 private:
  std::vector<std::vector<std::vector<Cell>>> script_;
  int max_batch_;
  std::vector<int>* batches_;
  size_t call_ = 0;
};

DetectionPipeline make(DetectorPipelineOptions o, std::vector<std::vector<std::vector<Cell>>> script,
                       std::vector<int>* batches = nullptr, int max_batch = 8) {
  return DetectionPipeline(std::move(o), std::make_unique<FakeBackend>(std::move(script), max_batch, batches),
                           thesis());
}

const cv::Mat& image_1280x720() {
  static const cv::Mat img(720, 1280, CV_8UC3, cv::Scalar(90, 120, 150));
  return img;
}

TEST(RegionDecode, HandComputedCell) {
  const DarknetModel m = thesis();
  const Layer& region = m.layers.back();
  std::vector<float> raw(30 * 13 * 13, 0.0f);
  const int plane = 169;
  for (int a = 0; a < 5; ++a)
    for (int p = 0; p < plane; ++p) raw[(a * 6 + 4) * plane + p] = -30.0f;
  // Anchor 2 (6.63 x 11.38 cells), row 4, column 7.
  const int p = 4 * 13 + 7;
  float* base = raw.data() + 2 * 6 * plane;
  base[p] = 0.5f;               // t_x
  base[plane + p] = -1.0f;      // t_y
  base[2 * plane + p] = 0.25f;  // t_w
  base[3 * plane + p] = -0.5f;  // t_h
  base[4 * plane + p] = 2.0f;   // t_o
  base[5 * plane + p] = -7.0f;  // t_class: one class, softmax = 1 whatever the value
  std::vector<Box> boxes;
  decode_region(raw.data(), {30, 13, 13}, region, 416, 416, 0.2f, boxes);
  ASSERT_EQ(boxes.size(), 1u);
  EXPECT_NEAR(boxes[0].cx, (sigmoid(0.5f) + 7) * kCell, 1e-3);   // (0.62246 + 7) x 32 = 243.919
  EXPECT_NEAR(boxes[0].cy, (sigmoid(-1.0f) + 4) * kCell, 1e-3);  // (0.26894 + 4) x 32 = 136.606
  EXPECT_NEAR(boxes[0].cx, 243.9187f, 1e-3);
  EXPECT_NEAR(boxes[0].w, 6.63f * std::exp(0.25f) * kCell, 1e-3);
  EXPECT_NEAR(boxes[0].h, 11.38f * std::exp(-0.5f) * kCell, 1e-3);
  EXPECT_NEAR(boxes[0].confidence, sigmoid(2.0f), 1e-6);  // 0.8808
  // Above the threshold nothing is kept.
  boxes.clear();
  decode_region(raw.data(), {30, 13, 13}, region, 416, 416, 0.9f, boxes);
  EXPECT_TRUE(boxes.empty());
}

TEST(DetectorPipelineOptions, DefaultsAreValidAndBadValuesNamed) {
  EXPECT_TRUE(DetectorPipelineOptions{}.validate().empty());
  DetectorPipelineOptions o;
  o.p_thresh = 1.5;
  o.policy = "best";
  o.max_detections = 0;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 3u);
  EXPECT_NE(p[0].find("detection.p_thresh"), std::string::npos) << p[0];
  EXPECT_NE(p[1].find("detection.policy"), std::string::npos) << p[1];
  EXPECT_NE(p[2].find("detection.max_detections"), std::string::npos) << p[2];
  const auto loaded = common::load_options_from_string<DetectorPipelineOptions>(
      "detection: {p_thresh: 0.3, zoom_in: true, policy: most_confident}", "t.yaml");
  EXPECT_DOUBLE_EQ(loaded.p_thresh, 0.3);
  EXPECT_TRUE(loaded.zoom_in);
}

TEST(Algorithm2, SubsquareAndResizeMapToFullImagePixels) {
  // Cell (6, 6), anchor 0, t = 0: centre (6.5, 6.5) cells = (208, 208) network pixels.
  const std::vector<std::vector<std::vector<Cell>>> script = {{{{0, 6, 6, 0, 0, 0, 0, 0.8f}}}};
  DetectorPipelineOptions o;
  o.subsquare = true;
  auto with_square = make(o, script).detect(image_1280x720());
  ASSERT_EQ(with_square.size(), 1u);
  // 720 x 720 square at x = 280: scale 720 / 416.
  EXPECT_NEAR(with_square[0].cx, 280 + 208 * 720.0f / 416, 1e-2);  // 640
  EXPECT_NEAR(with_square[0].cy, 208 * 720.0f / 416, 1e-2);        // 360
  EXPECT_NEAR(with_square[0].w, 1.08f * kCell * 720 / 416, 1e-2);
  EXPECT_NEAR(with_square[0].h, 1.19f * kCell * 720 / 416, 1e-2);
  EXPECT_NEAR(with_square[0].confidence, 0.8f, 1e-5);
  EXPECT_FALSE(with_square[0].zoom_refined);
  o.subsquare = false;
  auto whole = make(o, script).detect(image_1280x720());
  ASSERT_EQ(whole.size(), 1u);
  EXPECT_NEAR(whole[0].cx, 640.0f, 1e-2);
  EXPECT_NEAR(whole[0].w, 1.08f * kCell * 1280 / 416, 1e-2);  // stretched: x scale 1280 / 416
  EXPECT_NEAR(whole[0].h, 1.19f * kCell * 720 / 416, 1e-2);
}

TEST(Algorithm2, ThresholdNmsAndPolicy) {
  // Two overlapping boxes (same anchor, neighbouring cells, wide anchor 4) and one far away; one below p_thresh.
  const std::vector<std::vector<std::vector<Cell>>> script = {{{{4, 6, 6, 0, 0, 0, 0, 0.7f},
                                                                {4, 6, 7, 0, 0, 0, 0, 0.9f},
                                                                {0, 1, 1, 0, 0, 0, 0, 0.5f},
                                                                {0, 11, 11, 0, 0, 0, 0, 0.1f}}}};
  DetectorPipelineOptions o;
  auto all = make(o, script).detect(image_1280x720());
  ASSERT_EQ(all.size(), 2u);
  EXPECT_NEAR(all[0].confidence, 0.9f, 1e-5);
  EXPECT_NEAR(all[1].confidence, 0.5f, 1e-5);
  o.policy = "most_confident";
  auto one = make(o, script).detect(image_1280x720());
  ASSERT_EQ(one.size(), 1u);
  EXPECT_NEAR(one[0].confidence, 0.9f, 1e-5);
}

TEST(Algorithm2, ZoomInKeepsMostConfidentRedetectionInClampedCrop) {
  // First pass (no subsquare): cell (6, 12) -> centre (400, 208) network px -> (1230.77, 360) image px,
  // so the 416 x 416 crop is clamped to x = 1280 - 416 = 864, y = 360 - 208 = 152.
  // In the crop: a weaker box at cell (6, 6) and the most confident one at cell (2, 3).
  std::vector<int> batches;
  DetectorPipelineOptions o;
  o.zoom_in = true;
  auto p = make(o, {{{{0, 6, 12, 0, 0, 0, 0, 0.6f}}}, {{{1, 6, 6, 0, 0, 0, 0, 0.7f}, {0, 2, 3, 0, 0, 0, 0, 0.95f}}}},
                &batches);
  auto boxes = p.detect(image_1280x720());
  ASSERT_EQ(boxes.size(), 1u);
  EXPECT_TRUE(boxes[0].zoom_refined);
  EXPECT_NEAR(boxes[0].confidence, 0.95f, 1e-5);
  EXPECT_NEAR(boxes[0].cx, 864 + 3.5f * kCell, 1e-2);  // crop is full resolution: scale 1
  EXPECT_NEAR(boxes[0].cy, 152 + 2.5f * kCell, 1e-2);
  EXPECT_NEAR(boxes[0].w, 1.08f * kCell, 1e-2);
  EXPECT_EQ(batches, (std::vector<int>{1, 1}));
}

TEST(Algorithm2, ZoomInFallsBackToOriginalBoxWhenRedetectionFindsNothing) {
  DetectorPipelineOptions o;
  o.zoom_in = true;
  auto p = make(o, {{{{0, 6, 6, 0, 0, 0, 0, 0.6f}}}, {{}}});
  auto boxes = p.detect(image_1280x720());
  ASSERT_EQ(boxes.size(), 1u);
  EXPECT_FALSE(boxes[0].zoom_refined);
  EXPECT_NEAR(boxes[0].cx, 640.0f, 1e-2);
  EXPECT_NEAR(boxes[0].confidence, 0.6f, 1e-5);
}

TEST(Algorithm2, ZoomInCropsRunAsBatches) {
  // Three separate detections: with max_batch 2 the crops run as a batch of 2 then 1; with 8 as one batch.
  const std::vector<Cell> three = {
      {0, 1, 1, 0, 0, 0, 0, 0.9f}, {0, 6, 6, 0, 0, 0, 0, 0.8f}, {0, 11, 11, 0, 0, 0, 0, 0.7f}};
  DetectorPipelineOptions o;
  o.zoom_in = true;
  std::vector<int> batches;
  make(o, {{three}}, &batches, 2).detect(image_1280x720());
  EXPECT_EQ(batches, (std::vector<int>{1, 2, 1}));
  batches.clear();
  auto boxes = make(o, {{three}}, &batches, 8).detect(image_1280x720());
  EXPECT_EQ(batches, (std::vector<int>{1, 3}));
  EXPECT_EQ(boxes.size(), 3u);
}

TEST(Algorithm2, RejectsABackendThatDoesNotFitTheModel) {
  class Wrong : public FakeBackend {
   public:
    Wrong() : FakeBackend({}, 1, nullptr) {}
    Shape output_shape() const override { return {125, 13, 13}; }
  };
  EXPECT_THROW(DetectionPipeline(DetectorPipelineOptions{}, std::make_unique<Wrong>(), thesis()),
               std::invalid_argument);
}

TEST(Algorithm2, RunsOnTheCpuBackendWithRandomWeights) {
  DarknetModel m = thesis();
  randomize_weights(m, 99);
  DetectorPipelineOptions o;
  o.subsquare = true;
  o.zoom_in = true;
  DetectionPipeline p(o, std::make_unique<CpuBackend>(m, 4), m);
  cv::Mat img(720, 1280, CV_8UC3);
  cv::randu(img, 0, 255);
  const auto boxes = p.detect(img);
  EXPECT_LE(boxes.size(), 10u);
  for (size_t i = 1; i < boxes.size(); ++i) EXPECT_GE(boxes[i - 1].confidence, boxes[i].confidence);
}

}  // namespace
}  // namespace wingman::detector
