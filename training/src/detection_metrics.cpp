// SPDX-License-Identifier: MIT
// Matching predictions to truths, precision / recall / AP / PR curve, size bins, reports.
#include "wingman/training/detection_metrics.hpp"

#include <fmt/format.h>
#include <wingman/common/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace wingman::training {

const char* criterion_name(MatchCriterion c) { return c == MatchCriterion::kIou ? "iou" : "centre"; }

std::vector<std::string> MetricsOptions::validate() const {
  std::vector<std::string> p;
  if (!(iou_thresh > 0.0 && iou_thresh <= 1.0))
    p.push_back(fmt::format("iou_thresh = {}: must be in (0, 1]", iou_thresh));
  if (!(conf_thresh >= 0.0 && conf_thresh <= 1.0))
    p.push_back(fmt::format("conf_thresh = {}: must be in 0..1", conf_thresh));
  for (size_t i = 0; i < size_edges_px.size(); ++i)
    if (!(size_edges_px[i] > 0.0) || (i > 0 && !(size_edges_px[i] > size_edges_px[i - 1])))
      p.push_back(fmt::format("size_edges_px[{}] = {}: edges must be positive and increasing", i, size_edges_px[i]));
  if (pr_points < 2) p.push_back(fmt::format("pr_points = {}: must be >= 2", pr_points));
  if (!(edge_margin_px >= 0.0)) p.push_back(fmt::format("edge_margin_px = {}: must be >= 0", edge_margin_px));
  return p;
}

namespace {

/// A prediction after matching.
struct Record {
  double confidence;
  bool tp;
  double iou;  // with the matched truth (0 if none)
  int bin;     // the matched truth's bin, or the prediction's own
};

bool centre_inside(const detector::Box& p, const detector::Box& t) {
  return p.cx >= t.cx - 0.5f * t.w && p.cx <= t.cx + 0.5f * t.w && p.cy >= t.cy - 0.5f * t.h &&
         p.cy <= t.cy + 0.5f * t.h;
}

int size_bin(const detector::Box& b, const std::vector<double>& edges) {
  const double s = std::sqrt(std::max(0.0, static_cast<double>(b.w) * b.h));
  int bin = 0;
  while (bin < static_cast<int>(edges.size()) && s >= edges[static_cast<size_t>(bin)]) ++bin;
  return bin;
}

/// Matches every image's predictions; returns records in image order, each image's in decreasing confidence.
/// `found` (per image, per truth): whether a prediction >= conf_thresh took that truth.
std::vector<Record> match_all(const std::vector<ImageDetections>& images, MatchCriterion criterion,
                              const MetricsOptions& o, std::vector<std::vector<bool>>* found) {
  std::vector<Record> out;
  found->clear();
  for (const ImageDetections& img : images) {
    std::vector<bool>& img_found = found->emplace_back(img.truths.size(), false);
    std::vector<size_t> order(img.predictions.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return img.predictions[a].confidence > img.predictions[b].confidence; });
    std::vector<bool> taken(img.truths.size(), false);
    for (size_t pi : order) {
      const detector::Box& p = img.predictions[pi];
      int best = -1;
      double best_score = 0.0;
      for (size_t ti = 0; ti < img.truths.size(); ++ti) {
        if (taken[ti]) continue;
        const detector::Box& t = img.truths[ti];
        double score;
        if (criterion == MatchCriterion::kIou) {
          score = detector::iou(p, t);
          if (score < o.iou_thresh) continue;
        } else {
          if (!centre_inside(p, t)) continue;
          score = -std::hypot(static_cast<double>(p.cx - t.cx), static_cast<double>(p.cy - t.cy));
        }
        if (best < 0 || score > best_score) best = static_cast<int>(ti), best_score = score;
      }
      Record r{p.confidence, best >= 0, 0.0, size_bin(p, o.size_edges_px)};
      if (best >= 0) {
        taken[static_cast<size_t>(best)] = true;
        if (p.confidence >= o.conf_thresh) img_found[static_cast<size_t>(best)] = true;
        r.iou = detector::iou(p, img.truths[static_cast<size_t>(best)]);
        r.bin = size_bin(img.truths[static_cast<size_t>(best)], o.size_edges_px);
      }
      out.push_back(r);
    }
  }
  return out;
}

