// SPDX-License-Identifier: MIT
// Algorithm 2: the detection pipeline around an InferenceBackend.
#include "wingman/detector/detection_pipeline.hpp"

#include "wingman/detector/nms.hpp"
#include "wingman/detector/preprocess.hpp"
#include "wingman/detector/region_decode.hpp"

#include <wingman/common/config.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wingman::detector {

std::vector<std::string> DetectorPipelineOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (!(p_thresh >= 0.0 && p_thresh <= 1.0)) p.push_back(problem("detection.p_thresh", p_thresh, "must be in 0..1"));
  if (!(o_thresh >= 0.0 && o_thresh <= 1.0)) p.push_back(problem("detection.o_thresh", o_thresh, "must be in 0..1"));
  if (policy != "all" && policy != "most_confident")
    p.push_back(problem("detection.policy", policy, "must be all or most_confident"));
  if (!(zoom_max_fraction > 0.0 && zoom_max_fraction <= 1.0))
    p.push_back(problem("detection.zoom_max_fraction", zoom_max_fraction, "must be in (0, 1]"));
  if (!(fusion_iou >= 0.0 && fusion_iou <= 1.0))
    p.push_back(problem("detection.fusion_iou", fusion_iou, "must be in 0..1"));
  if (!(coarse_scale > 0.0 && coarse_scale < 1.0))
    p.push_back(problem("detection.coarse_scale", coarse_scale, "must be in (0, 1)"));
  if (!(std::isfinite(coarse_min_size) && coarse_min_size >= 0.0))
    p.push_back(problem("detection.coarse_min_size", coarse_min_size, "must be a finite number >= 0 (pixels)"));
  if (max_detections < 1) p.push_back(problem("detection.max_detections", max_detections, "must be >= 1"));
  return p;
}

cv::Size coarse_net_size(cv::Size net, double scale) {
  if (net.width <= 0 || net.height <= 0 || !(scale > 0.0 && scale < 1.0))
    throw std::invalid_argument(fmt::format("coarse_net_size: network {}x{} must be positive, scale {} in (0, 1)",
                                            net.width, net.height, scale));
  const auto side = [scale](int n) { return std::max(32, static_cast<int>(std::floor(n * scale / 32.0 + 0.5)) * 32); };
  return {side(net.width), side(net.height)};
}

DetectorPipelineOptions coarse_pass_options(const DetectorPipelineOptions& options) {
  DetectorPipelineOptions coarse = options;
  coarse.zoom_in = false;
  coarse.coarse_pass = false;
  return coarse;
}

