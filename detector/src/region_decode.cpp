// SPDX-License-Identifier: MIT
// YOLOv2 region decode.
#include "wingman/detector/region_decode.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wingman::detector {

namespace {
inline float sigmoid(float x) { return 1.0f / (1.0f + std::exp(-x)); }
}  // namespace

void decode_region(const float* raw, const Shape& shape, const Layer& region, int net_w, int net_h, float p_thresh,
                   std::vector<Box>& boxes) {
  const int per_anchor = 5 + region.classes;
  if (!(shape == region.input) || shape.c != region.num * per_anchor ||
      region.anchors.size() < static_cast<size_t>(2 * region.num))
    throw std::invalid_argument(fmt::format(
        "decode_region: tensor {}x{}x{} does not fit the [region] layer (input {}x{}x{}, num {}, classes {})", shape.c,
        shape.h, shape.w, region.input.c, region.input.h, region.input.w, region.num, region.classes));
  const int plane = shape.h * shape.w;
  for (int a = 0; a < region.num; ++a) {
    const float* base = raw + static_cast<size_t>(a) * per_anchor * plane;
    const float p_w = region.anchors[2 * a];
    const float p_h = region.anchors[2 * a + 1];
    for (int row = 0; row < shape.h; ++row) {
      for (int col = 0; col < shape.w; ++col) {
        const int i = row * shape.w + col;
        float class_prob = 1.0f;
        if (region.classes > 1) {
          float max_t = base[5 * plane + i];
          for (int c = 1; c < region.classes; ++c) max_t = std::max(max_t, base[(5 + c) * plane + i]);
          float sum = 0.0f;
          for (int c = 0; c < region.classes; ++c) sum += std::exp(base[(5 + c) * plane + i] - max_t);
          class_prob = 1.0f / sum;  // the largest softmax value
        }
        const float confidence = sigmoid(base[4 * plane + i]) * class_prob;
        if (confidence < p_thresh) continue;
        Box b;
        b.cx = (sigmoid(base[i]) + col) * net_w / shape.w;
        b.cy = (sigmoid(base[plane + i]) + row) * net_h / shape.h;
        b.w = p_w * std::exp(base[2 * plane + i]) * net_w / shape.w;
        b.h = p_h * std::exp(base[3 * plane + i]) * net_h / shape.h;
        b.confidence = confidence;
        boxes.push_back(b);
      }
    }
  }
}

}  // namespace wingman::detector