/// Stats and PR curve over `records` (the ones of one bin, or all) against `truths` truth boxes.
MatchStats stats_of(std::vector<Record> records, int64_t truths, const MetricsOptions& o, std::vector<PrPoint>* curve) {
  MatchStats s;
  s.truths = truths;
  double iou_sum = 0.0;
  for (const Record& r : records) {
    if (r.confidence < o.conf_thresh) continue;
    ++s.detections;
    if (r.tp) {
      ++s.true_positives;
      iou_sum += r.iou;
    } else {
      ++s.false_positives;
    }
  }
  s.precision = s.detections > 0 ? static_cast<double>(s.true_positives) / s.detections : 0.0;
  s.recall = truths > 0 ? static_cast<double>(s.true_positives) / truths : 0.0;
  s.f1 = s.precision + s.recall > 0 ? 2 * s.precision * s.recall / (s.precision + s.recall) : 0.0;
  s.mean_iou = s.true_positives > 0 ? iou_sum / s.true_positives : 0.0;

  std::stable_sort(records.begin(), records.end(),
                   [](const Record& a, const Record& b) { return a.confidence > b.confidence; });
  const size_t m = records.size();
  std::vector<double> rec(m), prec(m);
  int64_t tp = 0;
  for (size_t i = 0; i < m; ++i) {
    tp += records[i].tp ? 1 : 0;
    rec[i] = truths > 0 ? static_cast<double>(tp) / truths : 0.0;
    prec[i] = static_cast<double>(tp) / static_cast<double>(i + 1);
  }
  for (size_t i = m; i-- > 1;) prec[i - 1] = std::max(prec[i - 1], prec[i]);  // precision envelope
  double prev = 0.0;
  for (size_t i = 0; i < m; ++i) {
    s.ap += (rec[i] - prev) * prec[i];
    prev = rec[i];
  }
  if (curve) {
    curve->clear();
    for (int k = 0; k < o.pr_points; ++k) {
      const double r = static_cast<double>(k) / (o.pr_points - 1);
      PrPoint p;
      p.recall = r;
      const auto it = std::lower_bound(rec.begin(), rec.end(), r - 1e-12);  // rec is non-decreasing
      if (truths > 0 && it != rec.end()) {
        const size_t j = static_cast<size_t>(it - rec.begin());
        p.precision = prec[j];
        p.confidence = records[j].confidence;
      }
      curve->push_back(p);
    }
  }
  return s;
}

std::string bin_name(double lo, double hi) {
  if (lo <= 0.0) return fmt::format("<{}px", hi);
  if (std::isinf(hi)) return fmt::format(">={}px", lo);
  return fmt::format("{}-{}px", lo, hi);
}

bool touches_edge(const detector::Box& t, const ImageDetections& img, double margin) {
  if (img.width <= 0 || img.height <= 0) return false;
  return t.cx - 0.5 * t.w <= margin || t.cy - 0.5 * t.h <= margin || t.cx + 0.5 * t.w >= img.width - margin ||
         t.cy + 0.5 * t.h >= img.height - margin;
}

/// What the detections >= conf_thresh of `img` did at truth `t` (not found under the criterion).
UnmatchedTruth describe_unmatched(size_t index, const ImageDetections& img, const detector::Box& t, bool at_edge,
                                  const MetricsOptions& o) {
  UnmatchedTruth u;
  u.image = index;
  u.image_name = img.name;
  u.truth = t;
  u.at_edge = at_edge;
  for (const detector::Box& p : img.predictions) {
    if (p.confidence < o.conf_thresh) continue;
    const double v = detector::iou(p, t);
    if (v > u.best_iou || (v == u.best_iou && v > 0.0 && p.confidence > u.best.confidence)) {
      u.best_iou = v;
      u.best = p;
    }
  }
  u.reason = u.best_iou > 0.0 ? "loose" : "missed";
  return u;
}

