// SPDX-License-Identifier: MIT
// Detection metrics: the thesis's recall at IoU 0.5 and mean IoU, precision, AP@0.5 and the PR curve, by box size.
#pragma once

#include <wingman/detector/box.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace wingman::training {

/// When a prediction counts as finding a truth box.
enum class MatchCriterion {
  kIou,          ///< IoU(prediction, truth) >= iou_thresh (0.5: the thesis's criterion)
  kCentreInBox,  ///< the prediction's centre lies inside the truth box (for loose truth boxes)
};

/// "iou" or "centre".
const char* criterion_name(MatchCriterion c);

/// The truth and predicted boxes of one image, in that image's pixels (detector::Box: centre, size,
/// confidence; a truth's confidence is ignored).
struct ImageDetections {
  std::vector<detector::Box> truths;
  std::vector<detector::Box> predictions;
  std::string name;  ///< how reports name the image (its path); may be empty
  int width = 0;     ///< the image's size in pixels, for the edge test of UnmatchedTruth; 0 = unknown
  int height = 0;
};

/// How evaluate_detections() matches and bins.
struct MetricsOptions {
  double iou_thresh = 0.5;  ///< IoU criterion's threshold, 0 < iou_thresh <= 1
  double conf_thresh =
      0.2;  ///< operating point: predictions below it are not detections (the detector's p_thresh), 0..1
  /// Size bins by sqrt(w h) of a box in image pixels: edges in increasing order, giving bins
  /// [0, e0), [e0, e1), ..., [e_last, inf). Default: < 16, 16-32, 32-64, >= 64 px.
  std::vector<double> size_edges_px = {16.0, 32.0, 64.0};
  int pr_points = 101;  ///< the PR curve is reported at this many evenly spaced recalls 0..1, >= 2
  /// A truth box touches the image's edge when it reaches within this many pixels of the border (a drone cut
  /// off by the frame); needs ImageDetections::width and height. >= 0.
  double edge_margin_px = 1.0;

  /// One "field = value: rule" line per invalid field; empty when valid.
  std::vector<std::string> validate() const;
};

/// One point of a precision-recall curve.
struct PrPoint {
  double recall = 0.0;
  double precision = 0.0;   ///< interpolated: the best precision at this recall or higher (0 if unreachable)
  double confidence = 0.0;  ///< the lowest confidence threshold that reaches this recall (0 if unreachable)
};

/// Counts and rates for one set of truths (all, or one size bin) under one criterion.
struct MatchStats {
  int64_t truths = 0;  ///< truth boxes
  int64_t detections =
      0;  ///< predictions with confidence >= conf_thresh (in this bin: by their own size when unmatched)
  int64_t true_positives = 0;   ///< truths found by a detection >= conf_thresh
  int64_t false_positives = 0;  ///< detections >= conf_thresh that found no truth
  double precision = 0.0;       ///< TP / (TP + FP) at conf_thresh (0 without detections)
  double recall = 0.0;          ///< TP / truths at conf_thresh (0 without truths)
  double f1 = 0.0;              ///< 2 P R / (P + R)
  double mean_iou = 0.0;        ///< mean IoU of the matched (prediction, truth) pairs at conf_thresh (0 if none)
  double ap = 0.0;              ///< average precision over every confidence: all-point interpolated (VOC 2010+)
};

/// One size bin's stats.
struct SizeBinStats {
  std::string name;  ///< "<16px", "16-32px", ..., ">=64px"
  double min_px = 0.0;
  double max_px = 0.0;  ///< infinity for the last bin
  MatchStats stats;
};

/// A truth box that no detection at conf_thresh found under one criterion: what the detector did there.
struct UnmatchedTruth {
  size_t image = 0;        ///< index of its image in the evaluated list
  std::string image_name;  ///< ImageDetections::name
  detector::Box truth;     ///< image pixels
  bool at_edge = false;    ///< it touches the image's edge (MetricsOptions::edge_margin_px); false if size unknown
  /// "loose": a detection >= conf_thresh overlaps it (IoU > 0) but none matched it: its box is not tight enough
  /// (IoU criterion), its centre lies outside (centre criterion), or it went to another truth.
  /// "missed": no detection >= conf_thresh overlaps it.
  std::string reason;
  double best_iou = 0.0;  ///< the largest IoU of a detection >= conf_thresh with it (0 when missed)
  detector::Box best;     ///< that detection, confidence included (all zero when missed)
};

/// All metrics under one criterion.
struct CriterionMetrics {
  MatchCriterion criterion = MatchCriterion::kIou;
  MatchStats all;
  std::vector<SizeBinStats> by_size;
  std::vector<PrPoint> pr_curve;          ///< MetricsOptions::pr_points points, recall 0 .. 1
  std::vector<UnmatchedTruth> unmatched;  ///< every truth not found at conf_thresh, in image order
  int64_t edge_truths = 0;                ///< truths that touch the image's edge (of images with a known size)
  int64_t edge_found = 0;                 ///< of those, found at conf_thresh
};

/// The result of evaluating a set of images.
struct DetectionMetrics {
  int64_t images = 0;
  int64_t negative_images = 0;  ///< images without a truth box
  int64_t truths = 0;
  int64_t predictions = 0;  ///< every prediction, at any confidence
  MetricsOptions options;
  CriterionMetrics iou;     ///< IoU >= iou_thresh
  CriterionMetrics centre;  ///< centre in truth box

  std::string one_line() const;  ///< "AP@0.5 0.812, recall 0.90, precision 0.85, mean IoU 0.71 (IoU); ..."
  /// A table for people, then per criterion the unmatched truths: missed / loose, at the edge, and the
  /// `listed` largest of them (0 = none listed).
  std::string report(size_t listed = 10) const;
  std::string json()
      const;  ///< one JSON object (every field above, both criteria, the PR curves, every unmatched truth)
};

/// Evaluates predictions against truths, image by image.
///
/// Matching, per image and criterion: predictions in decreasing confidence (stable for ties) each take the
/// still unmatched truth that fits best: the largest IoU >= iou_thresh (kIou), or among the truths containing
/// the prediction's centre the one whose centre is nearest (kCentreInBox); ties go to the first truth. A
/// prediction that takes no truth is a false positive. Because a prediction only competes with more confident
/// ones, the same matching gives the counts at every confidence threshold: the PR curve and AP use all of
/// them, the MatchStats counts use conf_thresh.
/// Size bins use sqrt(w h) in pixels: a truth by its own size; a matched prediction follows its truth; an
/// unmatched prediction counts in the bin of its own size (COCO's rule for area ranges).
/// A box is inside when its centre is within [x - w/2, x + w/2] x [y - h/2, y + h/2] (edges included).
/// A truth not taken by a prediction >= conf_thresh is unmatched (CriterionMetrics::unmatched).
/// Throws std::invalid_argument listing the invalid options.
DetectionMetrics evaluate_detections(const std::vector<ImageDetections>& images, const MetricsOptions& options);

}  // namespace wingman::training