DetectionPipeline::DetectionPipeline(DetectorPipelineOptions options, std::unique_ptr<InferenceBackend> backend,
                                     const DarknetModel& model, std::unique_ptr<DetectionPipeline> coarse)
    : options_(std::move(options)), backend_(std::move(backend)), coarse_(std::move(coarse)) {
  const std::vector<std::string> problems = options_.validate();
  if (!problems.empty()) {
    std::string all;
    for (const auto& p : problems) all += (all.empty() ? "" : "; ") + p;
    throw std::invalid_argument("DetectorPipelineOptions: " + all);
  }
  if (!backend_) throw std::invalid_argument("DetectionPipeline: backend is null");
  if (options_.coarse_pass != (coarse_ != nullptr))
    throw std::invalid_argument(options_.coarse_pass
                                    ? "DetectionPipeline: detection.coarse_pass needs the coarse pipeline"
                                    : "DetectionPipeline: a coarse pipeline without detection.coarse_pass");
  if (coarse_ && (coarse_->options_.coarse_pass || coarse_->options_.zoom_in))
    throw std::invalid_argument(
        "DetectionPipeline: the coarse pipeline must have neither coarse_pass nor zoom_in "
        "(coarse_pass_options())");
  for (const int h : model.heads()) heads_.push_back(model.layers[h]);
  if (heads_.empty())
    throw std::invalid_argument(
        fmt::format("DetectionPipeline: {} has no [region] or [yolo] head to decode", model.cfg_path));
  net_size_ = cv::Size(model.net.width, model.net.height);
  const Shape in = backend_->input_shape();
  if (!(in == Shape{3, model.net.height, model.net.width}))
    throw std::invalid_argument(fmt::format("DetectionPipeline: backend {} takes {}x{}x{}, the model 3x{}x{}",
                                            backend_->name(), in.c, in.h, in.w, model.net.height, model.net.width));
  const std::vector<Shape> outs = backend_->output_shapes();
  std::string want, got;
  for (const Layer& h : heads_) want += fmt::format(" {}x{}x{}", h.input.c, h.input.h, h.input.w);
  for (const Shape& o : outs) got += fmt::format(" {}x{}x{}", o.c, o.h, o.w);
  if (want != got)
    throw std::invalid_argument(
        fmt::format("DetectionPipeline: backend {} outputs{}, the heads need{}", backend_->name(), got, want));
  if (backend_->max_batch() < 1)
    throw std::invalid_argument(
        fmt::format("DetectionPipeline: backend {} has max_batch {}", backend_->name(), backend_->max_batch()));
  batch_capacity_ = options_.zoom_in ? std::max(1, std::min(backend_->max_batch(), options_.max_detections)) : 1;
  input_.resize(static_cast<size_t>(batch_capacity_) * in.size());
  output_.resize(static_cast<size_t>(batch_capacity_) * output_size(outs));
  candidates_.resize(batch_capacity_);
  size_t per_image = 0;  // most boxes one image can decode to
  for (const Layer& h : heads_) per_image += static_cast<size_t>(h.input.h) * h.input.w * h.num;
  for (auto& c : candidates_) c.reserve(per_image);
  detections_.reserve(per_image);
  crops_.reserve(options_.max_detections);
  zoomed_.reserve(options_.max_detections);
  resized_.create(net_size_, CV_8UC3);
  const int passes = (options_.flip_fusion ? 2 : 1) * (options_.coarse_pass ? 2 : 1);
  pass_floor_ = static_cast<float>(options_.p_thresh / passes);
  if (coarse_) coarse_->pass_floor_ = pass_floor_;
  if (passes > 1) views_.reserve(static_cast<size_t>(passes) * static_cast<size_t>(options_.max_detections));
  view_min_size_.reserve(static_cast<size_t>(passes));
}

void DetectionPipeline::run_and_decode(int count) {
  backend_->forward(input_.data(), count, output_);
  const size_t per_image = output_.size() / static_cast<size_t>(count);
  for (int i = 0; i < count; ++i) {
    candidates_[i].clear();
    const float* raw = output_.data() + i * per_image;
    for (const Layer& h : heads_) {
      decode_head(raw, h.input, h, net_size_.width, net_size_.height, pass_floor_, candidates_[i],
                  options_.drone_first);
      raw += h.input.size();
    }
  }
}