CriterionMetrics evaluate(const std::vector<ImageDetections>& images, MatchCriterion criterion,
                          const MetricsOptions& o) {
  CriterionMetrics c;
  c.criterion = criterion;
  std::vector<std::vector<bool>> found;
  const std::vector<Record> records = match_all(images, criterion, o, &found);
  for (size_t i = 0; i < images.size(); ++i)
    for (size_t ti = 0; ti < images[i].truths.size(); ++ti) {
      const bool edge = touches_edge(images[i].truths[ti], images[i], o.edge_margin_px);
      c.edge_truths += edge ? 1 : 0;
      if (found[i][ti]) {
        c.edge_found += edge ? 1 : 0;
      } else {
        c.unmatched.push_back(describe_unmatched(i, images[i], images[i].truths[ti], edge, o));
      }
    }
  const int bins = static_cast<int>(o.size_edges_px.size()) + 1;
  std::vector<int64_t> truths_per_bin(static_cast<size_t>(bins), 0);
  int64_t truths = 0;
  for (const ImageDetections& img : images)
    for (const detector::Box& t : img.truths) {
      ++truths;
      ++truths_per_bin[static_cast<size_t>(size_bin(t, o.size_edges_px))];
    }
  c.all = stats_of(records, truths, o, &c.pr_curve);
  for (int b = 0; b < bins; ++b) {
    SizeBinStats bs;
    bs.min_px = b == 0 ? 0.0 : o.size_edges_px[static_cast<size_t>(b - 1)];
    bs.max_px = b == bins - 1 ? std::numeric_limits<double>::infinity() : o.size_edges_px[static_cast<size_t>(b)];
    bs.name = bin_name(bs.min_px, bs.max_px);
    std::vector<Record> in_bin;
    for (const Record& r : records)
      if (r.bin == b) in_bin.push_back(r);
    bs.stats = stats_of(in_bin, truths_per_bin[static_cast<size_t>(b)], o, nullptr);
    c.by_size.push_back(bs);
  }
  return c;
}

common::Json stats_json(const MatchStats& s) {
  return {{"truths", s.truths},
          {"detections", s.detections},
          {"true_positives", s.true_positives},
          {"false_positives", s.false_positives},
          {"precision", s.precision},
          {"recall", s.recall},
          {"f1", s.f1},
          {"mean_iou", s.mean_iou},
          {"ap", s.ap}};
}

common::Json criterion_json(const CriterionMetrics& c) {
  using common::Json;
  Json bins = Json::array();
  for (const SizeBinStats& b : c.by_size)
    bins.push_back({{"name", b.name},
                    {"min_px", b.min_px},
                    {"max_px", std::isinf(b.max_px) ? Json(nullptr) : Json(b.max_px)},
                    {"stats", stats_json(b.stats)}});
  Json curve = Json::array();
  for (const PrPoint& p : c.pr_curve) curve.push_back({p.recall, p.precision, p.confidence});
  Json unmatched = Json::array();
  for (const UnmatchedTruth& u : c.unmatched) {
    const Json best =
        u.reason == "missed" ? Json(nullptr) : Json{u.best.cx, u.best.cy, u.best.w, u.best.h, u.best.confidence};
    unmatched.push_back({{"image", u.image},
                         {"name", u.image_name},
                         {"truth", {u.truth.cx, u.truth.cy, u.truth.w, u.truth.h}},
                         {"size_px", std::sqrt(std::max(0.0, static_cast<double>(u.truth.w) * u.truth.h))},
                         {"at_edge", u.at_edge},
                         {"reason", u.reason},
                         {"best_iou", u.best_iou},
                         {"best", best}});
  }
  Json j;
  j["criterion"] = criterion_name(c.criterion);
  j["all"] = stats_json(c.all);
  j["by_size"] = bins;
  j["pr_curve_columns"] = {"recall", "precision", "confidence"};
  j["pr_curve"] = curve;
  j["edge_truths"] = c.edge_truths;
  j["edge_found"] = c.edge_found;
  j["unmatched_columns"] = {{"truth", {"cx", "cy", "w", "h"}}, {"best", {"cx", "cy", "w", "h", "confidence"}}};
  j["unmatched"] = unmatched;
  return j;
}

std::string report_rows(const CriterionMetrics& c) {
  std::string s;
  auto row = [&](const std::string& name, const MatchStats& m) {
    s += fmt::format("  {:<9} {:>7} {:>7} {:>7} {:>7} {:>9.3f} {:>7.3f} {:>9.3f} {:>7.3f}\n", name, m.truths,
                     m.detections, m.true_positives, m.false_positives, m.precision, m.recall, m.mean_iou, m.ap);
  };
  row("all", c.all);
  for (const SizeBinStats& b : c.by_size) row(b.name, b.stats);
  return s;
}

