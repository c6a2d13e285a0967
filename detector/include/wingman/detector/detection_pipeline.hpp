// SPDX-License-Identifier: MIT
// Algorithm 2 of the thesis: subsquare, resize, detect, NMS, optional zoom-in re-detection.
#pragma once

#include "wingman/detector/backend.hpp"
#include "wingman/detector/box.hpp"
#include "wingman/detector/box_fusion.hpp"
#include "wingman/detector/darknet_model.hpp"

#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

namespace wingman::detector {

/// Options of the detection pipeline (keys under `detection.` in config/detector.yaml).
struct DetectorPipelineOptions {
  double p_thresh = 0.2;   ///< confidence threshold: boxes with confidence < p_thresh are dropped, 0..1
  double o_thresh = 0.2;   ///< NMS overlap threshold (Algorithm 1): IoU > o_thresh suppresses, 0..1
  bool subsquare = false;  ///< detect in the centred h x h square of a wider image instead of the whole image
  bool zoom_in = false;    ///< re-detect in a network-sized full-resolution crop around each detection
  /// zoom-in only for boxes at most this fraction of the crop's width and of its height (the crop is the network's
  /// size in full-image pixels); larger boxes keep the first pass's box. (0..1]; 1 zooms every box.
  double zoom_max_fraction = 0.25;
  /// also detect in the horizontally mirrored image and fuse the two passes' boxes (weighted box fusion,
  /// fuse_boxes()): tighter boxes and fewer one-view false positives, for twice the network work
  bool flip_fusion = false;
  double fusion_iou = 0.3;     ///< flip_fusion: boxes of the two passes overlapping at IoU > this are one drone, 0..1
  std::string policy = "all";  ///< which detections to return: "all" or "most_confident"
  int max_detections = 10;     ///< at most this many boxes per image (and zoom-in crops), >= 1

  template <class V>
  void visit(V& v) {
    v("detection.p_thresh", p_thresh, "confidence threshold, boxes below it are dropped (0..1)");
    v("detection.o_thresh", o_thresh, "non-max suppression: IoU above this suppresses the less confident box (0..1)");
    v("detection.subsquare", subsquare, "detect in the centred h x h square of a wider image (Algorithm 2)");
    v("detection.zoom_in", zoom_in, "re-detect in a full-resolution network-sized crop around each detection");
    v("detection.zoom_max_fraction", zoom_max_fraction,
      "zoom-in only boxes at most this fraction of the crop's width and height; larger keep the first box (0..1]");
    v("detection.flip_fusion", flip_fusion,
      "also detect in the mirrored image and fuse both passes' boxes (weighted box fusion; twice the work)");
    v("detection.fusion_iou", fusion_iou,
      "flip_fusion: boxes of the two passes overlapping above this IoU are fused (0..1)");
    v("detection.policy", policy, "all or most_confident");
    v("detection.max_detections", max_detections, "at most this many boxes per image (>= 1)");
  }
  /// One "key = value: rule" line per invalid field; empty when valid.
  std::vector<std::string> validate() const;
};

/// Algorithm 2, on one BGR image at a time, with any InferenceBackend whose network has [region] or [yolo]
/// heads (the thesis network: one [region]; a tiny-YOLOv3: two [yolo]):
///  1. region = the whole image, or with `subsquare` its centred min(w, h) square;
///  2. stretch the region to the network input (bilinear), run the backend, decode every head's output
///     (decode_region / decode_yolo) into one candidate list, keep confidence >= p_thresh;
///  3. non-max suppression (Algorithm 1, o_thresh); apply `policy` and `max_detections`;
///  4. with `zoom_in`, when step 1's region is larger than the network input in width or height (otherwise a
///     crop sees the drone at the first pass's scale or coarser, and nothing is zoomed): for each kept detection
///     whose box is at most `zoom_max_fraction` of the network's width and height (in full-image pixels: a crop
///     could not hold a larger one with a margin) and overlaps no more confident detection (NMS keeps a part of
///     a drone at IoU <= o_thresh, and a crop centred on the part re-detects the part), a network-sized crop of
///     the full-resolution image centred on it and clamped inside the image (zoom_crop()); all crops run as
///     batches of up to backend.max_batch(); in each crop the most confident re-detection (>= p_thresh)
///     replaces the detection (zoom_refined = true). The other detections, and those whose crop finds nothing,
///     keep their first-pass box unchanged (zoom_refined = false). The refined boxes go through NMS once more
///     (two crops may find the same drone);
///  5. with `flip_fusion`, steps 1-4 run twice, on the image and on its horizontal mirror (each pass keeping
///     boxes >= p_thresh / 2 and up to max_detections), the mirror's boxes are mirrored back, and the two lists
///     are fused (fuse_boxes(), IoU > fusion_iou: a box both passes found is their confidence-weighted mean with the
///     mean confidence; one only one pass found keeps half its confidence); then >= p_thresh, NMS, `policy` and
///     `max_detections` as in step 3;
///  6. boxes are returned in full-image pixels, most confident first.
/// Buffers (network input batch, output tensor, box lists, resize scratch) are allocated at construction;
/// detect() allocates only the returned vector (and, for a new image size, the resize scratch and with flip_fusion the
/// mirrored image).
class DetectionPipeline {
 public:
  /// @param options  validated here (std::invalid_argument listing every problem).
  /// @param backend  not null; its input_shape() must be the model's net size and its output_shapes() the
  ///                 heads' inputs, in order (std::invalid_argument otherwise).
  /// @param model    the network the backend runs; must have at least one [region] or [yolo] head (the
  ///                 anchors are taken from them).
  DetectionPipeline(DetectorPipelineOptions options, std::unique_ptr<InferenceBackend> backend,
                    const DarknetModel& model);

