// SPDX-License-Identifier: MIT
// Tests of `wingman report`'s axis ticks (round 1-2-5 steps, hand-computed cases), tick labels, and the headline
// of a flight with nothing measured. The report of real logs: test_eval.cpp (Report.*) and report_chromium_test.sh.
#include <wingman/tools/report.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace wingman::tools {
namespace {

void expect_ticks(const AxisTicks& t, double step, const std::vector<double>& values) {
  EXPECT_DOUBLE_EQ(t.step, step);
  ASSERT_EQ(t.values.size(), values.size());
  for (size_t i = 0; i < values.size(); ++i) EXPECT_NEAR(t.values[i], values[i], 1e-9 * std::max(1.0, step)) << i;
  EXPECT_DOUBLE_EQ(t.lo, t.values.front());
  EXPECT_DOUBLE_EQ(t.hi, t.values.back());
}

TEST(NiceTicks, HandComputedCases) {
  // 0..1640 in at most 5 intervals: 100 needs 17, 200 needs 9, 500 needs 4.
  expect_ticks(nice_ticks(0, 1640, 5), 500, {0, 500, 1000, 1500, 2000});
  // -7.62..4.01 in at most 6: 1 needs 13 (-8..5), 2 needs 7 (-8..6), 5 needs 3 (-10..5).
  expect_ticks(nice_ticks(-7.62, 4.01, 6), 5, {-10, -5, 0, 5});
  // ... in at most 8: 2.
  expect_ticks(nice_ticks(-7.62, 4.01, 8), 2, {-8, -6, -4, -2, 0, 2, 4, 6});
  // 0..0.37 in at most 6: 0.01, 0.02, 0.05 need 37, 19, 8; 0.1 needs 4.
  expect_ticks(nice_ticks(0, 0.37, 6), 0.1, {0, 0.1, 0.2, 0.3, 0.4});
  // 0..95 s in at most 10: 10.
  expect_ticks(nice_ticks(0, 95, 10), 10, {0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100});
  // A bound on a tick stays that tick (0.3 / 0.1 is 2.9999999999999996 in doubles).
  expect_ticks(nice_ticks(0, 0.3, 3), 0.1, {0, 0.1, 0.2, 0.3});
  // 9.3..12.2 ms in at most 8: 0.5 needs 6 (9.0..12.5).
  expect_ticks(nice_ticks(9.3, 12.2, 8), 0.5, {9, 9.5, 10, 10.5, 11, 11.5, 12, 12.5});
  // Counts: min_step 1 keeps steps integral (0..3 would otherwise get 0.5).
  expect_ticks(nice_ticks(0, 3, 5, 1.0), 1, {0, 1, 2, 3});
  expect_ticks(nice_ticks(0, 3, 6), 0.5, {0, 0.5, 1, 1.5, 2, 2.5, 3});
  // Reversed bounds are swapped; an empty range is widened upward by a tenth (1 at 0); non-finite gives 0..1.
  expect_ticks(nice_ticks(4, -1, 5), 1, {-1, 0, 1, 2, 3, 4});
  expect_ticks(nice_ticks(0, 0, 5), 0.2, {0, 0.2, 0.4, 0.6, 0.8, 1});
  expect_ticks(nice_ticks(3, 3, 6), 0.05, {3, 3.05, 3.1, 3.15, 3.2, 3.25, 3.3});
  expect_ticks(nice_ticks(std::numeric_limits<double>::quiet_NaN(), 2, 5), 0.2, {0, 0.2, 0.4, 0.6, 0.8, 1});
}

TEST(NiceTicks, EveryStepIsOneTwoOrFiveTimesAPowerOfTenAndWithinTheLimit) {
  for (const double lo : {-123.4, -1.0, 0.0, 0.013, 7.62}) {
    for (const double span : {0.004, 0.37, 1.0, 11.63, 1640.0, 2.5e6}) {
      for (const int n : {3, 5, 8, 10}) {
        const AxisTicks t = nice_ticks(lo, lo + span, n);
        const double m = t.step / std::pow(10.0, std::floor(std::log10(t.step) + 1e-9));
        EXPECT_TRUE(std::abs(m - 1) < 1e-6 || std::abs(m - 2) < 1e-6 || std::abs(m - 5) < 1e-6) << t.step;
        EXPECT_LE(t.values.size(), static_cast<size_t>(n) + 1) << lo << " " << span << " " << n;
        EXPECT_LE(t.lo, lo + 1e-12);
        EXPECT_GE(t.hi, lo + span - 1e-9 * span);
      }
    }
  }
}

TEST(TickLabel, DecimalsFromTheStepThousandsAsKAndNoNegativeZero) {
  EXPECT_EQ(tick_label(1500, 500), "1500");
  EXPECT_EQ(tick_label(2000, 1000), "2k");
  EXPECT_EQ(tick_label(15000, 5000), "15k");
  EXPECT_EQ(tick_label(3e6, 1e6), "3M");
  EXPECT_EQ(tick_label(0.25, 0.05), "0.25");
  EXPECT_EQ(tick_label(0.30000000000000004, 0.1), "0.3");
  EXPECT_EQ(tick_label(-10, 5), "-10");
  EXPECT_EQ(tick_label(-1e-17, 0.1), "0.0");
  EXPECT_EQ(tick_label(-0.0, 2), "0");
  EXPECT_EQ(tick_label(10.5, 0.5), "10.5");
}

TEST(Report, HeadlineSaysNotMeasuredWhereThereIsNoData) {
  EvalResult r;  // a log with ground truth only: no visible leader, no targets, no detections, no latency
  r.truth_frames = 20;
  r.duration_s = 1.9;
  const auto h = report_headline(r);
  ASSERT_EQ(h.size(), 6u);
  const char* keys[] = {"localization_rms", "formation_rms", "detection_rate", "false_targets", "track_ids", "latency"};
  for (size_t i = 0; i < h.size(); ++i) {
    EXPECT_EQ(h[i].key, keys[i]);
    EXPECT_FALSE(h[i].measured) << h[i].key;
    EXPECT_EQ(h[i].text, "not measured") << h[i].key;
    EXPECT_TRUE(h[i].values.empty()) << h[i].key;
    EXPECT_FALSE(h[i].detail.empty()) << h[i].key;  // why
  }
  EXPECT_FALSE(h[0].thesis.empty());  // the thesis's figure is shown even when ours is not measured
  EXPECT_FALSE(h[5].thesis.empty());

  // No ground truth at all (an EvalResult not from evaluate_log, which refuses such logs).
  const auto none = report_headline(EvalResult{});
  EXPECT_EQ(none[0].detail, "the log has no ground truth");

  // The leader visible but no detections_t: not measured, not "0 of N".
  r.frames_leader_visible = 20;
  EXPECT_EQ(report_headline(r)[2].detail, "the log has no detections_t");
  r.detection_frames = 20;  // detections_t present, none on the leader: measured, 0 of 20
  EXPECT_EQ(report_headline(r)[2].text, "0 of 20 frames (0.0 %)");

  r.target_estimates = 5;  // targets, none false: measured, 0
  EXPECT_TRUE(report_headline(r)[3].measured);
  EXPECT_EQ(report_headline(r)[3].text, "0");
  r.target_estimates = 0;

  EvalOptions o;
  const std::string html = html_report(r, o, {});
  size_t n = 0;
  for (size_t p = html.find("data-measured=\"0\""); p != std::string::npos; p = html.find("data-measured=\"0\"", p + 1))
    ++n;
  EXPECT_EQ(n, 5u);
  EXPECT_EQ(html.find(">0 m<"), std::string::npos);
  EXPECT_EQ(html.find(">0.0 ms"), std::string::npos);
  EXPECT_NE(html.find("id=\"no-images\""), std::string::npos);
  for (const char* id : {"topdown", "errors", "error-by-range", "box-width", "latency"})
    EXPECT_NE(html.find(std::string("<svg id=\"") + id + "\""), std::string::npos) << id;
}

TEST(Report, ChartTickLabelsAreRoundAndFitTheMargin) {
  EvalResult r;
  r.truth_frames = 100;
  r.duration_s = 9.9;
  for (int i = 0; i < 1640; ++i) r.latency_samples_ms.push_back(10.0 + 0.0001 * i);  // one tall bin of 1640
  r.latency_ms.n = 1640;
  r.leader_truth = {{0.0, {-7.62, 4.01, 5.0}}, {1.0, {3.3, 21.7, 5.0}}};
  const std::string html = html_report(r, EvalOptions{}, {});
  const auto svg = [&](const std::string& id) {
    const size_t at = html.find("<svg id=\"" + id + "\"");
    return html.substr(at, html.find("</svg>", at) - at);
  };
  const std::string latency = svg("latency");
  // The count axis: 0..2000 by 500 (1640 in at most 5 intervals), labels whole, no exponent.
  for (const char* label : {">0<", ">500<", ">1000<", ">1500<", ">2000<"})
    EXPECT_NE(latency.find(label), std::string::npos) << label;
  EXPECT_EQ(latency.find("e+"), std::string::npos);
  // Every y label's left edge (right-anchored at x, about 6.5 px a character) clears the rotated title (x <= 20).
  for (const char* id : {"topdown", "errors", "error-by-range", "box-width", "latency"}) {
    const std::string s = svg(id);
    size_t labels = 0;
    for (size_t p = s.find("class=\"ytick\" x=\""); p != std::string::npos; p = s.find("class=\"ytick\" x=\"", p + 1)) {
      const double x = std::stod(s.substr(p + 17));
      const size_t open = s.find('>', p) + 1;
      const std::string text = s.substr(open, s.find('<', open) - open);
      EXPECT_GE(x - 6.5 * static_cast<double>(text.size()), 20.0) << id << ": " << text;
      EXPECT_EQ(text.find('e'), std::string::npos) << id << ": " << text;
      ++labels;
    }
    EXPECT_GE(labels, 2u) << id;
  }
  // The top-down view: equal 1-2-5 steps on both axes, ticks at multiples of 5 m (not -7.62 or 4.01).
  const std::string top = svg("topdown");
  EXPECT_EQ(top.find(">-7.62<"), std::string::npos);
  EXPECT_NE(top.find(">-10<"), std::string::npos);
  EXPECT_NE(top.find(">25<"), std::string::npos);
}

}  // namespace
}  // namespace wingman::tools