/// "not found at confidence >= 0.2: 58 of 300 (24 missed: no detection overlaps; 34 loose) ..." and the
/// `listed` largest unmatched truths.
std::string report_unmatched(const CriterionMetrics& c, const MetricsOptions& o, size_t listed) {
  int64_t missed = 0, edge = 0;
  for (const UnmatchedTruth& u : c.unmatched) {
    missed += u.reason == "missed" ? 1 : 0;
    edge += u.at_edge ? 1 : 0;
  }
  std::string s = fmt::format(
      "  not found at confidence >= {}: {} of {} truths ({} missed: no detection overlaps them; {} loose: "
      "overlapped, not matched)",
      o.conf_thresh, c.unmatched.size(), c.all.truths, missed, static_cast<int64_t>(c.unmatched.size()) - missed);
  if (c.edge_truths > 0) s += fmt::format("; at the image's edge: {} of the {} truths there", edge, c.edge_truths);
  s += "\n";
  std::vector<const UnmatchedTruth*> by_size;
  for (const UnmatchedTruth& u : c.unmatched) by_size.push_back(&u);
  std::stable_sort(by_size.begin(), by_size.end(), [](const UnmatchedTruth* a, const UnmatchedTruth* b) {
    return static_cast<double>(a->truth.w) * a->truth.h > static_cast<double>(b->truth.w) * b->truth.h;
  });
  if (by_size.size() > listed) by_size.resize(listed);
  for (const UnmatchedTruth* u : by_size) {
    s += fmt::format("    {} truth {:.0f}x{:.0f} at ({:.0f}, {:.0f}){}: {}",
                     u->image_name.empty() ? fmt::format("image {}", u->image) : u->image_name, u->truth.w, u->truth.h,
                     u->truth.cx, u->truth.cy, u->at_edge ? " at the edge" : "", u->reason);
    if (u->reason == "loose")
      s += fmt::format(", best {:.0f}x{:.0f} at ({:.0f}, {:.0f}) IoU {:.2f} confidence {:.2f}", u->best.w, u->best.h,
                       u->best.cx, u->best.cy, u->best_iou, u->best.confidence);
    s += "\n";
  }
  return s;
}

}  // namespace

DetectionMetrics evaluate_detections(const std::vector<ImageDetections>& images, const MetricsOptions& options) {
  const std::vector<std::string> problems = options.validate();
  if (!problems.empty()) {
    std::string msg = "evaluate_detections: invalid options:";
    for (const auto& p : problems) msg += " " + p + ";";
    throw std::invalid_argument(msg);
  }
  DetectionMetrics m;
  m.options = options;
  m.images = static_cast<int64_t>(images.size());
  for (const ImageDetections& img : images) {
    m.truths += static_cast<int64_t>(img.truths.size());
    m.predictions += static_cast<int64_t>(img.predictions.size());
    m.negative_images += img.truths.empty() ? 1 : 0;
  }
  m.iou = evaluate(images, MatchCriterion::kIou, options);
  m.centre = evaluate(images, MatchCriterion::kCentreInBox, options);
  return m;
}

std::string DetectionMetrics::one_line() const {
  return fmt::format(
      "{} images, {} truths: IoU>={}: AP {:.3f}, recall {:.3f}, precision {:.3f}, mean IoU {:.3f} @conf {}; "
      "centre-in-box: AP {:.3f}, recall {:.3f}, precision {:.3f}",
      images, truths, options.iou_thresh, iou.all.ap, iou.all.recall, iou.all.precision, iou.all.mean_iou,
      options.conf_thresh, centre.all.ap, centre.all.recall, centre.all.precision);
}

std::string DetectionMetrics::report(size_t listed) const {
  std::string s = fmt::format("{} images ({} without a drone), {} truth boxes, {} predictions\n", images,
                              negative_images, truths, predictions);
  const std::string header = fmt::format("  {:<9} {:>7} {:>7} {:>7} {:>7} {:>9} {:>7} {:>9} {:>7}\n", "size", "truths",
                                         "dets", "TP", "FP", "precision", "recall", "mean IoU", "AP");
  s += fmt::format("match IoU >= {} (counts at confidence >= {}; AP over all confidences):\n", options.iou_thresh,
                   options.conf_thresh);
  s += header + report_rows(iou) + report_unmatched(iou, options, listed);
  s += "match centre in truth box:\n" + header + report_rows(centre) + report_unmatched(centre, options, listed);
  return s;
}

std::string DetectionMetrics::json() const {
  common::Json j;
  j["images"] = images;
  j["negative_images"] = negative_images;
  j["truths"] = truths;
  j["predictions"] = predictions;
  j["iou_thresh"] = options.iou_thresh;
  j["conf_thresh"] = options.conf_thresh;
  j["size_edges_px"] = options.size_edges_px;
  j["edge_margin_px"] = options.edge_margin_px;
  j["iou"] = criterion_json(iou);
  j["centre"] = criterion_json(centre);
  return common::json_text(j);
}

}  // namespace wingman::training
