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
  double fusion_iou = 0.3;  ///< flip_fusion, coarse_pass: boxes of two passes overlapping at IoU > this are fused, 0..1
  /// also detect with the network input scaled by coarse_scale (the whole image; with flip_fusion its mirror too) and
  /// fuse those boxes of at least coarse_min_size with the full-size passes' (step 6): finds the close drones too large
  /// for the full-size network's receptive field and largest anchors, for about coarse_scale^2 more network work
  bool coarse_pass = false;
  double coarse_scale = 0.5;      ///< coarse_pass: network input sides times this (multiples of 32), (0, 1)
  double coarse_min_size = 48.0;  ///< coarse_pass: its boxes below this sqrt(w h), image pixels, are dropped, >= 0
  /// multi-class models ([yolo] heads): a box whose drone score (objectness x P(drone)) reaches p_thresh is a drone
  /// box even when another class scores higher (decode_yolo); false: each box is its most probable class
  bool drone_first = false;
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
      "flip_fusion, coarse_pass: boxes of two passes overlapping above this IoU are fused (0..1)");
    v("detection.coarse_pass", coarse_pass,
      "also detect at coarse_scale of the network input and fuse its large boxes (close drones)");
    v("detection.coarse_scale", coarse_scale, "coarse_pass: network input sides times this, multiples of 32 (0..1)");
    v("detection.coarse_min_size", coarse_min_size,
      "coarse_pass: its boxes smaller than this sqrt(w h), image pixels, are dropped (>= 0)");
    v("detection.drone_first", drone_first,
      "multi-class models: a box whose drone score reaches p_thresh is a drone even if another class scores higher");
    v("detection.policy", policy, "all or most_confident");
    v("detection.max_detections", max_detections, "at most this many boxes per image (>= 1)");
  }
  /// One "key = value: rule" line per invalid field; empty when valid.
  std::vector<std::string> validate() const;
};

/// coarse_pass: the coarse pass's network input for a full-size one of `net`: each side times `scale`, rounded to
/// the nearest multiple of 32 (halves up), at least 32 (640x352 at 0.5: 320x192). Preconditions: `net` positive,
/// 0 < scale < 1 (std::invalid_argument otherwise).
cv::Size coarse_net_size(cv::Size net, double scale);
/// coarse_pass: the options of the nested coarse pipeline for the full-size pipeline's `options`: no zoom-in (a crop
/// is finer than the full-size pass already) and no coarse pass of its own; the rest as given.
DetectorPipelineOptions coarse_pass_options(const DetectorPipelineOptions& options);

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
///     replaces the detection (pass kZoomIn). The other detections, and those whose crop finds nothing,
///     keep their first-pass box unchanged (pass kSingle). The refined boxes go through NMS once more
///     (two crops may find the same drone);
///  5. with `flip_fusion`, steps 1-4 run twice, on the image and on its horizontal mirror (each pass keeping
///     boxes >= p_thresh / 2 and up to max_detections), the mirror's boxes are mirrored back, and the two lists
///     are fused (fuse_boxes(), IoU > fusion_iou: a box both passes found is their confidence-weighted mean with the
///     mean confidence; one only one pass found keeps half its confidence); then >= p_thresh, NMS, `policy` and
///     `max_detections` as in step 3;
///  6. with `coarse_pass`, a nested DetectionPipeline at coarse_net_size() (coarse_pass_options(): no zoom-in) runs
///     steps 1-3 on the image (and with flip_fusion on its mirror too); its boxes of sqrt(w h) >= coarse_min_size
///     join the full-size passes' and all are fused (fuse_boxes() with per-view minimum sizes, IoU > fusion_iou: a
///     box's confidence is its group's sum over the passes that see its size, so a small drone keeps the full-size
///     passes' confidence and a large one only the coarse passes found keeps half); each pass keeps boxes >=
///     p_thresh / (number of passes); then >= p_thresh, NMS, `policy` and `max_detections` as in step 3;
///  7. boxes are returned in full-image pixels, most confident first.
/// Buffers (network input batch, output tensor, box lists, resize scratch) are allocated at construction;
/// detect() allocates only the returned vector (and, for a new image size, the resize scratch and with flip_fusion the
/// mirrored image; the coarse pipeline likewise).
class DetectionPipeline {
 public:
  /// @param options  validated here (std::invalid_argument listing every problem).
  /// @param backend  not null; its input_shape() must be the model's net size and its output_shapes() the
  ///                 heads' inputs, in order (std::invalid_argument otherwise).
  /// @param model    the network the backend runs; must have at least one [region] or [yolo] head (the
  ///                 anchors are taken from them).
  /// @param coarse   with options.coarse_pass (and only then; std::invalid_argument otherwise), the step 6 pipeline:
  ///                 built with coarse_pass_options(options) on the model at coarse_net_size() of its size.
  DetectionPipeline(DetectorPipelineOptions options, std::unique_ptr<InferenceBackend> backend,
                    const DarknetModel& model, std::unique_ptr<DetectionPipeline> coarse = nullptr);

