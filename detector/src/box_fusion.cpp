// SPDX-License-Identifier: MIT
// Weighted box fusion of several passes' detections.
#include "wingman/detector/box_fusion.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace wingman::detector {

namespace {

/// Running sums of one group: the fused box is their weighted mean.
struct Group {
  double weight = 0.0, cx = 0.0, cy = 0.0, w = 0.0, h = 0.0;
  double drone_score = 0.0;  ///< sum of the members' drone scores
  uint32_t views = 0;        ///< bit v set: the group holds a box of view v
  Box fused;                 ///< the weighted mean so far; the highest pass of its members
};

/// Both overloads: `min_size` null (every view sees every size) or view_count minimum sizes.
void fuse(std::vector<ViewBox>& boxes, int view_count, const float* min_size, float iou_thresh,
          std::vector<Box>& fused) {
  if (view_count < 1 || view_count > 32)
    throw std::invalid_argument(fmt::format("fuse_boxes: view_count {} must be in 1..32", view_count));
  if (!(iou_thresh >= 0.0f && iou_thresh <= 1.0f))
    throw std::invalid_argument(fmt::format("fuse_boxes: iou_thresh {} must be in 0..1", iou_thresh));
  for (const ViewBox& b : boxes)
    if (b.view < 0 || b.view >= view_count)
      throw std::invalid_argument(fmt::format("fuse_boxes: a box of view {}; views are 0..{}", b.view, view_count - 1));
  std::stable_sort(boxes.begin(), boxes.end(),
                   [](const ViewBox& a, const ViewBox& b) { return a.box.confidence > b.box.confidence; });
  // One Group per output box; thread-local so that a detector calling this per frame allocates only while it grows.
  thread_local std::vector<Group> groups;
  groups.clear();
  for (const ViewBox& vb : boxes) {
    const uint32_t bit = uint32_t{1} << vb.view;
    Group* best = nullptr;
    float best_iou = iou_thresh;
    for (Group& g : groups) {
      if (g.views & bit) continue;
      const float o = iou(g.fused, vb.box);
      if (o > best_iou) {
        best_iou = o;
        best = &g;
      }
    }
    if (best == nullptr) {
      groups.emplace_back();
      best = &groups.back();
    }
    const double c = vb.box.confidence;
    best->weight += c;
    best->cx += c * vb.box.cx;
    best->cy += c * vb.box.cy;
    best->w += c * vb.box.w;
    best->h += c * vb.box.h;
    best->drone_score += vb.box.drone_score;
    best->views |= bit;
    const int class_id = best->views == bit ? vb.box.class_id : best->fused.class_id;  // the first (most confident)
    const Pass pass = std::max(best->fused.pass, vb.box.pass);
    if (best->weight > 0.0) {
      best->fused.cx = static_cast<float>(best->cx / best->weight);
      best->fused.cy = static_cast<float>(best->cy / best->weight);
      best->fused.w = static_cast<float>(best->w / best->weight);
      best->fused.h = static_cast<float>(best->h / best->weight);
    } else {  // only zero-confidence members so far: their plain box
      best->fused = vb.box;
    }
    best->fused.confidence = static_cast<float>(best->weight / view_count);
    best->fused.drone_score = static_cast<float>(best->drone_score / view_count);
    best->fused.class_id = class_id;
    best->fused.pass = pass;
  }
  fused.clear();
  for (const Group& g : groups) {
    fused.push_back(g.fused);
    if (min_size == nullptr) continue;
    // Only the views that see a box this size count; at least those that found it.
    const float size = std::sqrt(std::max(0.0f, g.fused.w) * std::max(0.0f, g.fused.h));
    int seeing = 0, holding = 0;
    for (int v = 0; v < view_count; ++v) {
      seeing += size >= min_size[v] ? 1 : 0;
      holding += (g.views >> v) & 1u ? 1 : 0;
    }
    fused.back().confidence = static_cast<float>(g.weight / std::max(seeing, holding));
    fused.back().drone_score = static_cast<float>(g.drone_score / std::max(seeing, holding));
  }
}

}  // namespace

void fuse_boxes(std::vector<ViewBox>& boxes, int view_count, float iou_thresh, std::vector<Box>& fused) {
  fuse(boxes, view_count, nullptr, iou_thresh, fused);
}

void fuse_boxes(std::vector<ViewBox>& boxes, const std::vector<float>& view_min_size_px, float iou_thresh,
                std::vector<Box>& fused) {
  for (size_t v = 0; v < view_min_size_px.size(); ++v)
    if (!(std::isfinite(view_min_size_px[v]) && view_min_size_px[v] >= 0.0f))
      throw std::invalid_argument(
          fmt::format("fuse_boxes: view {}'s minimum box size {} must be finite and >= 0", v, view_min_size_px[v]));
  fuse(boxes, static_cast<int>(view_min_size_px.size()), view_min_size_px.data(), iou_thresh, fused);
}

}  // namespace wingman::detector
