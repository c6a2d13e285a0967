// SPDX-License-Identifier: MIT
// Tracker-driven windows: placing full-resolution crops where tracks will be, and merging what they find.
#include "wingman/detector/track_windows.hpp"

#include "wingman/detector/darknet_cfg.hpp"
#include "wingman/detector/nms.hpp"

#include <wingman/common/config.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wingman::detector {
namespace {

/// Half the gate of a window in each axis, pixels.
double gate_half(const Window& w, const WindowOptions& o) {
  return std::max(1.0, o.gate_sigma * w.sigma_px + 0.5 * std::max(w.w, w.h));
}

bool centre_in(const Box& inner, const Box& outer) {
  return std::abs(inner.cx - outer.cx) <= 0.5f * outer.w && std::abs(inner.cy - outer.cy) <= 0.5f * outer.h;
}

}  // namespace

std::vector<std::string> WindowOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (channel.empty()) p.push_back(problem("windows.channel", channel, "must not be empty"));
  if (crop_px < 32 || crop_px > 1024 || crop_px % 32 != 0)
    p.push_back(problem("windows.crop_px", crop_px, "must be a multiple of 32 in 32..1024"));
  if (max_per_frame < 1) p.push_back(problem("windows.max_per_frame", max_per_frame, "must be >= 1"));
  if (!(max_net_px > 0) || !std::isfinite(max_net_px))
    p.push_back(problem("windows.max_net_px", max_net_px, "must be > 0 and finite"));
  if (!(p_thresh >= 0 && p_thresh <= 1)) p.push_back(problem("windows.p_thresh", p_thresh, "must be in 0..1"));
  if (!(gate_sigma > 0) || !std::isfinite(gate_sigma))
    p.push_back(problem("windows.gate_sigma", gate_sigma, "must be > 0 and finite"));
  if (!(max_age_s > 0) || !std::isfinite(max_age_s))
    p.push_back(problem("windows.max_age_s", max_age_s, "must be > 0 and finite"));
  return p;
}

std::vector<Window> windows_to_search(const wingman::track_windows_t& m, int64_t image_utime, cv::Size image,
                                      int32_t camera_id, double net_px_per_image_px, const WindowOptions& o) {
  std::vector<Window> out;
  if (m.camera_id != camera_id || m.image_width != image.width || m.image_height != image.height) return out;
  const double dt = static_cast<double>(image_utime - m.utime_predicted) * 1e-6;
  if (std::abs(dt) > o.max_age_s) return out;
  for (const wingman::track_window_t& t : m.windows) {
    if (o.confirmed_only && !t.confirmed) continue;
    Window w;
    w.cx = t.cx + dt * t.vx;
    w.cy = t.cy + dt * t.vy;
    w.w = t.w;
    w.h = t.h;
    w.sigma_px = t.sigma_px;
    w.confirmed = t.confirmed;
    w.track_id = t.track_id;
    if (w.cx + 0.5 * w.w < 0 || w.cx - 0.5 * w.w > image.width || w.cy + 0.5 * w.h < 0 ||
        w.cy - 0.5 * w.h > image.height)
      continue;                                                                // out of the image
    if (std::sqrt(w.w * w.h) * net_px_per_image_px >= o.max_net_px) continue;  // the single pass sees it well
    out.push_back(w);
  }
  return out;
}

std::vector<cv::Rect> place_window_crops(const std::vector<Window>& windows, cv::Size image, const WindowOptions& o,
                                         std::vector<int>& crop_of_window) {
  std::vector<cv::Rect> crops;
  crop_of_window.assign(windows.size(), -1);
  const int cw = std::min(o.crop_px, image.width), ch = std::min(o.crop_px, image.height);
  for (size_t i = 0; i < windows.size(); ++i) {
    const Window& w = windows[i];
    const double g = gate_half(w, o);
    for (size_t c = 0; c < crops.size() && crop_of_window[i] < 0; ++c) {
      const cv::Rect& r = crops[c];
      if (w.cx - g >= r.x && w.cx + g <= r.x + r.width && w.cy - g >= r.y && w.cy + g <= r.y + r.height)
        crop_of_window[i] = static_cast<int>(c);
    }
    if (crop_of_window[i] >= 0 || static_cast<int>(crops.size()) >= o.max_per_frame) continue;
    const int x = std::clamp(static_cast<int>(std::lround(w.cx - 0.5 * cw)), 0, image.width - cw);
    const int y = std::clamp(static_cast<int>(std::lround(w.cy - 0.5 * ch)), 0, image.height - ch);
    crops.emplace_back(x, y, cw, ch);
    crop_of_window[i] = static_cast<int>(crops.size()) - 1;
  }
  return crops;
}

