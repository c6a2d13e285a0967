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
#include "thesis_model.hpp"

#include <gtest/gtest.h>

#include <opencv2/dnn.hpp>

#include <cmath>

namespace wingman::detector {
namespace {

constexpr float kCell = 32.0f;  // 416 / 13 network pixels per grid cell

using test::thesis;

float sigmoid(float x) { return 1.0f / (1.0f + std::exp(-x)); }
float logit(float p) { return std::log(p / (1.0f - p)); }

/// One grid cell's raw values for the crafted tensor.
struct Cell {
  int anchor, row, col;
  float tx, ty, tw, th, confidence;
};

/// InferenceBackend returning scripted [region] tensors of the thesis network at grid x grid cells (its input
/// 32 grid x 32 grid): call k, image i gets the cells script[k][i]; every other cell has confidence ~0. Records the
/// batch size of every call.
class FakeBackend : public InferenceBackend {
 public:
  FakeBackend(std::vector<std::vector<std::vector<Cell>>> script, int max_batch, std::vector<int>* batches,
              int grid = 13)
      : script_(std::move(script)), max_batch_(max_batch), batches_(batches), grid_(grid) {}
  std::string name() const override { return "fake"; }
  Shape input_shape() const override { return {3, 32 * grid_, 32 * grid_}; }
  std::vector<Shape> output_shapes() const override { return {{30, grid_, grid_}}; }
  int max_batch() const override { return max_batch_; }
  void forward(const float*, int batch, std::vector<float>& output) override {
    const int plane = grid_ * grid_;
    output.assign(static_cast<size_t>(batch) * 30 * plane, 0.0f);
    for (int i = 0; i < batch; ++i) {
      float* o = output.data() + static_cast<size_t>(i) * 30 * plane;
      for (int a = 0; a < 5; ++a)
        for (int p = 0; p < plane; ++p) o[(a * 6 + 4) * plane + p] = -30.0f;
      if (call_ < script_.size() && static_cast<size_t>(i) < script_[call_].size())
        for (const Cell& c : script_[call_][i]) {
          const int p = c.row * grid_ + c.col;
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
  int grid_;
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

/// A [yolo] head as in a .cfg: yolov3-tiny's six anchors (pixels), `mask`, `classes`, optional extra keys.
std::string yolo_section(const char* mask, int classes, const std::string& extra = "") {
  return std::string("[yolo]\nmask=") + mask +
         "\nanchors=10,14, 23,27, 37,58, 81,82, 135,169, 344,319\nclasses=" + std::to_string(classes) + "\nnum=6\n" +
         extra + "\n";
}

/// A yolov3-tiny-like network at `size` x `size`: a stride-32 head (mask 3,4,5), a route back, 1x1 conv,
/// upsample x2, concat with the stride-16 features, a stride-16 head (mask 0,1,2). Layers 9 and 15 are the
/// heads (13 x 13 and 26 x 26 at 416).
std::string two_head_cfg(int size, int classes, const std::string& extra_first = "",
                         const std::string& extra_second = "") {
  const int f = 3 * (5 + classes);
  auto conv = [](int filters, int ksize, const char* act, bool bn) {
    return std::string("[convolutional]\n") + (bn ? "batch_normalize=1\n" : "") + "filters=" + std::to_string(filters) +
           "\nsize=" + std::to_string(ksize) + "\nstride=1\npad=1\nactivation=" + act + "\n\n";
  };
  const std::string pool = "[maxpool]\nsize=2\nstride=2\n\n";
  return "[net]\nwidth=" + std::to_string(size) + "\nheight=" + std::to_string(size) + "\nchannels=3\n\n" +
         conv(4, 3, "leaky", true) + pool + pool + pool +                             // 0-3: stride 8
         conv(8, 3, "leaky", true) + pool +                                           // 4-5: stride 16
         conv(8, 3, "leaky", true) + pool +                                           // 6-7: stride 32
         conv(f, 1, "linear", false) + yolo_section("3,4,5", classes, extra_first) +  // 8-9
         "[route]\nlayers=-3\n\n" + conv(4, 1, "leaky", true) +                       // 10-11
         "[upsample]\nstride=2\n\n[route]\nlayers=-1,5\n\n" +                         // 12-13: stride 16
         conv(f, 1, "linear", false) + yolo_section("0,1,2", classes, extra_second);  // 14-15
}

TEST(YoloDecode, HandComputedCellWithScaleXY) {
  // A 13 x 10 grid on a 416 x 320 input (32 px cells), mask 3,4,5, two classes, scale_x_y 1.05.
  Layer yolo;
  yolo.type = LayerType::kYolo;
  yolo.anchors = {10, 14, 23, 27, 37, 58, 81, 82, 135, 169, 344, 319};
  yolo.mask = {3, 4, 5};
  yolo.num = 3;
  yolo.classes = 2;
  yolo.scale_x_y = 1.05f;
  yolo.input = yolo.output = {21, 10, 13};
  const int plane = 10 * 13;
  std::vector<float> raw(21 * plane, 0.0f);
  for (int k = 0; k < 3; ++k)
    for (int p = 0; p < plane; ++p) raw[(k * 7 + 4) * plane + p] = -30.0f;  // no object anywhere...
  const int p = 4 * 13 + 7;                                                 // ...but row 4, column 7
  float* base = raw.data() + 1 * 7 * plane;                                 // of mask entry 1: anchor 4
  base[p] = 0.5f;                                                           // t_x
  base[plane + p] = -1.0f;                                                  // t_y
  base[2 * plane + p] = 0.25f;                                              // t_w
  base[3 * plane + p] = -0.5f;                                              // t_h
  base[4 * plane + p] = 2.0f;                                               // t_o
  base[5 * plane + p] = -1.0f;                                              // t_class 0
  base[6 * plane + p] = 0.5f;                                               // t_class 1 (the larger)
  std::vector<Box> boxes;
  decode_yolo(raw.data(), yolo.input, yolo, 416, 320, 0.2f, boxes);
  ASSERT_EQ(boxes.size(), 1u);
  // b_x = (1.05 sigma(0.5) - 0.025 + 7) / 13 * 416 = (0.6535823 - 0.025 + 7) * 32 = 244.1146
  EXPECT_NEAR(boxes[0].cx, 244.1146f, 1e-3);
  // b_y = (1.05 sigma(-1) - 0.025 + 4) / 10 * 320 = (0.2823885 - 0.025 + 4) * 32 = 136.2364
  EXPECT_NEAR(boxes[0].cy, 136.2364f, 1e-3);
  EXPECT_NEAR(boxes[0].w, 135.0f * std::exp(0.25f), 1e-3);                // 173.3434 px: anchor 4 is 135 x 169 px
  EXPECT_NEAR(boxes[0].h, 169.0f * std::exp(-0.5f), 1e-3);                // 102.5037 px
  EXPECT_NEAR(boxes[0].confidence, sigmoid(2.0f) * sigmoid(0.5f), 1e-6);  // 0.8808 x 0.6225 = 0.5483
  EXPECT_NEAR(boxes[0].confidence, 0.54826f, 1e-4);
  EXPECT_EQ(boxes[0].class_id, 1);                                          // the most probable class
  EXPECT_NEAR(boxes[0].drone_score, sigmoid(2.0f) * sigmoid(-1.0f), 1e-6);  // objectness x P(class 0)
  // drone_first: the drone score 0.8808 x 0.2689 = 0.2369 reaches 0.2, so the box is a drone with that confidence;
  // at 0.3 it does not, and the box stays class 1.
  std::vector<Box> drone_first;
  decode_yolo(raw.data(), yolo.input, yolo, 416, 320, 0.2f, drone_first, true);
  ASSERT_EQ(drone_first.size(), 1u);
  EXPECT_EQ(drone_first[0].class_id, 0);
  EXPECT_NEAR(drone_first[0].confidence, sigmoid(2.0f) * sigmoid(-1.0f), 1e-6);
  EXPECT_NEAR(drone_first[0].drone_score, drone_first[0].confidence, 1e-7);
  EXPECT_FLOAT_EQ(drone_first[0].cx, boxes[0].cx);
  drone_first.clear();
  decode_yolo(raw.data(), yolo.input, yolo, 416, 320, 0.3f, drone_first, true);
  ASSERT_EQ(drone_first.size(), 1u);
  EXPECT_EQ(drone_first[0].class_id, 1);
  EXPECT_NEAR(drone_first[0].confidence, 0.54826f, 1e-4);
  boxes.clear();
  decode_yolo(raw.data(), yolo.input, yolo, 416, 320, 0.55f, boxes);
  EXPECT_TRUE(boxes.empty());
  // With scale_x_y 1 (YOLOv3): b_x = (sigma(0.5) + 7) * 32.
  yolo.scale_x_y = 1.0f;
  decode_yolo(raw.data(), yolo.input, yolo, 416, 320, 0.2f, boxes);
  ASSERT_EQ(boxes.size(), 1u);
  EXPECT_NEAR(boxes[0].cx, (sigmoid(0.5f) + 7) * 32, 1e-3);
  // p_thresh 0 keeps every anchor of every cell.
  boxes.clear();
  decode_yolo(raw.data(), yolo.input, yolo, 416, 320, 0.0f, boxes);
  EXPECT_EQ(boxes.size(), 3u * plane);
}

TEST(YoloDecode, RejectsTensorsAndMasksThatDoNotFit) {
  const DarknetModel m = parse_darknet_cfg_string(two_head_cfg(416, 1), "two-heads.cfg");
  const Layer& head = m.layers[9];
  ASSERT_EQ(head.type, LayerType::kYolo);
  std::vector<float> raw(18 * 26 * 26, 0.0f);
  std::vector<Box> boxes;
  EXPECT_THROW(decode_yolo(raw.data(), {18, 26, 26}, head, 416, 416, 0.2f, boxes), std::invalid_argument);
  EXPECT_THROW(decode_head(raw.data(), {18, 13, 13}, m.layers[0], 416, 416, 0.2f, boxes), std::invalid_argument);
  Layer bad = head;
  bad.mask = {3, 4, 6};  // anchor 6 does not exist
  EXPECT_THROW(decode_yolo(raw.data(), {18, 13, 13}, bad, 416, 416, 0.2f, boxes), std::invalid_argument);
  EXPECT_NO_THROW(decode_yolo(raw.data(), {18, 13, 13}, head, 416, 416, 0.2f, boxes));
}

TEST(YoloDecode, MatchesOpenCvDnnDecodeOnATinyYoloV3LikeNetwork) {
  // OpenCV's Darknet importer decodes [yolo] heads itself (one row per cell and anchor: x, y, w, h relative
  // to the input, objectness, objectness x sigma(class) when above `thresh`). Same random weights: our
  // decode of CpuBackend's raw head inputs must give the same boxes. thresh=0 and nms_threshold=0 (keys
  // only OpenCV reads) make it keep every cell. The second head has scale_x_y 1.1.
  const int size = 128, classes = 2;
  DarknetModel m = parse_darknet_cfg_string(two_head_cfg(size, classes, "", "scale_x_y=1.1"), "two-heads.cfg");
  randomize_weights(m, 77);
  std::string opencv_cfg = write_darknet_cfg(m);
  for (size_t at = 0; (at = opencv_cfg.find("[yolo]\n", at)) != std::string::npos; at += 6)
    opencv_cfg.insert(at + 7, "thresh=0\nnms_threshold=0\n");
  const std::vector<char> weights = serialize_darknet_weights(m);
  cv::dnn::Net net = cv::dnn::readNetFromDarknet(opencv_cfg.data(), opencv_cfg.size(), weights.data(), weights.size());
  net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  cv::Mat image(size, size, CV_32FC3);
  cv::randu(image, 0.0f, 1.0f);
  const cv::Mat blob = cv::dnn::blobFromImage(image);  // 1 x 3 x size x size, planes in order
  net.setInput(blob);
  std::vector<cv::Mat> decoded;
  net.forward(decoded, std::vector<std::string>{"yolo_9", "yolo_15"});
  ASSERT_EQ(decoded.size(), 2u);

  CpuBackend backend(m, 1);
  std::vector<float> raw;
  backend.forward(blob.ptr<float>(), 1, raw);
  const std::vector<int> heads = m.heads();
  ASSERT_EQ(heads, (std::vector<int>{9, 15}));
  const float* head_raw = raw.data();
  for (int h = 0; h < 2; ++h) {
    const Layer& head = m.layers[heads[h]];
    SCOPED_TRACE("head " + std::to_string(h) + ", scale_x_y " + std::to_string(head.scale_x_y));
    std::vector<Box> boxes;
    decode_yolo(head_raw, head.input, head, size, size, 0.0f, boxes);  // order: anchor, row, column
    head_raw += head.input.size();
    const int rows = head.input.h, cols = head.input.w, num = head.num;
    const cv::Mat& d = decoded[h];
    ASSERT_EQ(d.rows, rows * cols * num);
    ASSERT_EQ(d.cols, 5 + classes);
    ASSERT_EQ(boxes.size(), static_cast<size_t>(d.rows));
    for (int k = 0; k < num; ++k)
      for (int y = 0; y < rows; ++y)
        for (int x = 0; x < cols; ++x) {
          const Box& b = boxes[(static_cast<size_t>(k) * rows + y) * cols + x];
          const float* o = d.ptr<float>((y * cols + x) * num + k);
          const std::string where =
              "anchor " + std::to_string(k) + " row " + std::to_string(y) + " col " + std::to_string(x);
          ASSERT_NEAR(b.cx / size, o[0], 1e-5) << where;
          ASSERT_NEAR(b.cy / size, o[1], 1e-5) << where;
          ASSERT_NEAR(b.w / size, o[2], 1e-5 * (1 + o[2])) << where;
          ASSERT_NEAR(b.h / size, o[3], 1e-5 * (1 + o[3])) << where;
          ASSERT_NEAR(b.confidence, std::max(o[5], o[6]), 1e-5) << where;
        }
  }
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
  EXPECT_EQ(with_square[0].pass, Pass::kSingle);
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
  o.zoom_max_fraction = 0.5;  // the boxes are 106 px wide, the crop 416: zoomed (the default 0.25 would not)
  auto p = make(o, {{{{0, 6, 12, 0, 0, 0, 0, 0.6f}}}, {{{1, 6, 6, 0, 0, 0, 0, 0.7f}, {0, 2, 3, 0, 0, 0, 0, 0.95f}}}},
                &batches);
  auto boxes = p.detect(image_1280x720());
  ASSERT_EQ(boxes.size(), 1u);
  EXPECT_EQ(boxes[0].pass, Pass::kZoomIn);
  EXPECT_NEAR(boxes[0].confidence, 0.95f, 1e-5);
  EXPECT_NEAR(boxes[0].cx, 864 + 3.5f * kCell, 1e-2);  // crop is full resolution: scale 1
  EXPECT_NEAR(boxes[0].cy, 152 + 2.5f * kCell, 1e-2);
  EXPECT_NEAR(boxes[0].w, 1.08f * kCell, 1e-2);
  EXPECT_EQ(batches, (std::vector<int>{1, 1}));
}

TEST(Algorithm2, ZoomInFallsBackToOriginalBoxWhenRedetectionFindsNothing) {
  DetectorPipelineOptions o;
  o.zoom_in = true;
  o.zoom_max_fraction = 0.5;  // the boxes are 106 px wide, the crop 416: zoomed (the default 0.25 would not)
  auto p = make(o, {{{{0, 6, 6, 0, 0, 0, 0, 0.6f}}}, {{}}});
  auto boxes = p.detect(image_1280x720());
  ASSERT_EQ(boxes.size(), 1u);
  EXPECT_EQ(boxes[0].pass, Pass::kSingle);
  EXPECT_NEAR(boxes[0].cx, 640.0f, 1e-2);
  EXPECT_NEAR(boxes[0].confidence, 0.6f, 1e-5);
}

TEST(Algorithm2, ZoomInOnlyBoxesThatFitTheCropByZoomMaxFraction) {
  // A small box (anchor 0 at cell (1, 1): 106 x 66 image px) and a large one (anchor 1 at cell (8, 8): 109 x 141
  // network px = 337 x 244 image px). The crop is 416 x 416 image px: with zoom_max_fraction 0.5 (208 px) only the
  // small box is zoomed and the large keeps its first-pass box; with 1.0 both are; with the default 0.25 (104 px)
  // neither (the small box is 106 px wide).
  const std::vector<Cell> first = {{0, 1, 1, 0, 0, 0, 0, 0.9f}, {1, 8, 8, 0, 0, 0, 0, 0.8f}};
  const std::vector<Cell> in_crop = {{0, 6, 6, 0, 0, 0, 0, 0.95f}};
  DetectorPipelineOptions o;
  o.zoom_in = true;
  EXPECT_DOUBLE_EQ(o.zoom_max_fraction, 0.25);  // the documented default
  std::vector<int> batches;
  auto unzoomed = make(o, {{first}, {in_crop, in_crop}}, &batches).detect(image_1280x720());
  EXPECT_EQ(batches, (std::vector<int>{1}));
  ASSERT_EQ(unzoomed.size(), 2u);
  EXPECT_EQ(unzoomed[0].pass, Pass::kSingle);
  EXPECT_EQ(unzoomed[1].pass, Pass::kSingle);

  o.zoom_max_fraction = 0.5;
  batches.clear();
  auto boxes = make(o, {{first}, {in_crop}}, &batches).detect(image_1280x720());
  EXPECT_EQ(batches, (std::vector<int>{1, 1}));
  ASSERT_EQ(boxes.size(), 2u);
  EXPECT_EQ(boxes[0].pass, Pass::kZoomIn);
  EXPECT_NEAR(boxes[0].confidence, 0.95f, 1e-5);
  EXPECT_EQ(boxes[1].pass, Pass::kSingle);
  EXPECT_NEAR(boxes[1].confidence, 0.8f, 1e-5);
  EXPECT_NEAR(boxes[1].cx, 8.5f * kCell * 1280 / 416, 1e-2);
  EXPECT_NEAR(boxes[1].cy, 8.5f * kCell * 720 / 416, 1e-2);
  EXPECT_NEAR(boxes[1].w, 3.42f * kCell * 1280 / 416, 1e-2);
  EXPECT_NEAR(boxes[1].h, 4.41f * kCell * 720 / 416, 1e-2);

  o.zoom_max_fraction = 1.0;
  batches.clear();
  boxes = make(o, {{first}, {in_crop, in_crop}}, &batches).detect(image_1280x720());
  EXPECT_EQ(batches, (std::vector<int>{1, 2}));
  ASSERT_EQ(boxes.size(), 2u);
  EXPECT_EQ(boxes[0].pass, Pass::kZoomIn);
  EXPECT_EQ(boxes[1].pass, Pass::kZoomIn);

  for (const double bad : {0.0, -0.1, 1.5}) {
    o.zoom_max_fraction = bad;
    const auto problems = o.validate();
    ASSERT_EQ(problems.size(), 1u) << bad;
    EXPECT_NE(problems[0].find("detection.zoom_max_fraction"), std::string::npos) << problems[0];
  }
}

TEST(Algorithm2, ZoomInSkipsADetectionOverlappingAMoreConfidentOne) {
  // NMS keeps two boxes at IoU <= o_thresh: a confident one (anchor 1 at cell (6, 6): 337 x 244 image px, too large to
  // zoom at 0.5) and a weaker small one at cell (6, 7) inside it (a part of the same drone). The weaker one is not
  // zoomed (a crop centred on a part re-detects the part); a third box elsewhere is. One crop runs.
  const std::vector<Cell> first = {
      {1, 6, 6, 0, 0, 0, 0, 0.9f}, {0, 6, 7, 0, 0, 0, 0, 0.5f}, {0, 1, 1, 0, 0, 0, 0, 0.4f}};
  DetectorPipelineOptions o;
  o.zoom_in = true;
  o.zoom_max_fraction = 0.5;
  std::vector<int> batches;
  auto boxes = make(o, {{first}, {{{0, 6, 6, 0, 0, 0, 0, 0.95f}}}}, &batches).detect(image_1280x720());
  EXPECT_EQ(batches, (std::vector<int>{1, 1}));
  ASSERT_EQ(boxes.size(), 3u);
  EXPECT_EQ(boxes[0].pass, Pass::kZoomIn);  // the box at cell (1, 1), re-detected at 0.95
  EXPECT_NEAR(boxes[0].confidence, 0.95f, 1e-5);
  EXPECT_EQ(boxes[1].pass, Pass::kSingle);
  EXPECT_NEAR(boxes[1].confidence, 0.9f, 1e-5);
  EXPECT_EQ(boxes[2].pass, Pass::kSingle);  // the part: its first-pass box, unchanged
  EXPECT_NEAR(boxes[2].confidence, 0.5f, 1e-5);
  EXPECT_NEAR(boxes[2].cx, 7.5f * kCell * 1280 / 416, 1e-2);
}

TEST(Algorithm2, ZoomInSkipsImagesNoLargerThanTheNetworkInput) {
  // A 416 x 416 image on a 416 x 416 network: a crop would be the image itself, so only the first pass runs; a
  // 416 x 600 image was shrunk vertically, so its detection is zoomed.
  DetectorPipelineOptions o;
  o.zoom_in = true;
  o.zoom_max_fraction = 1.0;
  const std::vector<std::vector<std::vector<Cell>>> script = {{{{0, 6, 6, 0, 0, 0, 0, 0.6f}}},
                                                              {{{0, 6, 6, 0, 0, 0, 0, 0.9f}}}};
  std::vector<int> batches;
  auto same = make(o, script, &batches).detect(cv::Mat(416, 416, CV_8UC3, cv::Scalar(0, 0, 0)));
  EXPECT_EQ(batches, (std::vector<int>{1}));
  ASSERT_EQ(same.size(), 1u);
  EXPECT_EQ(same[0].pass, Pass::kSingle);
  batches.clear();
  auto taller = make(o, script, &batches).detect(cv::Mat(600, 416, CV_8UC3, cv::Scalar(0, 0, 0)));
  EXPECT_EQ(batches, (std::vector<int>{1, 1}));
  ASSERT_EQ(taller.size(), 1u);
  EXPECT_EQ(taller[0].pass, Pass::kZoomIn);
}

TEST(Algorithm2, ZoomInCropsRunAsBatches) {
  // Three separate detections: with max_batch 2 the crops run as a batch of 2 then 1; with 8 as one batch.
  const std::vector<Cell> three = {
      {0, 1, 1, 0, 0, 0, 0, 0.9f}, {0, 6, 6, 0, 0, 0, 0, 0.8f}, {0, 11, 11, 0, 0, 0, 0, 0.7f}};
  DetectorPipelineOptions o;
  o.zoom_in = true;
  o.zoom_max_fraction = 0.5;  // the boxes are 106 px wide, the crop 416: zoomed (the default 0.25 would not)
  std::vector<int> batches;
  make(o, {{three}}, &batches, 2).detect(image_1280x720());
  EXPECT_EQ(batches, (std::vector<int>{1, 2, 1}));
  batches.clear();
  auto boxes = make(o, {{three}}, &batches, 8).detect(image_1280x720());
  EXPECT_EQ(batches, (std::vector<int>{1, 3}));
  EXPECT_EQ(boxes.size(), 3u);
}

TEST(Algorithm2, FlipFusionFusesTheMirroredPassAndHalvesOneViewBoxes) {
  // Call 0 is the image, call 1 its mirror (network pixels; the 1280x720 image stretched to 416x416).
  //  - a drone at network (216, 208) in the image, 0.8; the mirror sees it at (416 - 216, 216) = (200, 216), 1.5x as
  //    wide, 0.6: fused at the confidence-weighted mean, confidence 0.7;
  //  - a box at cell (2, 2), 0.5, that the mirror finds at 0.15 (under p_thresh 0.2, above the passes' floor 0.1):
  //    (0.5 + 0.15) / 2 = 0.325;
  //  - a box only the mirror finds, 0.3: 0.15 after fusion, under p_thresh: dropped.
  const float quarter = logit(0.25f), three_quarters = logit(0.75f);
  const std::vector<std::vector<std::vector<Cell>>> script = {
      {{{0, 6, 6, three_quarters, 0, 0, 0, 0.8f}, {0, 2, 2, 0, 0, 0, 0, 0.5f}}},
      {{{0, 6, 6, quarter, three_quarters, std::log(1.5f), 0, 0.6f},
        {0, 2, 10, 0, 0, 0, 0, 0.15f},
        {0, 10, 10, 0, 0, 0, 0, 0.3f}}}};
  DetectorPipelineOptions o;
  o.flip_fusion = true;
  std::vector<int> batches;
  auto boxes = make(o, script, &batches).detect(image_1280x720());
  EXPECT_EQ(batches, (std::vector<int>{1, 1}));  // one pass per view
  ASSERT_EQ(boxes.size(), 2u);
  const float sx = 1280.0f / 416, sy = 720.0f / 416;
  EXPECT_NEAR(boxes[0].confidence, 0.7f, 1e-5);
  EXPECT_NEAR(boxes[0].cx, 216 * sx, 1e-2);
  EXPECT_NEAR(boxes[0].cy, (0.8f * 208 + 0.6f * 216) / 1.4f * sy, 1e-2);
  EXPECT_NEAR(boxes[0].w, (0.8f * 1.08f + 0.6f * 1.08f * 1.5f) / 1.4f * kCell * sx, 1e-2);
  EXPECT_NEAR(boxes[0].h, 1.19f * kCell * sy, 1e-2);
  EXPECT_NEAR(boxes[1].confidence, 0.325f, 1e-5);
  EXPECT_NEAR(boxes[1].cx, 80 * sx, 1e-2);
  EXPECT_NEAR(boxes[1].cy, 80 * sy, 1e-2);
  // Without flip_fusion the same first call gives its own two boxes at their own confidences.
  o.flip_fusion = false;
  boxes = make(o, script).detect(image_1280x720());
  ASSERT_EQ(boxes.size(), 2u);
  EXPECT_NEAR(boxes[0].confidence, 0.8f, 1e-5);
  EXPECT_NEAR(boxes[1].confidence, 0.5f, 1e-5);
}

TEST(Algorithm2, FlipFusionAppliesPolicyAfterFusing) {
  // most_confident: each pass keeps its boxes; the fused list is cut to one. The image alone is more confident in
  // the box at (2, 2) (0.5 against 0.4), but the mirror agrees only on the drone at (6, 6): fused 0.45 against 0.25.
  const std::vector<std::vector<std::vector<Cell>>> script = {
      {{{0, 2, 2, 0, 0, 0, 0, 0.5f}, {0, 6, 6, 0, 0, 0, 0, 0.4f}}}, {{{0, 6, 6, 0, 0, 0, 0, 0.5f}}}};
  DetectorPipelineOptions o;
  o.flip_fusion = true;
  o.policy = "most_confident";
  const auto boxes = make(o, script).detect(image_1280x720());
  ASSERT_EQ(boxes.size(), 1u);
  EXPECT_NEAR(boxes[0].confidence, 0.45f, 1e-5);
  EXPECT_NEAR(boxes[0].cx, 6.5f * kCell * 1280 / 416, 1e-2);
}

/// The thesis network at 224 x 224 (grid 7): the coarse pass of a 416 x 416 one at coarse_scale 0.5.
DarknetModel thesis_224() {
  DarknetModel m = thesis();
  m.net.width = m.net.height = 224;
  compute_shapes(m);
  return m;
}

TEST(Algorithm2, CoarsePassFusesItsLargeBoxesAndCountsOnlyThePassesThatSeeASize) {
  // The 1280x720 image stretched to 416x416 (grid 13) and, coarse, to 224x224 (grid 7: a cell is 1280/7 x 720/7 image
  // pixels). The thesis network's anchor 0 is 1.08 x 1.19 cells.
  DetectorPipelineOptions o;
  o.coarse_pass = true;
  o.coarse_min_size = 100;
  ASSERT_EQ(coarse_net_size({416, 416}, o.coarse_scale), cv::Size(224, 224));
  const float two = std::log(2.0f), half = std::log(0.5f);
  const float fx = 1280.0f / 416, fy = 720.0f / 416, cx7 = 1280.0f / 7, cy7 = 720.0f / 7;
  // Full size: a drone at the centre (cell 6, 6; twice the anchor: 212.7 x 131.8 px), 0.7; a small one (the anchor,
  // 106.3 x 65.9: sqrt 83.7, under coarse_min_size) at row 10, column 2, 0.55.
  const std::vector<std::vector<std::vector<Cell>>> fine = {
      {{{0, 6, 6, 0, 0, two, two, 0.7f}, {0, 10, 2, 0, 0, 0, 0, 0.55f}}}};
  // Coarse: the centre drone (cell 3, 3; the anchor: 197.5 x 122.4 px), 0.5; a large drone only it finds at (1, 1),
  // 0.8; a small box (half the anchor: sqrt 77.7) at (5, 5), 0.9: dropped; a large box only it finds at (5, 3), 0.3:
  // 0.15 after fusion, under p_thresh.
  const std::vector<std::vector<std::vector<Cell>>> coarse = {{{{0, 3, 3, 0, 0, 0, 0, 0.5f},
                                                                {0, 1, 1, 0, 0, 0, 0, 0.8f},
                                                                {0, 5, 5, 0, 0, half, half, 0.9f},
                                                                {0, 5, 3, 0, 0, 0, 0, 0.3f}}}};
  std::vector<int> fine_batches, coarse_batches;
  auto nested = std::make_unique<DetectionPipeline>(
      coarse_pass_options(o), std::make_unique<FakeBackend>(coarse, 8, &coarse_batches, 7), thesis_224());
  DetectionPipeline p(o, std::make_unique<FakeBackend>(fine, 8, &fine_batches), thesis(), std::move(nested));
  ASSERT_NE(p.coarse(), nullptr);
  const std::vector<Box> boxes = p.detect(image_1280x720());
  EXPECT_EQ(fine_batches, (std::vector<int>{1}));
  EXPECT_EQ(coarse_batches, (std::vector<int>{1}));
  ASSERT_EQ(boxes.size(), 3u);
  // Both passes' centre drone: (0.7 + 0.5) / 2, the confidence-weighted mean box.
  EXPECT_NEAR(boxes[0].confidence, 0.6f, 1e-5);
  EXPECT_NEAR(boxes[0].cx, 640.0f, 1e-2);
  EXPECT_NEAR(boxes[0].cy, 360.0f, 1e-2);
  EXPECT_NEAR(boxes[0].w, (0.7f * 2 * 1.08f * kCell * fx + 0.5f * 1.08f * cx7) / 1.2f, 1e-2);
  EXPECT_NEAR(boxes[0].h, (0.7f * 2 * 1.19f * kCell * fy + 0.5f * 1.19f * cy7) / 1.2f, 1e-2);
  // The small drone: only the full-size pass sees its size, so it keeps its confidence.
  EXPECT_NEAR(boxes[1].confidence, 0.55f, 1e-5);
  EXPECT_NEAR(boxes[1].cx, 2.5f * kCell * fx, 1e-2);
  EXPECT_NEAR(boxes[1].cy, 10.5f * kCell * fy, 1e-2);
  // The large drone only the coarse pass found: half its confidence.
  EXPECT_NEAR(boxes[2].confidence, 0.4f, 1e-5);
  EXPECT_NEAR(boxes[2].cx, 1.5f * cx7, 1e-2);
  EXPECT_NEAR(boxes[2].cy, 1.5f * cy7, 1e-2);
  EXPECT_NEAR(boxes[2].w, 1.08f * cx7, 1e-2);
}

TEST(Algorithm2, CoarsePassWithFlipFusionRunsFourPassesAndNeedsItsPipeline) {
  // A drone at the centre that every pass finds at 0.8: four passes, fused at 0.8; the coarse pipeline's zoom-in is
  // off (coarse_pass_options()) while the full-size one zooms (1280x720 is larger than 416x416): one crop per view, at
  // full resolution around the centre, re-detects the drone at the first pass's size (106.3 x 65.9 px). The coarse
  // passes see it at 0.6 of their anchor (118.5 x 73.4 px; IoU 0.81 with it).
  DetectorPipelineOptions o;
  o.coarse_pass = true;
  o.flip_fusion = true;
  o.zoom_in = true;
  o.zoom_max_fraction = 0.5;  // the box is 0.26 of the network's width
  const float fx = 1280.0f / 416, fy = 720.0f / 416, shrink = std::log(0.6f);
  const std::vector<Cell> first = {{0, 6, 6, 0, 0, 0, 0, 0.8f}};
  const std::vector<Cell> crop = {{0, 6, 6, 0, 0, std::log(fx), std::log(fy), 0.8f}};
  const std::vector<Cell> coarse = {{0, 3, 3, 0, 0, shrink, shrink, 0.8f}};
  std::vector<int> fine_batches, coarse_batches;
  auto nested = std::make_unique<DetectionPipeline>(
      coarse_pass_options(o),
      std::make_unique<FakeBackend>(std::vector<std::vector<std::vector<Cell>>>{{coarse}, {coarse}}, 8, &coarse_batches,
                                    7),
      thesis_224());
  EXPECT_FALSE(nested->options().zoom_in);
  EXPECT_FALSE(nested->options().coarse_pass);
  DetectionPipeline p(
      o,
      std::make_unique<FakeBackend>(std::vector<std::vector<std::vector<Cell>>>{{first}, {crop}, {first}, {crop}}, 8,
                                    &fine_batches),
      thesis(), std::move(nested));
  const std::vector<Box> boxes = p.detect(image_1280x720());
  EXPECT_EQ(fine_batches, (std::vector<int>{1, 1, 1, 1}));  // image, its crop, mirror, its crop
  EXPECT_EQ(coarse_batches, (std::vector<int>{1, 1}));      // image, mirror
  ASSERT_EQ(boxes.size(), 1u);
  EXPECT_NEAR(boxes[0].confidence, 0.8f, 1e-5);
  EXPECT_NEAR(boxes[0].cx, 640.0f, 1.0f);

  // coarse_pass and the coarse pipeline go together, and the nested one must not zoom or nest again.
  const auto fake = [] {
    return std::make_unique<FakeBackend>(std::vector<std::vector<std::vector<Cell>>>{}, 1, nullptr);
  };
  const auto fake7 = [] {
    return std::make_unique<FakeBackend>(std::vector<std::vector<std::vector<Cell>>>{}, 1, nullptr, 7);
  };
  EXPECT_THROW(DetectionPipeline(o, fake(), thesis()), std::invalid_argument);
  DetectorPipelineOptions plain;
  EXPECT_THROW(
      DetectionPipeline(plain, fake(), thesis(),
                        std::make_unique<DetectionPipeline>(coarse_pass_options(plain), fake7(), thesis_224())),
      std::invalid_argument);
  DetectorPipelineOptions zooming;
  zooming.zoom_in = true;
  EXPECT_THROW(
      DetectionPipeline(o, fake(), thesis(), std::make_unique<DetectionPipeline>(zooming, fake7(), thesis_224())),
      std::invalid_argument);
}

TEST(DetectorPipelineOptions, CoarsePassKeysAndItsNetworkSize) {
  DetectorPipelineOptions o;
  EXPECT_FALSE(o.coarse_pass);  // the documented defaults
  EXPECT_DOUBLE_EQ(o.coarse_scale, 0.5);
  EXPECT_DOUBLE_EQ(o.coarse_min_size, 48.0);
  for (const double bad : {0.0, 1.0, -0.5, std::nan("")}) {
    o.coarse_scale = bad;
    const auto problems = o.validate();
    ASSERT_EQ(problems.size(), 1u) << bad;
    EXPECT_NE(problems[0].find("detection.coarse_scale"), std::string::npos) << problems[0];
  }
  o.coarse_scale = 0.5;
  for (const double bad : {-1.0, std::nan(""), HUGE_VAL}) {
    o.coarse_min_size = bad;
    const auto problems = o.validate();
    ASSERT_EQ(problems.size(), 1u) << bad;
    EXPECT_NE(problems[0].find("detection.coarse_min_size"), std::string::npos) << problems[0];
  }
  const auto loaded = common::load_options_from_string<DetectorPipelineOptions>(
      "detection: {coarse_pass: true, coarse_scale: 0.6, coarse_min_size: 32}", "t.yaml");
  EXPECT_TRUE(loaded.coarse_pass);
  EXPECT_DOUBLE_EQ(loaded.coarse_scale, 0.6);
  EXPECT_DOUBLE_EQ(loaded.coarse_min_size, 32.0);
  // Sides times the scale, to the nearest multiple of 32 (halves up), at least 32.
  EXPECT_EQ(coarse_net_size({640, 352}, 0.5), cv::Size(320, 192));  // 176 is 5.5 x 32: up
  EXPECT_EQ(coarse_net_size({640, 352}, 0.4), cv::Size(256, 128));  // 140.8
  EXPECT_EQ(coarse_net_size({640, 352}, 0.6), cv::Size(384, 224));  // 211.2
  EXPECT_EQ(coarse_net_size({64, 32}, 0.1), cv::Size(32, 32));
  EXPECT_THROW(coarse_net_size({640, 352}, 1.0), std::invalid_argument);
  EXPECT_THROW(coarse_net_size({0, 352}, 0.5), std::invalid_argument);
  const DetectorPipelineOptions nested = coarse_pass_options(loaded);
  EXPECT_FALSE(nested.coarse_pass);
  EXPECT_FALSE(nested.zoom_in);
  EXPECT_DOUBLE_EQ(nested.p_thresh, loaded.p_thresh);
}

TEST(DetectorPipelineOptions, FusionIouOutsideZeroToOneIsNamed) {
  DetectorPipelineOptions o;
  EXPECT_DOUBLE_EQ(o.fusion_iou, 0.3);  // the documented default
  EXPECT_FALSE(o.flip_fusion);
  for (const double bad : {-0.1, 1.5, std::nan("")}) {
    o.fusion_iou = bad;
    const auto problems = o.validate();
    ASSERT_EQ(problems.size(), 1u) << bad;
    EXPECT_NE(problems[0].find("detection.fusion_iou"), std::string::npos) << problems[0];
  }
  const auto loaded = common::load_options_from_string<DetectorPipelineOptions>(
      "detection: {flip_fusion: true, fusion_iou: 0.5}", "t.yaml");
  EXPECT_TRUE(loaded.flip_fusion);
  EXPECT_DOUBLE_EQ(loaded.fusion_iou, 0.5);
}

TEST(Algorithm2, RejectsABackendThatDoesNotFitTheModel) {
  class Wrong : public FakeBackend {
   public:
    Wrong() : FakeBackend({}, 1, nullptr) {}
    std::vector<Shape> output_shapes() const override { return {{125, 13, 13}}; }
  };
  EXPECT_THROW(DetectionPipeline(DetectorPipelineOptions{}, std::make_unique<Wrong>(), thesis()),
               std::invalid_argument);
}

TEST(Algorithm2, DecodesBothHeadsOfATinyYoloV3) {
  // A fake backend for the 416 two-head network: one confident cell in each head, nothing elsewhere.
  class TwoHeads : public InferenceBackend {
   public:
    std::string name() const override { return "fake-yolo"; }
    Shape input_shape() const override { return {3, 416, 416}; }
    std::vector<Shape> output_shapes() const override { return {{18, 13, 13}, {18, 26, 26}}; }
    int max_batch() const override { return 1; }
    void forward(const float*, int batch, std::vector<float>& output) override {
      const int p13 = 13 * 13, p26 = 26 * 26;
      output.assign(static_cast<size_t>(batch) * 18 * (p13 + p26), 0.0f);
      float* a = output.data();
      float* b = a + 18 * p13;
      for (int k = 0; k < 3; ++k) {
        for (int p = 0; p < p13; ++p) a[(k * 6 + 4) * p13 + p] = -30.0f;
        for (int p = 0; p < p26; ++p) b[(k * 6 + 4) * p26 + p] = -30.0f;
      }
      // Head 1 (stride 32), mask entry 0 = anchor 3 (81 x 82 px), row 2, column 3: centre (112, 80).
      a[4 * p13 + 2 * 13 + 3] = 3.0f;
      a[5 * p13 + 2 * 13 + 3] = 3.0f;
      // Head 2 (stride 16), mask entry 2 = anchor 2 (37 x 58 px), row 20, column 10: centre (168, 328).
      b[(2 * 6 + 4) * p26 + 20 * 26 + 10] = 1.0f;
      b[(2 * 6 + 5) * p26 + 20 * 26 + 10] = 2.0f;
    }
  };
  const DarknetModel m = parse_darknet_cfg_string(two_head_cfg(416, 1), "two-heads.cfg");
  DetectionPipeline p(DetectorPipelineOptions{}, std::make_unique<TwoHeads>(), m);
  const cv::Mat img(416, 416, CV_8UC3, cv::Scalar(0, 0, 0));  // network-sized: image pixels = network pixels
  const auto boxes = p.detect(img);
  ASSERT_EQ(boxes.size(), 2u);
  EXPECT_NEAR(boxes[0].confidence, sigmoid(3.0f) * sigmoid(3.0f), 1e-5);  // 0.907
  EXPECT_NEAR(boxes[0].cx, 112.0f, 1e-3);
  EXPECT_NEAR(boxes[0].cy, 80.0f, 1e-3);
  EXPECT_NEAR(boxes[0].w, 81.0f, 1e-3);
  EXPECT_NEAR(boxes[0].h, 82.0f, 1e-3);
  EXPECT_NEAR(boxes[1].confidence, sigmoid(1.0f) * sigmoid(2.0f), 1e-5);  // 0.644
  EXPECT_NEAR(boxes[1].cx, 168.0f, 1e-3);
  EXPECT_NEAR(boxes[1].cy, 328.0f, 1e-3);
  EXPECT_NEAR(boxes[1].w, 37.0f, 1e-3);
  EXPECT_NEAR(boxes[1].h, 58.0f, 1e-3);
  // The backend's outputs must be the heads' inputs, in order.
  class Swapped : public TwoHeads {
   public:
    std::vector<Shape> output_shapes() const override { return {{18, 26, 26}, {18, 13, 13}}; }
  };
  EXPECT_THROW(DetectionPipeline(DetectorPipelineOptions{}, std::make_unique<Swapped>(), m), std::invalid_argument);
}

TEST(Algorithm2, RunsATinyYoloV3OnTheCpuBackendWithRandomWeights) {
  DarknetModel m = parse_darknet_cfg_string(two_head_cfg(416, 1), "two-heads.cfg");
  randomize_weights(m, 5);
  DetectorPipelineOptions o;
  o.p_thresh = 0.0;  // keep every cell and anchor of both heads...
  o.o_thresh = 1.0;  // ...and suppress none (IoU > 1 never happens)
  o.max_detections = 10000;
  DetectionPipeline p(o, std::make_unique<CpuBackend>(m, 1), m);
  cv::Mat img(480, 640, CV_8UC3);
  cv::randu(img, 0, 255);
  const auto boxes = p.detect(img);
  EXPECT_EQ(boxes.size(), 3u * 13 * 13 + 3u * 26 * 26);
  for (size_t i = 1; i < boxes.size(); ++i) ASSERT_GE(boxes[i - 1].confidence, boxes[i].confidence);
}

TEST(Algorithm2, RunsOnTheCpuBackendWithRandomWeights) {
  DarknetModel m = thesis();
  randomize_weights(m, 99);
  cv::Mat img(720, 1280, CV_8UC3);
  cv::randu(img, 0, 255);
  for (const bool flip : {false, true}) {
    DetectorPipelineOptions o;
    o.subsquare = true;
    o.zoom_in = true;
    o.flip_fusion = flip;
    o.p_thresh = 0.0;  // random weights: keep every box
    DetectionPipeline p(o, std::make_unique<CpuBackend>(m, 4), m);
    const auto boxes = p.detect(img);
    ASSERT_FALSE(boxes.empty()) << "flip_fusion " << flip;
    EXPECT_LE(boxes.size(), 10u);
    for (size_t i = 1; i < boxes.size(); ++i) EXPECT_GE(boxes[i - 1].confidence, boxes[i].confidence);
    for (const Box& b : boxes) EXPECT_TRUE(b.confidence >= 0.0f && b.confidence <= 1.0f && b.w > 0 && b.h > 0);
  }
}

}  // namespace
}  // namespace wingman::detector
