// SPDX-License-Identifier: MIT
// The training losses of the detection heads: eq. 13 for YOLOv2's [region], the YOLOv3 loss for [yolo].
//
// This header includes libtorch: include it only from the trainer's own sources and tests.
#pragma once

#include "wingman/training/yolo_dataset.hpp"

#include <wingman/detector/darknet_model.hpp>

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <vector>

namespace wingman::training {

/// The loss of one head on one batch, summed over the batch's images (the trainer divides by the batch).
struct LossTerms {
  at::Tensor total;         ///< scalar, differentiable w.r.t. the raw head tensor: coord + object + noobject + cls
  double coord = 0.0;       ///< centre and size term (weighted)
  double object = 0.0;      ///< confidence term of the responsible predictions (weighted)
  double noobject = 0.0;    ///< confidence term of the other predictions (weighted)
  double cls = 0.0;         ///< class term (weighted); 0 for one class under [region]'s softmax
  int64_t responsible = 0;  ///< truth boxes that got a responsible prediction
  double iou_sum = 0.0;     ///< sum over those of the IoU of the prediction with its truth (for a mean IoU)
};

/// The YOLOv2 [region] loss, eq. 13 of the thesis, on one batch. Its weights and switches are the layer's
/// .cfg keys: object_scale (lambda_obj; the thesis network: 5), noobject_scale (lambda_noobj: 1), coord_scale,
/// class_scale, thresh (the ignore threshold) and rescore.
///
/// `raw` is the head's input, N x num*(5+classes) x H x W, channel a*(5+classes)+k holding t_x, t_y, t_w, t_h,
/// t_o, t_class... of anchor a (the detector's layout; decode as in detector::decode_region). With
/// sigma the logistic function, (c_x, c_y) the cell and (p_w, p_h) the anchor in cells, a prediction is
///   x = sigma(t_x), y = sigma(t_y)  (offset in the cell),   w = p_w e^{t_w} / W,  h = p_h e^{t_h} / H  (image
///   fractions),   C = sigma(t_o),   p(c) = softmax(t_class)_c.
/// Each truth box (cx, cy, w_t, h_t; image fractions) is assigned to the cell holding its centre,
/// (floor(cx W), floor(cy H)), and there to the anchor whose shape (p_w / W, p_h / H) has the largest IoU with
/// (w_t, h_t), both centred (ties: the first anchor; two truths on one anchor: the later one wins). Then
///   coord    = coord_scale    * sum_resp [(x - x_t)^2 + (y - y_t)^2 + (sqrt w - sqrt w_t)^2 + (sqrt h - sqrt h_t)^2]
///   object   = object_scale   * sum_resp (C - C_t)^2,  C_t = IoU(predicted box, truth box) with rescore, else 1
///   noobject = noobject_scale * sum_other C^2, leaving out predictions whose IoU with some truth > thresh
///   cls      = class_scale    * sum_resp sum_c (p(c) - [c = class_t])^2
/// with x_t = cx W - floor(cx W), y_t likewise. C_t and the ignore test use the predicted box without gradient.
/// `truths[n]` are image n's boxes; truths.size() must be N (std::invalid_argument otherwise), as must the
/// channel count be num * (5 + classes).
LossTerms region_loss(const at::Tensor& raw, const detector::Layer& region,
                      const std::vector<std::vector<LabeledBox>>& truths);

/// The YOLOv3 [yolo] loss of one head on one batch (Darknet's assignment, the usual terms).
///
/// `raw` as for region_loss with num = mask.size(); anchors are in network-input pixels, so with
/// s = scale_x_y (1 in YOLOv3)
///   x = s sigma(t_x) - (s - 1) / 2, y likewise,  w = p_w e^{t_w} / net_w,  h = p_h e^{t_h} / net_h.
/// Each truth box goes to the anchor of the whole `anchors` list (all heads) whose shape has the largest IoU
/// with it; only if that anchor is in this head's mask does this head get a responsible prediction, in the
/// cell holding the centre. With s = 2 - w_t h_t (more weight on small boxes) and BCE the binary cross-entropy
/// on the logits:
///   coord    = sum_resp s [(x - x_t)^2 + (y - y_t)^2 + (t_w - log(w_t net_w / p_w))^2 + (t_h - log(h_t net_h /
///   p_h))^2] object   = sum_resp BCE(t_o, 1) noobject = sum_other BCE(t_o, 0), leaving out predictions whose IoU with
///   some truth exceeds ignore_thresh cls      = sum_resp sum_c BCE(t_class_c, [c = class_t])
/// With the layer's iou_loss giou, diou or ciou (AlexeyAB Darknet's keys) the box term is instead
///   coord = iou_normalizer * sum_resp (1 - L(b, b_t)),  b = ((x + c_x) / W, (y + c_y) / H, w, h) the predicted box,
/// L the generalized IoU (IoU - (|C| - |A u B|) / |C|, C the smallest box holding both), the distance IoU
/// (IoU - d^2 / c^2: d the distance of the centres, c the diagonal of C) or the complete IoU (DIoU - alpha v,
/// v = 4 / pi^2 (atan(w_t / h_t) - atan(w / h))^2, alpha = v / (1 - IoU + v) held constant), all in image fractions,
/// differentiable through b (t_w and t_h clamped to +-10 inside the exponential).
LossTerms yolo_loss(const at::Tensor& raw, const detector::Layer& yolo, int net_w, int net_h,
                    const std::vector<std::vector<LabeledBox>>& truths);

}  // namespace wingman::training