std::vector<std::vector<Box>> DetectionPipeline::detect_regions(const cv::Mat& bgr_image,
                                                                const std::vector<cv::Rect>& regions) {
  if (bgr_image.empty() || bgr_image.type() != CV_8UC3)
    throw std::invalid_argument(
        fmt::format("DetectionPipeline::detect_regions: image {}x{} type {}: must be non-empty CV_8UC3", bgr_image.cols,
                    bgr_image.rows, bgr_image.type()));
  const cv::Rect whole(0, 0, bgr_image.cols, bgr_image.rows);
  for (const cv::Rect& r : regions)
    if (r.empty() || (r & whole) != r)
      throw std::invalid_argument(
          fmt::format("DetectionPipeline::detect_regions: region {}x{} at ({}, {}) is empty or "
                      "leaves the {}x{} image",
                      r.width, r.height, r.x, r.y, bgr_image.cols, bgr_image.rows));
  const int batch = std::max(1, std::min(backend_->max_batch(), static_cast<int>(regions.size())));
  if (batch > batch_capacity_) {  // grow once to the batch this caller uses
    const Shape in = backend_->input_shape();
    batch_capacity_ = batch;
    input_.resize(static_cast<size_t>(batch_capacity_) * in.size());
    output_.resize(static_cast<size_t>(batch_capacity_) * output_size(backend_->output_shapes()));
    const size_t per_image = candidates_.empty() ? 0 : candidates_[0].capacity();
    candidates_.resize(static_cast<size_t>(batch_capacity_));
    for (auto& c : candidates_) c.reserve(per_image);
  }
  const size_t input_size = static_cast<size_t>(backend_->input_shape().size());
  const size_t keep = options_.policy == "most_confident" ? 1 : static_cast<size_t>(options_.max_detections);
  std::vector<std::vector<Box>> out(regions.size());
  for (size_t first = 0; first < regions.size(); first += static_cast<size_t>(batch)) {
    const int count = static_cast<int>(std::min(regions.size() - first, static_cast<size_t>(batch)));
    for (int i = 0; i < count; ++i)
      to_network_input(bgr_image, regions[first + i], net_size_, resized_, input_.data() + i * input_size);
    run_and_decode(count);
    for (int i = 0; i < count; ++i) {
      std::vector<Box>& found = candidates_[static_cast<size_t>(i)];
      // Boxes of at least p_thresh (run_and_decode() keeps down to the pass floor, the same for a single pass).
      found.erase(std::remove_if(found.begin(), found.end(),
                                 [&](const Box& b) { return b.confidence < static_cast<float>(options_.p_thresh); }),
                  found.end());
      non_max_suppression(found, static_cast<float>(options_.o_thresh));
      if (found.size() > keep) found.resize(keep);
      const cv::Rect& r = regions[first + static_cast<size_t>(i)];
      const cv::Rect own(0, 0, r.width, r.height);
      for (const Box& b : found) out[first + static_cast<size_t>(i)].push_back(network_to_image(b, own, net_size_));
    }
  }
  return out;
}

std::vector<Box> DetectionPipeline::detect(const cv::Mat& bgr_image) {
  if (bgr_image.empty() || bgr_image.type() != CV_8UC3)
    throw std::invalid_argument(fmt::format("DetectionPipeline::detect: image {}x{} type {}: must be non-empty CV_8UC3",
                                            bgr_image.cols, bgr_image.rows, bgr_image.type()));
  const size_t keep = options_.policy == "most_confident" ? 1 : static_cast<size_t>(options_.max_detections);
  if (!options_.flip_fusion && !options_.coarse_pass) {
    detect_view(bgr_image, keep);
    return detections_;
  }
  // Steps 5-6: every pass, fused.
  views_.clear();
  view_min_size_.clear();
  if (options_.flip_fusion) cv::flip(bgr_image, mirrored_, 1);  // once, for both sizes' passes
  const int fine = append_views(bgr_image, mirrored_, 0, 0.0f, views_);
  view_min_size_.assign(static_cast<size_t>(fine), 0.0f);
  if (coarse_) {
    const float min_size = static_cast<float>(options_.coarse_min_size);
    const int coarse = coarse_->append_views(bgr_image, mirrored_, fine, min_size, views_);
    view_min_size_.insert(view_min_size_.end(), static_cast<size_t>(coarse), min_size);
  }
  fuse_boxes(views_, view_min_size_, static_cast<float>(options_.fusion_iou), detections_);
  const float p_thresh = static_cast<float>(options_.p_thresh);
  detections_.erase(std::remove_if(detections_.begin(), detections_.end(),
                                   [p_thresh](const Box& b) { return b.confidence < p_thresh; }),
                    detections_.end());
  non_max_suppression(detections_, static_cast<float>(options_.o_thresh));
  if (detections_.size() > keep) detections_.resize(keep);
  return detections_;
}