  /// Detects drones in `bgr_image` (CV_8UC3, any size >= 1 x 1; std::invalid_argument otherwise).
  /// Returns boxes in full-image pixels, most confident first.
  std::vector<Box> detect(const cv::Mat& bgr_image);

  const DetectorPipelineOptions& options() const { return options_; }
  InferenceBackend& backend() { return *backend_; }

 private:
  /// Runs `count` images already in input_ through the backend and decodes image i's boxes from every head
  /// (>= p_thresh, network pixels) into candidates_[i].
  void run_and_decode(int count);
  /// Steps 1-4 on one view (the image or its mirror), keeping at most `keep` first-pass boxes; into detections_.
  void detect_view(const cv::Mat& bgr_image, size_t keep);

  DetectorPipelineOptions options_;
  std::unique_ptr<InferenceBackend> backend_;
  std::vector<Layer> heads_;                  ///< the [region]/[yolo] layers, in the backend's output order
  cv::Size net_size_;                         ///< network input, pixels
  int batch_capacity_ = 1;                    ///< images input_ holds: min(max_batch, max_detections), >= 1
  std::vector<float> input_;                  ///< batch_capacity_ x 3 x H x W network inputs
  std::vector<float> output_;                 ///< raw output tensor of the last forward()
  std::vector<std::vector<Box>> candidates_;  ///< per batch slot: decoded boxes
  std::vector<Box> detections_;               ///< current detections, full-image pixels
  std::vector<cv::Rect> crops_;               ///< zoom-in crops, full-image pixels
  std::vector<size_t> zoomed_;                ///< per crop: the index in detections_ it re-detects
  cv::Mat resized_;                           ///< resize scratch
  float pass_floor_ = 0.0f;     ///< confidence floor of each pass: p_thresh, p_thresh / 2 with flip_fusion
  cv::Mat mirrored_;            ///< flip_fusion: the mirrored image
  std::vector<ViewBox> views_;  ///< flip_fusion: both passes' boxes, full-image pixels
};

}  // namespace wingman::detector
