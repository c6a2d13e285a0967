// SPDX-License-Identifier: MIT
// Decoding the raw input of a YOLOv2 [region] or YOLOv3 [yolo] head into boxes in network-input pixels.
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
///   class_id = argmax_c t_class_c (the first of equal maxima), drone_score = sigma(t_o) * softmax(t_class)_0
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

/// Appends to `boxes` every anchor of every grid cell whose confidence is >= p_thresh, decoded as Darknet's
/// [yolo] layer (YOLOv3, get_yolo_box), with s = yolo.scale_x_y (1 in YOLOv3):
///   b_x = (s * sigma(t_x) - (s - 1) / 2 + c_x) / W * net_w,  b_y likewise with c_y, H, net_h   (pixels)
///   b_w = a_w * exp(t_w),  b_h = a_h * exp(t_h)     (a = anchors[mask[k]], already network-input pixels)
///   confidence = sigma(t_o) * max_c sigma(t_class_c)   (independent logistic classes, no softmax)
///   class_id = argmax_c t_class_c (the first of equal maxima), drone_score = sigma(t_o) * sigma(t_class_0)
/// Darknet thresholds the objectness and then each class product; here the product is thresholded, as in
/// decode_region, so both heads mean the same by p_thresh. With `drone_first`, a cell whose drone score is
/// >= p_thresh is a drone box (class_id 0, confidence = drone_score) even when another class scores higher: a
/// multi-class model's drone that also looks like a bird is still reported as a drone.
///
/// @param raw    one image's raw head input, C x H x W floats with C = mask.size() * (5 + classes); channel
///               k * (5 + classes) + j holds t_x, t_y, t_w, t_h, t_o, t_class... (j = 0..4+classes) of
///               anchor mask[k].
/// @param shape  C x H x W of `raw`; must equal yolo.input (std::invalid_argument otherwise, also for a mask
///               index without an anchor).
/// @param yolo   the [yolo] layer (anchors, mask, classes, scale_x_y).
/// Does not allocate if `boxes` has capacity for H * W * mask.size() more boxes.
void decode_yolo(const float* raw, const Shape& shape, const Layer& yolo, int net_w, int net_h, float p_thresh,
                 std::vector<Box>& boxes, bool drone_first = false);

/// decode_region or decode_yolo (with `drone_first`), after `head`'s type (std::invalid_argument for any other layer).
void decode_head(const float* raw, const Shape& shape, const Layer& head, int net_w, int net_h, float p_thresh,
                 std::vector<Box>& boxes, bool drone_first = false);

}  // namespace wingman::detector
