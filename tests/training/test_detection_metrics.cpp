// SPDX-License-Identifier: MIT
// Detection metrics against a hand-computed case: matching, precision, recall, mean IoU, AP, PR curve, size bins.
#include <wingman/training/detection_metrics.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <utility>

namespace wingman::training {
namespace {

detector::Box box(float cx, float cy, float w, float h, float conf = 0.f) {
  detector::Box b;
  b.cx = cx, b.cy = cy, b.w = w, b.h = h, b.confidence = conf;
  return b;
}

// Three images worked out by hand (boxes in pixels, centre and size):
//  A: truths T1 (50,50,20,20) and T2 (150,50,10,10);
//     P1 (52,50,20,20) 0.9: IoU with T1 = 18*20 / (400 + 400 - 360) = 360/440 = 0.81818;
//     P2 (150,52,30,30) 0.6: IoU with T2 = 100/900 = 0.11111 (< 0.5), but its centre is inside T2;
//     P3 (300,300,10,10) 0.3: nothing.
//  B: truth T3 (100,100,40,40); P5 (102,100,40,40) 0.8: IoU 38*40 / (3200 - 1520) = 0.90476;
//     P4 (100,100,40,40) 0.1: IoU 1, but T3 is already taken by the more confident P5.
//  C: no truth; P6 (10,10,8,8) 0.5.
ImageDetections image(std::vector<detector::Box> truths, std::vector<detector::Box> predictions) {
  ImageDetections d;
  d.truths = std::move(truths);
  d.predictions = std::move(predictions);
  return d;  // no name and no size: the edge test is off
}

std::vector<ImageDetections> hand_case() {
  return {image({box(50, 50, 20, 20), box(150, 50, 10, 10)},
                {box(52, 50, 20, 20, 0.9f), box(150, 52, 30, 30, 0.6f), box(300, 300, 10, 10, 0.3f)}),
          image({box(100, 100, 40, 40)}, {box(100, 100, 40, 40, 0.1f), box(102, 100, 40, 40, 0.8f)}),
          image({}, {box(10, 10, 8, 8, 0.5f)})};
}

constexpr double kIouP1 = 360.0 / 440.0;
constexpr double kIouP5 = 1520.0 / 1680.0;
constexpr double kIouP2 = 100.0 / 900.0;

TEST(DetectionMetrics, DefaultsAreValid) { EXPECT_TRUE(MetricsOptions{}.validate().empty()); }

TEST(DetectionMetrics, IouCriterionMatchesHandComputedCase) {
  MetricsOptions o;
  o.pr_points = 3;  // recall 0, 0.5, 1
  const DetectionMetrics m = evaluate_detections(hand_case(), o);
  EXPECT_EQ(m.images, 3);
  EXPECT_EQ(m.negative_images, 1);
  EXPECT_EQ(m.truths, 3);
  EXPECT_EQ(m.predictions, 6);
  const MatchStats& s = m.iou.all;
  // At confidence >= 0.2: P1 TP, P5 TP, P2 FP, P6 FP, P3 FP (P4 is below the operating point).
  EXPECT_EQ(s.detections, 5);
  EXPECT_EQ(s.true_positives, 2);
  EXPECT_EQ(s.false_positives, 3);
  EXPECT_DOUBLE_EQ(s.precision, 0.4);
  EXPECT_DOUBLE_EQ(s.recall, 2.0 / 3.0);
  EXPECT_NEAR(s.f1, 2 * 0.4 * (2.0 / 3.0) / (0.4 + 2.0 / 3.0), 1e-12);
  EXPECT_NEAR(s.mean_iou, (kIouP1 + kIouP5) / 2, 1e-6);
  // Ranked: TP TP FP FP FP FP: recall 1/3 and 2/3 at precision 1, never more: AP = 2/3.
  EXPECT_NEAR(s.ap, 2.0 / 3.0, 1e-12);
  ASSERT_EQ(m.iou.pr_curve.size(), 3u);
  EXPECT_DOUBLE_EQ(m.iou.pr_curve[0].precision, 1.0);
  EXPECT_FLOAT_EQ(static_cast<float>(m.iou.pr_curve[0].confidence), 0.9f);
  EXPECT_DOUBLE_EQ(m.iou.pr_curve[1].precision, 1.0);  // recall 0.5 first reached by P5 (2/3)
  EXPECT_FLOAT_EQ(static_cast<float>(m.iou.pr_curve[1].confidence), 0.8f);
  EXPECT_DOUBLE_EQ(m.iou.pr_curve[2].precision, 0.0);  // recall 1 is never reached
}

TEST(DetectionMetrics, CentreInBoxCriterionMatchesHandComputedCase) {
  const DetectionMetrics m = evaluate_detections(hand_case(), MetricsOptions{});
  const MatchStats& s = m.centre.all;
  // P1, P5 and P2 (centre inside T2) match; P6, P3 and P4 (T3 taken) do not.
  EXPECT_EQ(s.detections, 5);
  EXPECT_EQ(s.true_positives, 3);
  EXPECT_EQ(s.false_positives, 2);
  EXPECT_DOUBLE_EQ(s.precision, 0.6);
  EXPECT_DOUBLE_EQ(s.recall, 1.0);
  EXPECT_NEAR(s.mean_iou, (kIouP1 + kIouP5 + kIouP2) / 3, 1e-6);
  EXPECT_NEAR(s.ap, 1.0, 1e-12);  // the three TPs come first
}

TEST(DetectionMetrics, SizeBinsFollowTheTruthOrTheUnmatchedPrediction) {
  const DetectionMetrics m = evaluate_detections(hand_case(), MetricsOptions{});
  ASSERT_EQ(m.iou.by_size.size(), 4u);
  EXPECT_EQ(m.iou.by_size[0].name, "<16px");
  EXPECT_EQ(m.iou.by_size[3].name, ">=64px");
  // <16: T2 (10 px) unfound; P3 (10 px) and P6 (8 px) are its false positives.
  const MatchStats& tiny = m.iou.by_size[0].stats;
  EXPECT_EQ(tiny.truths, 1);
  EXPECT_EQ(tiny.true_positives, 0);
  EXPECT_EQ(tiny.false_positives, 2);
  EXPECT_DOUBLE_EQ(tiny.recall, 0.0);
  EXPECT_DOUBLE_EQ(tiny.ap, 0.0);
  // 16-32: T1 (20 px) found by P1; P2 (30 px, unmatched) is a false positive here.
  const MatchStats& small = m.iou.by_size[1].stats;
  EXPECT_EQ(small.truths, 1);
  EXPECT_EQ(small.true_positives, 1);
  EXPECT_EQ(small.false_positives, 1);
  EXPECT_DOUBLE_EQ(small.ap, 1.0);
  // 32-64: T3 (40 px) found by P5; P4 (below 0.2) only enters the AP, after the TP.
  const MatchStats& medium = m.iou.by_size[2].stats;
  EXPECT_EQ(medium.truths, 1);
  EXPECT_EQ(medium.detections, 1);
  EXPECT_EQ(medium.true_positives, 1);
  EXPECT_DOUBLE_EQ(medium.precision, 1.0);
  EXPECT_DOUBLE_EQ(medium.ap, 1.0);
  EXPECT_EQ(m.iou.by_size[3].stats.truths, 0);
  // Centre criterion: T2 found by P2 in its own bin.
  EXPECT_EQ(m.centre.by_size[0].stats.true_positives, 1);
  EXPECT_EQ(m.centre.by_size[0].stats.false_positives, 2);
}

TEST(DetectionMetrics, ConfidenceThresholdMovesTheOperatingPointNotTheAp) {
  MetricsOptions o;
  o.conf_thresh = 0.05;  // P4 now counts: a duplicate, so a false positive
  const DetectionMetrics m = evaluate_detections(hand_case(), o);
  EXPECT_EQ(m.iou.all.detections, 6);
  EXPECT_EQ(m.iou.all.false_positives, 4);
  EXPECT_NEAR(m.iou.all.ap, 2.0 / 3.0, 1e-12);
}

TEST(DetectionMetrics, JsonAndReportCarryTheNumbers) {
  const DetectionMetrics m = evaluate_detections(hand_case(), MetricsOptions{});
  const nlohmann::json j = nlohmann::json::parse(m.json());
  EXPECT_EQ(j["iou"]["criterion"], "iou") << j;
  EXPECT_EQ(j["centre"]["criterion"], "centre") << j;
  EXPECT_NEAR(j["iou"]["all"]["ap"].get<double>(), 2.0 / 3.0, 1e-12) << j;
  EXPECT_TRUE(j["iou"]["by_size"].back()["max_px"].is_null()) << j;  // the last size bin is open
  EXPECT_EQ(j["iou"]["pr_curve_columns"], nlohmann::json({"recall", "precision", "confidence"}));
  EXPECT_NE(m.report().find("16-32px"), std::string::npos);
  EXPECT_NE(m.one_line().find("AP 0.667"), std::string::npos) << m.one_line();
}

// The hand case plus image D (200 x 100, named "d"): truth T4 (11,50,20,20) reaches x = 1, the image's edge
// at the default margin of 1 px; truth T5 (100,50,10,10). P7 (130,50,10,10) 0.7 overlaps neither (IoU 0);
// P8 (100,50,10,10) 0.1 matches T5 exactly but is below the operating point, so T5 counts as missed there.
std::vector<ImageDetections> hand_case_with_edge() {
  std::vector<ImageDetections> images = hand_case();
  ImageDetections d =
      image({box(11, 50, 20, 20), box(100, 50, 10, 10)}, {box(130, 50, 10, 10, 0.7f), box(100, 50, 10, 10, 0.1f)});
  d.name = "d", d.width = 200, d.height = 100;
  images.push_back(d);
  return images;
}

TEST(DetectionMetrics, UnmatchedTruthsSayWhatTheDetectorDidThere) {
  const DetectionMetrics m = evaluate_detections(hand_case_with_edge(), MetricsOptions{});
  // IoU: T2 is loose (P2's centre is inside, IoU 1/9); T4 and T5 are missed (P8 is under 0.2).
  ASSERT_EQ(m.iou.unmatched.size(), 3u);
  const UnmatchedTruth& t2 = m.iou.unmatched[0];
  EXPECT_EQ(t2.image, 0u);
  EXPECT_EQ(t2.reason, "loose");
  EXPECT_NEAR(t2.best_iou, kIouP2, 1e-6);
  EXPECT_FLOAT_EQ(t2.best.confidence, 0.6f);
  EXPECT_FLOAT_EQ(t2.best.w, 30.f);
  EXPECT_FALSE(t2.at_edge);  // image A's size is unknown
  const UnmatchedTruth& t4 = m.iou.unmatched[1];
  EXPECT_EQ(t4.image, 3u);
  EXPECT_EQ(t4.image_name, "d");
  EXPECT_EQ(t4.reason, "missed");
  EXPECT_DOUBLE_EQ(t4.best_iou, 0.0);
  EXPECT_TRUE(t4.at_edge);
  EXPECT_EQ(m.iou.unmatched[2].reason, "missed");
  EXPECT_FLOAT_EQ(m.iou.unmatched[2].truth.cx, 100.f);
  EXPECT_FALSE(m.iou.unmatched[2].at_edge);
  EXPECT_EQ(m.iou.edge_truths, 1);
  EXPECT_EQ(m.iou.edge_found, 0);
  // Centre in box: T1, T2 and T3 are found; T4 and T5 are not.
  ASSERT_EQ(m.centre.unmatched.size(), 2u);
  EXPECT_EQ(m.centre.unmatched[0].image_name, "d");
  EXPECT_EQ(m.centre.unmatched[0].reason, "missed");

  MetricsOptions narrow;
  narrow.edge_margin_px = 0.5;  // T4's left side at x = 1 is now inside
  const DetectionMetrics n = evaluate_detections(hand_case_with_edge(), narrow);
  EXPECT_EQ(n.iou.edge_truths, 0);
  EXPECT_FALSE(n.iou.unmatched[1].at_edge);

  // The report lists the largest first (T4, then T2 and T5 in image order); the JSON lists every one.
  const std::string r = m.report();
  EXPECT_NE(r.find("not found at confidence >= 0.2: 3 of 5 truths (2 missed: no detection overlaps them; 1 loose"),
            std::string::npos)
      << r;
  EXPECT_NE(r.find("at the image's edge: 1 of the 1 truths there"), std::string::npos) << r;
  EXPECT_NE(r.find("    d truth 20x20 at (11, 50) at the edge: missed\n"
                   "    image 0 truth 10x10 at (150, 50): loose, best 30x30 at (150, 52) IoU 0.11 confidence 0.60\n"
                   "    d truth 10x10 at (100, 50): missed\n"),
            std::string::npos)
      << r;
  EXPECT_EQ(m.report(1).find("image 0 truth"), std::string::npos) << m.report(1);
  const nlohmann::json j = nlohmann::json::parse(m.json());
  EXPECT_EQ(j["iou"]["edge_truths"], 1) << j;
  EXPECT_EQ(j["iou"]["edge_found"], 0) << j;
  const nlohmann::json& unmatched = j["iou"]["unmatched"];
  const auto find = [&](const std::string& name, const std::string& reason, bool at_edge) {
    for (const nlohmann::json& u : unmatched)
      if (u.at("name") == name && u.at("reason") == reason && u.at("at_edge") == at_edge) return u;
    return nlohmann::json();
  };
  const nlohmann::json loose = find("", "loose", false);
  ASSERT_FALSE(loose.is_null()) << j;
  EXPECT_EQ(loose["image"], 0);
  EXPECT_EQ(loose["name"], "");
  EXPECT_EQ(loose["truth"], nlohmann::json({150.0, 50.0, 10.0, 10.0}));
  EXPECT_DOUBLE_EQ(loose["size_px"].get<double>(), 10.0);
  EXPECT_EQ(loose["at_edge"], false);
  EXPECT_NEAR(loose["best_iou"].get<double>(), 100.0 / 900.0, 1e-6);  // the 10x10 truth inside the 30x30 box
  ASSERT_EQ(loose["best"].size(), 5u);
  EXPECT_FLOAT_EQ(loose["best"][1].get<float>(), 52.0f);
  EXPECT_FLOAT_EQ(loose["best"][2].get<float>(), 30.0f);
  EXPECT_NEAR(loose["best"][4].get<double>(), 0.6, 1e-6);  // a float confidence
  const nlohmann::json edge = find("d", "missed", true);
  ASSERT_FALSE(edge.is_null()) << j;
  EXPECT_EQ(edge["truth"], nlohmann::json({11.0, 50.0, 20.0, 20.0}));
  EXPECT_DOUBLE_EQ(edge["size_px"].get<double>(), 20.0);
  EXPECT_EQ(edge["best_iou"], 0.0);
  EXPECT_TRUE(edge["best"].is_null());
}

TEST(DetectionMetrics, ImageNamesAreEscapedInTheJson) {
  std::vector<ImageDetections> images(1);
  images[0].truths = {box(10, 10, 4, 4)};
  images[0].name = "a \"b\".png";
  const std::string j = evaluate_detections(images, MetricsOptions{}).json();
  EXPECT_NE(j.find("\"name\": \"a \\\"b\\\".png\""), std::string::npos) << j;
  EXPECT_EQ(nlohmann::json::parse(j)["iou"]["unmatched"][0]["name"], "a \"b\".png");
}

TEST(DetectionMetrics, InvalidOptionsAreNamed) {
  MetricsOptions o;
  o.iou_thresh = 0;
  o.size_edges_px = {32, 16};
  o.edge_margin_px = -1;
  try {
    evaluate_detections(hand_case(), o);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("iou_thresh = 0"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("size_edges_px[1] = 16"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("edge_margin_px = -1: must be >= 0"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace wingman::training
