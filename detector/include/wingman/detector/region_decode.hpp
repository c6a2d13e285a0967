// SPDX-License-Identifier: MIT
// Decoding the raw output of a YOLOv2 [region] head into boxes in network-input pixels.
#pragma once

#include "wingman/detector/box.hpp"
#include "wingman/detector/darknet_model.hpp"

#include <vector>

namespace wingman::detector {

/// Appends to `boxes` every anchor of every grid cell whose confidence is >= p_thresh, decoded as in
/// YOLOv2 (the thesis' region layer):
///   b_x = sigma(t_x) + c_x,  b_y = sigma(t_y) + c_y          (grid cells)
///   b_w = p_w * exp(t_w),    b_h = p_h * exp(t_h)            (p_w, p_h: the anchor, grid cells)
///   confidence = sigma(t_o) * max_c softmax(t_class)_c      (= sigma(t_o) with one class)
/// then scaled to network-input pixels: x * net_w / W, y * net_h / H (W x H: the grid).
///
/// @param raw    one image's raw output, C x H x W floats with C = num * (5 + classes); channel
///               a * (5 + classes) + k holds t_x, t_y, t_w, t_h, t_o, t_class... (k = 0..4+classes) of anchor a.
/// @param shape  C x H x W of `raw`; must equal region.input (std::invalid_argument otherwise).
/// @param region the [region] layer (anchors, num, classes).
/// @param net_w, net_h  network input size, pixels.
/// Does not allocate if `boxes` has capacity for H * W * num more boxes.
void decode_region(const float* raw, const Shape& shape, const Layer& region, int net_w, int net_h, float p_thresh,
                   std::vector<Box>& boxes);

}  // namespace wingman::detector