  /// Detects drones in `bgr_image` (CV_8UC3, any size >= 1 x 1; std::invalid_argument otherwise).
  /// Returns boxes in full-image pixels, most confident first.
  std::vector<Box> detect(const cv::Mat& bgr_image);

  /// Steps 2-3 on each of `regions` of `bgr_image` (each stretched to the network input; no subsquare, zoom-in, mirror
  /// or coarse pass), run in batches of up to backend().max_batch() images: per region, its boxes >= p_thresh after
  /// NMS and `policy`/`max_detections`, in that region's own pixels (origin at its top-left corner), most confident
  /// first. For tracker-driven windows (WindowDetector). Every region must lie inside the image and be non-empty
  /// (std::invalid_argument otherwise). The batch buffers grow to the largest batch used, once.
  std::vector<std::vector<Box>> detect_regions(const cv::Mat& bgr_image, const std::vector<cv::Rect>& regions);

  const DetectorPipelineOptions& options() const { return options_; }
  InferenceBackend& backend() { return *backend_; }
  /// coarse_pass: the nested coarse pipeline; null otherwise.
  DetectionPipeline* coarse() { return coarse_.get(); }

 private:
  /// Runs `count` images already in input_ through the backend and decodes image i's boxes from every head
  /// (>= p_thresh, network pixels) into candidates_[i].
  void run_and_decode(int count);
  /// Steps 1-4 on one view (the image or its mirror), keeping at most `keep` first-pass boxes; into detections_.
  void detect_view(const cv::Mat& bgr_image, size_t keep);
  /// Steps 1-4 on the image and, with flip_fusion, on `mirrored` (the image's horizontal mirror); appends the boxes
  /// of at least `min_size` (sqrt(w h), image pixels; the mirror's mirrored back) to `views` as views first_view and
  /// first_view + 1. Returns the number of views run (1 or 2).
  int append_views(const cv::Mat& bgr_image, const cv::Mat& mirrored, int first_view, float min_size,
                   std::vector<ViewBox>& views);

  DetectorPipelineOptions options_;
  std::unique_ptr<InferenceBackend> backend_;
  std::vector<Layer> heads_;                   ///< the [region]/[yolo] layers, in the backend's output order
  cv::Size net_size_;                          ///< network input, pixels
  int batch_capacity_ = 1;                     ///< images input_ holds: min(max_batch, max_detections), >= 1
  std::vector<float> input_;                   ///< batch_capacity_ x 3 x H x W network inputs
  std::vector<float> output_;                  ///< raw output tensor of the last forward()
  std::vector<std::vector<Box>> candidates_;   ///< per batch slot: decoded boxes
  std::vector<Box> detections_;                ///< current detections, full-image pixels
  std::vector<cv::Rect> crops_;                ///< zoom-in crops, full-image pixels
  std::vector<size_t> zoomed_;                 ///< per crop: the index in detections_ it re-detects
  cv::Mat resized_;                            ///< resize scratch
  float pass_floor_ = 0.0f;                    ///< confidence floor of each pass: p_thresh over the number of passes
  cv::Mat mirrored_;                           ///< flip_fusion: the mirrored image
  std::vector<ViewBox> views_;                 ///< flip_fusion, coarse_pass: every pass's boxes, full-image pixels
  std::vector<float> view_min_size_;           ///< coarse_pass: per pass, the smallest box it reports (fuse_boxes())
  std::unique_ptr<DetectionPipeline> coarse_;  ///< coarse_pass: the step 6 pipeline
};

}  // namespace wingman::detector