std::vector<Box> merge_window_boxes(std::vector<Box> first_pass, const std::vector<Window>& windows,
                                    const std::vector<cv::Rect>& crops, const std::vector<int>& crop_of_window,
                                    const std::vector<std::vector<Box>>& crop_boxes,
                                    const DetectorPipelineOptions& pipeline, const WindowOptions& o,
                                    WindowStats* stats) {
  if (crop_of_window.size() != windows.size() || crop_boxes.size() < crops.size())
    throw std::invalid_argument("merge_window_boxes: one crop index per window and one box list per crop expected");
  std::vector<Box> found;
  std::vector<const Window*> found_for;  // the window each found box answers
  int searched = 0, hits = 0;
  for (size_t i = 0; i < windows.size(); ++i) {
    const int c = crop_of_window[i];
    if (c < 0) continue;
    ++searched;
    const Window& w = windows[i];
    const double g = gate_half(w, o);
    const Box* best = nullptr;
    Box best_in_image;
    for (const Box& b : crop_boxes[static_cast<size_t>(c)]) {
      if (b.class_id != 0) continue;  // a window looks for the tracked drone
      Box in_image = b;
      in_image.cx += static_cast<float>(crops[static_cast<size_t>(c)].x);
      in_image.cy += static_cast<float>(crops[static_cast<size_t>(c)].y);
      if (std::abs(in_image.cx - w.cx) > g || std::abs(in_image.cy - w.cy) > g) continue;
      if (!best || b.confidence > best->confidence) {
        best = &b;
        best_in_image = in_image;
      }
    }
    if (!best) continue;
    ++hits;
    best_in_image.pass = Pass::kWindow;
    found.push_back(best_in_image);
    found_for.push_back(&w);
  }
  // A window's box replaces the single pass's boxes of the same drone.
  for (size_t i = 0; i < found.size(); ++i) {
    const Box& f = found[i];
    const Window& w = *found_for[i];
    const double g = gate_half(w, o);
    first_pass.erase(std::remove_if(first_pass.begin(), first_pass.end(),
                                    [&](const Box& b) {
                                      return iou(b, f) > pipeline.o_thresh || centre_in(f, b) || centre_in(b, f) ||
                                             (std::abs(b.cx - w.cx) <= g && std::abs(b.cy - w.cy) <= g);
                                    }),
                     first_pass.end());
  }
  first_pass.insert(first_pass.end(), found.begin(), found.end());
  non_max_suppression(first_pass, static_cast<float>(pipeline.o_thresh));
  const size_t keep = pipeline.policy == "most_confident" ? 1 : static_cast<size_t>(pipeline.max_detections);
  if (first_pass.size() > keep) first_pass.resize(keep);
  if (stats) {
    stats->windows += searched;
    stats->crops += static_cast<int>(crops.size());
    stats->found += hits;
  }
  return first_pass;
}

WindowDetector::WindowDetector(WindowOptions options, const DetectorPipelineOptions& pipeline,
                               const DarknetModel& model, const BackendFactory& make_backend)
    : options_(std::move(options)), pipeline_options_(pipeline) {
  if (const auto p = options_.validate(); !p.empty()) {
    std::string all;
    for (const auto& line : p) all += (all.empty() ? "" : "; ") + line;
    throw std::invalid_argument("WindowDetector: " + all);
  }
  DetectorPipelineOptions crop_options = pipeline;
  crop_options.p_thresh = options_.p_thresh;
  crop_options.subsquare = false;
  crop_options.zoom_in = false;
  crop_options.flip_fusion = false;
  crop_options.coarse_pass = false;
  crop_options.policy = "all";
  DarknetModel sized = model;
  sized.net.width = options_.crop_px;
  sized.net.height = options_.crop_px;
  compute_shapes(sized);
  pipeline_ = std::make_unique<DetectionPipeline>(crop_options, make_backend(sized), sized);
}

std::vector<Box> WindowDetector::detect(const cv::Mat& bgr_image, std::vector<Box> first_pass,
                                        const std::vector<Window>& windows, WindowStats* stats) {
  return detect(bgr_image, std::move(first_pass), windows, options_, stats);
}

std::vector<Box> WindowDetector::detect(const cv::Mat& bgr_image, std::vector<Box> first_pass,
                                        const std::vector<Window>& windows, const WindowOptions& options,
                                        WindowStats* stats) {
  if (options.crop_px != options_.crop_px)
    throw std::logic_error("WindowDetector::detect: crop_px differs from the network's input");
  const std::vector<cv::Rect> crops = place_window_crops(windows, bgr_image.size(), options, crop_of_window_);
  // Every crop of the frame in one forward (up to the backend's max_batch).
  const std::vector<std::vector<Box>> crop_boxes = pipeline_->detect_regions(bgr_image, crops);
  return merge_window_boxes(std::move(first_pass), windows, crops, crop_of_window_, crop_boxes, pipeline_options_,
                            options, stats);
}

}  // namespace wingman::detector