int DetectionPipeline::append_views(const cv::Mat& bgr_image, const cv::Mat& mirrored, int first_view, float min_size,
                                    std::vector<ViewBox>& views) {
  const size_t per_view = static_cast<size_t>(options_.max_detections);
  const auto big_enough = [min_size](const Box& b) {
    return std::sqrt(std::max(0.0f, b.w) * std::max(0.0f, b.h)) >= min_size;
  };
  detect_view(bgr_image, per_view);
  for (const Box& b : detections_)
    if (big_enough(b)) views.push_back({b, first_view});
  if (!options_.flip_fusion) return 1;
  detect_view(mirrored, per_view);
  const float width = static_cast<float>(bgr_image.cols);
  for (const Box& b : detections_) {
    const Box back = mirror_horizontally(b, width);
    if (big_enough(back)) views.push_back({back, first_view + 1});
  }
  return 2;
}

void DetectionPipeline::detect_view(const cv::Mat& bgr_image, size_t keep) {
  const float o_thresh = static_cast<float>(options_.o_thresh);
  const size_t input_size = static_cast<size_t>(backend_->input_shape().size());

  // Steps 1-2: subsquare, resize, detect (Algorithm 2).
  const cv::Rect roi = detection_region(bgr_image.size(), options_.subsquare);
  to_network_input(bgr_image, roi, net_size_, resized_, input_.data());
  run_and_decode(1);
  // Step 3: NMS (Algorithm 1), policy, cap.
  non_max_suppression(candidates_[0], o_thresh);
  if (candidates_[0].size() > keep) candidates_[0].resize(keep);
  detections_.clear();
  for (const Box& b : candidates_[0]) detections_.push_back(network_to_image(b, roi, net_size_));

  // Step 4: zoom-in re-detection, crops in batches.
  // A crop is network-sized at full resolution: when the first pass did not shrink the region in either direction,
  // a crop would see the drone at the same scale or coarser, and zoom-in adds nothing.
  const bool zoom_finer = roi.width > net_size_.width || roi.height > net_size_.height;
  if (options_.zoom_in && zoom_finer && !detections_.empty()) {
    crops_.clear();
    zoomed_.clear();
    const float max_w = static_cast<float>(options_.zoom_max_fraction) * static_cast<float>(net_size_.width);
    const float max_h = static_cast<float>(options_.zoom_max_fraction) * static_cast<float>(net_size_.height);
    for (size_t k = 0; k < detections_.size(); ++k) {
      const Box& b = detections_[k];
      if (b.w > max_w || b.h > max_h) continue;  // too large for the crop: keep the first pass's box
      // Overlapping a more confident detection (NMS left detections_ most confident first, and kept this one at
      // IoU <= o_thresh): likely a part of that drone, and a crop centred on a part re-detects the part with a
      // confident box. Keep the first pass's box.
      bool overlaps_better = false;
      for (size_t j = 0; j < k && !overlaps_better; ++j) overlaps_better = iou(detections_[j], b) > 0.0f;
      if (overlaps_better) continue;
      crops_.push_back(zoom_crop(bgr_image.size(), net_size_, b.cx, b.cy));
      zoomed_.push_back(k);
    }
    for (size_t first = 0; first < crops_.size(); first += batch_capacity_) {
      const int count = static_cast<int>(std::min(crops_.size() - first, static_cast<size_t>(batch_capacity_)));
      for (int i = 0; i < count; ++i)
        to_network_input(bgr_image, crops_[first + i], net_size_, resized_, input_.data() + i * input_size);
      run_and_decode(count);
      for (int i = 0; i < count; ++i) {
        const std::vector<Box>& found = candidates_[i];
        if (found.empty()) continue;  // nothing re-detected: keep the original box, its pass stays single
        const Box* best = &found[0];
        for (const Box& b : found)
          if (b.confidence > best->confidence) best = &b;
        Box refined = network_to_image(*best, crops_[first + i], net_size_);
        refined.pass = Pass::kZoomIn;
        detections_[zoomed_[first + i]] = refined;
      }
    }
    non_max_suppression(detections_, o_thresh);
  }
}

}  // namespace wingman::detector
