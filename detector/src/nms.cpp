// SPDX-License-Identifier: MIT
// Box IoU, clipping to the image, mirroring, and non-maximum suppression (Algorithm 1).
#include "wingman/detector/nms.hpp"

#include <algorithm>

namespace wingman::detector {

float iou(const Box& a, const Box& b) {
  const float ix = std::min(a.cx + a.w / 2, b.cx + b.w / 2) - std::max(a.cx - a.w / 2, b.cx - b.w / 2);
  const float iy = std::min(a.cy + a.h / 2, b.cy + b.h / 2) - std::max(a.cy - a.h / 2, b.cy - b.h / 2);
  if (ix <= 0.0f || iy <= 0.0f) return 0.0f;
  const float inter = ix * iy;
  const float uni = a.w * a.h + b.w * b.h - inter;
  return uni > 0.0f ? inter / uni : 0.0f;
}

Box clip_to_image(const Box& b, float width, float height) {
  const float x0 = std::clamp(b.cx - b.w / 2, 0.0f, width), x1 = std::clamp(b.cx + b.w / 2, 0.0f, width);
  const float y0 = std::clamp(b.cy - b.h / 2, 0.0f, height), y1 = std::clamp(b.cy + b.h / 2, 0.0f, height);
  Box c = b;
  c.cx = 0.5f * (x0 + x1), c.cy = 0.5f * (y0 + y1);
  c.w = x1 - x0, c.h = y1 - y0;
  return c;
}

std::vector<Box> clip_to_image(const std::vector<Box>& boxes, float width, float height) {
  std::vector<Box> out;
  out.reserve(boxes.size());
  for (const Box& b : boxes) {
    const Box c = clip_to_image(b, width, height);
    if (c.w > 0.0f && c.h > 0.0f) out.push_back(c);
  }
  return out;
}

Box mirror_horizontally(const Box& b, float width) {
  Box m = b;
  m.cx = width - b.cx;
  return m;
}

void non_max_suppression(std::vector<Box>& boxes, float o_thresh) {
  // Algorithm 1: sort by confidence, keep the best, drop those overlapping it by more than o_thresh, repeat.
  std::stable_sort(boxes.begin(), boxes.end(), [](const Box& a, const Box& b) { return a.confidence > b.confidence; });
  size_t kept = 0;
  for (size_t i = 0; i < boxes.size(); ++i) {
    bool suppressed = false;
    for (size_t k = 0; k < kept && !suppressed; ++k) suppressed = iou(boxes[k], boxes[i]) > o_thresh;
    if (!suppressed) boxes[kept++] = boxes[i];
  }
  boxes.resize(kept);
}

}  // namespace wingman::detector
