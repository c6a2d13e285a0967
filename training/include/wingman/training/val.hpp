// SPDX-License-Identifier: MIT
// `wingman val`: a detector (or saved predictions) against a labelled dataset split, with detection_metrics.
#pragma once

#include "wingman/training/detection_metrics.hpp"

#include <wingman/detector/detection_pipeline.hpp>

#include <functional>
#include <string>
#include <vector>

namespace wingman::training {

/// What `wingman val` evaluates and how.
struct ValOptions {
  std::string data;                           ///< data.yaml or YOLO-layout folder (required)
  std::string split = "val";                  ///< the split to evaluate ("" = a folder's images/ without splits)
  std::string cfg = "builtin:wingman-small";  ///< Darknet .cfg path or builtin:<name> (detector::load_model)
  std::string weights;          ///< run the detector with these .weights (exactly one of weights / predictions)
  std::string predictions;      ///< or read `wingman predict` output: <predictions>/<image stem>.txt per image
  std::string backend = "cpu";  ///< detector backend: auto (opencl whenever usable, not timed), opencl or cpu
  /// Network input size, as the detector's model.input_size (detector::InputSize::parse): auto fits the cfg's size
  /// to each image's aspect (640x512 for Halmstad's 640x512 frames), cfg keeps the cfg's, WxH is that size.
  std::string input_size = "auto";
  int class_id = 0;    ///< the class evaluated (truths of other classes are ignored), >= 0
  int max_images = 0;  ///< evaluate at most this many images, spread evenly over the split (0 = all), >= 0
  /// The detector's Algorithm 2 settings. p_thresh is low (0.005) so that the PR curve and AP see nearly every
  /// box; the operating point of the counts is metrics.conf_thresh (the detector's default p_thresh, 0.2).
  detector::DetectorPipelineOptions detection = low_threshold_detection();
  MetricsOptions metrics;  ///< IoU threshold, operating confidence, size bins, PR points

  /// One "field = value: rule" line per invalid field; empty when valid.
  std::vector<std::string> validate() const;
  /// DetectorPipelineOptions with p_thresh 0.005 (otherwise the detector's defaults).
  static detector::DetectorPipelineOptions low_threshold_detection();
};

/// Evaluates one split: for each image (sorted by path), its truths (class class_id, in pixels) and the
/// detector's boxes (or the prediction file's, scaled to pixels), then evaluate_detections().
/// `progress(done, total)` (may be empty) is called after each image; `log` (may be empty) gets one line per
/// network built (which backend, at which input size). Throws std::invalid_argument listing invalid options;
/// DatasetError naming the file for bad labels, a missing or bad prediction file, an unreadable image, or two images
/// with the same stem in predictions mode; std::runtime_error from loading the model.
DetectionMetrics run_val(const ValOptions& options, const std::function<void(size_t, size_t)>& progress = {},
                         const std::function<void(const std::string&)>& log = {});

}  // namespace wingman::training
