// SPDX-License-Identifier: MIT
// YOLOv2 [region] and YOLOv3 [yolo] decode.
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
        float class_prob = 1.0f, drone_prob = 1.0f;
        int best = 0;
        if (region.classes > 1) {
          float max_t = base[5 * plane + i];
          for (int c = 1; c < region.classes; ++c)
            if (base[(5 + c) * plane + i] > max_t) max_t = base[(5 + c) * plane + i], best = c;
          float sum = 0.0f;
          for (int c = 0; c < region.classes; ++c) sum += std::exp(base[(5 + c) * plane + i] - max_t);
          class_prob = 1.0f / sum;  // the largest softmax value
          drone_prob = std::exp(base[5 * plane + i] - max_t) / sum;
        }
        const float objectness = sigmoid(base[4 * plane + i]);
        const float confidence = objectness * class_prob;
        if (confidence < p_thresh) continue;
        Box b;
        b.class_id = best;
        b.drone_score = objectness * drone_prob;
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

void decode_yolo(const float* raw, const Shape& shape, const Layer& yolo, int net_w, int net_h, float p_thresh,
                 std::vector<Box>& boxes, bool drone_first) {
  const int per_anchor = 5 + yolo.classes;
  const int num = static_cast<int>(yolo.mask.size());
  if (!(shape == yolo.input) || num < 1 || shape.c != num * per_anchor)
    throw std::invalid_argument(fmt::format(
        "decode_yolo: tensor {}x{}x{} does not fit the [yolo] layer (input {}x{}x{}, mask of {}, classes {})", shape.c,
        shape.h, shape.w, yolo.input.c, yolo.input.h, yolo.input.w, num, yolo.classes));
  for (const int m : yolo.mask)
    if (m < 0 || 2 * static_cast<size_t>(m) + 1 >= yolo.anchors.size())
      throw std::invalid_argument(
          fmt::format("decode_yolo: mask index {} has no anchor ({} anchors)", m, yolo.anchors.size() / 2));
  const int plane = shape.h * shape.w;
  const float s = yolo.scale_x_y;
  const float shift = 0.5f * (s - 1.0f);
  const float to_px_x = static_cast<float>(net_w) / shape.w;
  const float to_px_y = static_cast<float>(net_h) / shape.h;
  for (int k = 0; k < num; ++k) {
    const float* base = raw + static_cast<size_t>(k) * per_anchor * plane;
    const float a_w = yolo.anchors[2 * yolo.mask[k]];
    const float a_h = yolo.anchors[2 * yolo.mask[k] + 1];
    for (int row = 0; row < shape.h; ++row) {
      for (int col = 0; col < shape.w; ++col) {
        const int i = row * shape.w + col;
        float max_t = base[5 * plane + i];  // sigma is increasing: max of sigma = sigma of max
        int best = 0;                       // the first of equal maxima, as the reference's argmax
        for (int c = 1; c < yolo.classes; ++c)
          if (base[(5 + c) * plane + i] > max_t) max_t = base[(5 + c) * plane + i], best = c;
        const float objectness = sigmoid(base[4 * plane + i]);
        float confidence = objectness * sigmoid(max_t);
        const float drone_score = best == 0 ? confidence : objectness * sigmoid(base[5 * plane + i]);
        if (drone_first && drone_score >= p_thresh) best = 0, confidence = drone_score;
        if (confidence < p_thresh) continue;
        Box b;
        b.class_id = best;
        b.drone_score = drone_score;
        b.cx = (s * sigmoid(base[i]) - shift + col) * to_px_x;
        b.cy = (s * sigmoid(base[plane + i]) - shift + row) * to_px_y;
        b.w = a_w * std::exp(base[2 * plane + i]);
        b.h = a_h * std::exp(base[3 * plane + i]);
        b.confidence = confidence;
        boxes.push_back(b);
      }
    }
  }
}

void decode_head(const float* raw, const Shape& shape, const Layer& head, int net_w, int net_h, float p_thresh,
                 std::vector<Box>& boxes, bool drone_first) {
  if (head.type == LayerType::kRegion)
    decode_region(raw, shape, head, net_w, net_h, p_thresh, boxes);
  else if (head.type == LayerType::kYolo)
    decode_yolo(raw, shape, head, net_w, net_h, p_thresh, boxes, drone_first);
  else
    throw std::invalid_argument("decode_head: the layer is neither [region] nor [yolo]");
}

}  // namespace wingman::detector
