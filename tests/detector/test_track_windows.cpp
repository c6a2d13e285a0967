// SPDX-License-Identifier: MIT
// Tracker-driven windows in the detector: which windows to search, where their crops go, and how their boxes join the
// single pass's.
#include "wingman/detector/track_windows.hpp"

#include "wingman/detector/cpu_backend.hpp"
#include "wingman/detector/darknet_cfg.hpp"
#include "wingman/detector/darknet_weights.hpp"
#include "wingman/detector/model_loader.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace wingman::detector {
namespace {

constexpr int64_t kT = 1700000000000000;
const cv::Size kImage(1280, 720);

wingman::track_window_t window(float cx, float cy, float w, float h, float sigma, bool confirmed = true) {
  wingman::track_window_t t{};
  t.track_id = confirmed ? 1 : 0;
  t.confirmed = confirmed;
  t.cx = cx;
  t.cy = cy;
  t.w = w;
  t.h = h;
  t.sigma_px = sigma;
  t.range_m = 25;
  t.confidence = 0.7f;
  return t;
}

wingman::track_windows_t message(std::vector<wingman::track_window_t> windows) {
  wingman::track_windows_t m{};
  m.utime = kT - 33333;
  m.utime_predicted = kT;
  m.camera_id = 0;
  m.image_width = 1280;
  m.image_height = 720;
  m.windows = std::move(windows);
  m.num_windows = static_cast<int32_t>(m.windows.size());
  return m;
}

Box box(float cx, float cy, float w, float h, float confidence, int class_id = 0) {
  Box b;
  b.cx = cx;
  b.cy = cy;
  b.w = w;
  b.h = h;
  b.confidence = confidence;
  b.class_id = class_id;
  b.drone_score = class_id == 0 ? confidence : 0.01f;
  return b;
}

TEST(WindowsToSearch, OnlySmallWindowsOfThisCameraSizeAndTimeMovedToTheExposure) {
  WindowOptions o;  // max_net_px 14; the single pass sees 0.5 network pixels per image pixel (640 of 1280)
  auto m = message({window(600, 300, 20, 16, 3), window(100, 100, 40, 30, 3), window(1400, 300, 20, 16, 3),
                    window(700, 400, 10, 8, 2, false)});
  m.windows[0].vx = 300;  // pixels/s
  m.windows[0].vy = -150;
  // 10 ms after the predicted exposure: the first window moved 3 px right and 1.5 px up.
  const auto w = windows_to_search(m, kT + 10000, kImage, 0, 0.5, o);
  ASSERT_EQ(w.size(), 2u);  // the 40x30 one is 17 network px (seen well), the third is outside the image
  EXPECT_NEAR(w[0].cx, 603.0, 1e-6);
  EXPECT_NEAR(w[0].cy, 298.5, 1e-6);
  EXPECT_TRUE(w[0].confirmed);
  EXPECT_FALSE(w[1].confirmed);
  o.confirmed_only = true;
  EXPECT_EQ(windows_to_search(m, kT, kImage, 0, 0.5, o).size(), 1u);
  o.confirmed_only = false;
  EXPECT_TRUE(windows_to_search(m, kT, kImage, 1, 0.5, o).empty());              // another camera
  EXPECT_TRUE(windows_to_search(m, kT, cv::Size(640, 360), 0, 0.5, o).empty());  // another image size
  EXPECT_TRUE(windows_to_search(m, kT + 600000, kImage, 0, 0.5, o).empty());     // 0.6 s > max_age_s
  EXPECT_TRUE(windows_to_search(m, kT - 600000, kImage, 0, 0.5, o).empty());     // predicted for much later
  EXPECT_EQ(windows_to_search(m, kT, kImage, 0, 1.0, o).size(), 1u);             // full-resolution single pass
}

TEST(PlaceWindowCrops, WindowsShareACropTheyFitInAndTheBudgetLimitsTheRest) {
  WindowOptions o;  // 256 px crops, 2 per frame, gate 3 sigma + half the box
  std::vector<Window> w(4);
  w[0] = {640, 360, 20, 16, 3, true, 1};
  w[1] = {700, 380, 20, 16, 3, false, 0};   // inside the first crop with its gate
  w[2] = {10, 700, 20, 16, 3, true, 2};     // a corner: the crop is clamped inside the image
  w[3] = {1000, 100, 20, 16, 3, false, 0};  // over the budget
  std::vector<int> crop_of;
  const auto crops = place_window_crops(w, kImage, o, crop_of);
  ASSERT_EQ(crops.size(), 2u);
  EXPECT_EQ(crops[0], cv::Rect(512, 232, 256, 256));
  EXPECT_EQ(crops[1], cv::Rect(0, 464, 256, 256));
  EXPECT_EQ(crop_of, (std::vector<int>{0, 0, 1, -1}));
  // A small image: the crop is the whole image.
  std::vector<int> small_of;
  const auto small = place_window_crops({w[0]}, cv::Size(200, 100), o, small_of);
  ASSERT_EQ(small.size(), 1u);
  EXPECT_EQ(small[0], cv::Rect(0, 0, 200, 100));
}

TEST(MergeWindowBoxes, TheWindowsBoxInItsGateReplacesTheSinglePassBoxOfTheSameDrone) {
  WindowOptions o;
  DetectorPipelineOptions p;  // o_thresh 0.2, max_detections 10
  const std::vector<Window> w = {{640, 360, 12, 10, 2, true, 1}, {200, 600, 12, 10, 2, false, 0}};
  const std::vector<cv::Rect> crops = {cv::Rect(512, 232, 256, 256), cv::Rect(72, 464, 256, 256)};
  const std::vector<int> crop_of = {0, 1};
  // Crop 0: the drone near the prediction (crop pixels 129, 130 = image 641, 362), a less confident box elsewhere
  // in the crop (outside the gate: 3 x 2 + 6 = 12 px) and a bird box on the prediction. Crop 1: nothing in the gate.
  const std::vector<std::vector<Box>> crop_boxes = {
      {box(129, 130, 11, 9, 0.5f), box(20, 20, 11, 9, 0.9f), box(128, 128, 11, 9, 0.95f, 2)},
      {box(10, 10, 11, 9, 0.9f)}};
  // The single pass: a coarse box on the same drone and a box elsewhere.
  const std::vector<Box> first = {box(642, 361, 16, 14, 0.3f), box(1000, 200, 30, 20, 0.6f)};
  WindowStats stats;
  const auto out = merge_window_boxes(first, w, crops, crop_of, crop_boxes, p, o, &stats);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_FLOAT_EQ(out[0].cx, 1000.0f);  // most confident first
  EXPECT_EQ(out[0].pass, Pass::kSingle);
  EXPECT_FLOAT_EQ(out[1].cx, 641.0f);
  EXPECT_FLOAT_EQ(out[1].cy, 362.0f);
  EXPECT_FLOAT_EQ(out[1].w, 11.0f);
  EXPECT_FLOAT_EQ(out[1].confidence, 0.5f);
  EXPECT_EQ(out[1].pass, Pass::kWindow);
  EXPECT_EQ(stats.windows, 2);
  EXPECT_EQ(stats.crops, 2);
  EXPECT_EQ(stats.found, 1);
  // A far drone's single-pass box: twice the size and offset downwards, touching the window's box (IoU 0), its centre
  // in the window's gate (12 px): the same drone, replaced.
  const std::vector<Box> coarse = {box(643, 368, 24, 9, 0.31f)};
  const std::vector<std::vector<Box>> found_at = {{box(128, 129, 14, 6, 0.5f)}, {}};  // image (640, 361)
  const auto replaced = merge_window_boxes(coarse, w, crops, crop_of, found_at, p, o);
  ASSERT_EQ(replaced.size(), 1u);
  EXPECT_EQ(replaced[0].pass, Pass::kWindow);
  EXPECT_FLOAT_EQ(replaced[0].w, 14.0f);
  // With policy most_confident, one box.
  p.policy = "most_confident";
  EXPECT_EQ(merge_window_boxes(first, w, crops, crop_of, crop_boxes, p, o).size(), 1u);
  // A window left out by the budget (crop -1) finds nothing.
  const auto none = merge_window_boxes(first, w, crops, {-1, -1}, crop_boxes, DetectorPipelineOptions{}, o);
  EXPECT_EQ(none.size(), 2u);
  EXPECT_EQ(none[0].pass, Pass::kSingle);
  EXPECT_EQ(none[1].pass, Pass::kSingle);
  EXPECT_THROW(merge_window_boxes(first, w, crops, {0}, crop_boxes, DetectorPipelineOptions{}, o),
               std::invalid_argument);
}

// The batched path against the plain one: detect_regions() on three crops in batches of two (a real CPU backend, the
// thesis network at 128x128 with random weights, a low threshold so that there are boxes) gives each crop's
// detect(), in the crop's pixels.
TEST(DetectRegions, BatchedCropsGiveEachCropsOwnDetection) {
  DarknetModel model = parse_darknet_cfg_string(builtin_thesis_cfg(), "thesis");
  model.net.width = model.net.height = 128;
  compute_shapes(model);
  randomize_weights(model, 11);
  DetectorPipelineOptions o;
  o.p_thresh = 0.05;
  DetectionPipeline batched(o, std::make_unique<CpuBackend>(model, 2), model);
  DetectionPipeline plain(o, std::make_unique<CpuBackend>(model, 1), model);
  cv::Mat image(300, 400, CV_8UC3);
  cv::theRNG().state = 5;
  cv::randu(image, cv::Scalar::all(0), cv::Scalar::all(255));
  const std::vector<cv::Rect> crops = {cv::Rect(0, 0, 128, 128), cv::Rect(250, 100, 128, 128),
                                       cv::Rect(100, 150, 150, 150)};
  const auto out = batched.detect_regions(image, crops);
  ASSERT_EQ(out.size(), crops.size());
  size_t boxes = 0;
  for (size_t c = 0; c < crops.size(); ++c) {
    const std::vector<Box> expected = plain.detect(image(crops[c]).clone());
    ASSERT_EQ(out[c].size(), expected.size()) << "crop " << c;
    for (size_t k = 0; k < expected.size(); ++k) {
      EXPECT_NEAR(out[c][k].cx, expected[k].cx, 1e-3) << c << "/" << k;
      EXPECT_NEAR(out[c][k].cy, expected[k].cy, 1e-3) << c << "/" << k;
      EXPECT_NEAR(out[c][k].w, expected[k].w, 1e-3) << c << "/" << k;
      EXPECT_NEAR(out[c][k].confidence, expected[k].confidence, 1e-5) << c << "/" << k;
    }
    boxes += expected.size();
  }
  EXPECT_GT(boxes, 0u) << "no box in any crop: the comparison proves nothing";
  EXPECT_THROW(batched.detect_regions(image, {cv::Rect(350, 0, 128, 128)}), std::invalid_argument);  // leaves it
}

TEST(WindowOptions, EveryBadKeyIsNamed) {
  WindowOptions o;
  EXPECT_TRUE(o.validate().empty());
  o.channel = "";
  o.crop_px = 250;
  o.max_per_frame = 0;
  o.max_net_px = 0;
  o.p_thresh = 1.5;
  o.gate_sigma = -1;
  o.max_age_s = 0;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 7u);
  for (const char* key : {"windows.channel", "windows.crop_px", "windows.max_per_frame", "windows.max_net_px",
                          "windows.p_thresh", "windows.gate_sigma", "windows.max_age_s"}) {
    bool named = false;
    for (const auto& line : p) named = named || line.find(key) != std::string::npos;
    EXPECT_TRUE(named) << key;
  }
}

}  // namespace
}  // namespace wingman::detector
