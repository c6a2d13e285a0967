// SPDX-License-Identifier: MIT
// [region] (eq. 13) and [yolo] losses.
#include "wingman/training/detection_loss.hpp"

#include <wingman/detector/darknet_cfg.hpp>

#include <ATen/ATen.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>

namespace wingman::training {

namespace {

/// The parts of a raw head tensor, each N x A x H x W (cls: N x A x K x H x W).
struct HeadView {
  int64_t n, a, k, h, w;
  at::Tensor tx, ty, tw, th, to, cls;
};

HeadView split_head(const at::Tensor& raw, const detector::Layer& l, size_t truth_images) {
  const int per = 5 + l.classes;
  if (raw.dim() != 4 || raw.size(1) != static_cast<int64_t>(l.num) * per)
    throw std::invalid_argument(
        fmt::format("[{}] loss: tensor with {} dimensions and {} channels, expected N x {} x H x W",
                    detector::layer_type_name(l.type), raw.dim(), raw.dim() > 1 ? raw.size(1) : 0, l.num * per));
  if (static_cast<size_t>(raw.size(0)) != truth_images)
    throw std::invalid_argument(fmt::format("[{}] loss: batch of {} images but {} truth lists",
                                            detector::layer_type_name(l.type), raw.size(0), truth_images));
  HeadView v{raw.size(0), l.num, l.classes, raw.size(2), raw.size(3), {}, {}, {}, {}, {}, {}};
  const at::Tensor r = raw.view({v.n, v.a, per, v.h, v.w});
  v.tx = r.select(2, 0);
  v.ty = r.select(2, 1);
  v.tw = r.select(2, 2);
  v.th = r.select(2, 3);
  v.to = r.select(2, 4);
  v.cls = r.slice(2, 5, per);
  return v;
}

/// Predicted boxes (centre x, y, width, height as image fractions), N x A x H x W x 4, without gradient.
/// s: [yolo]'s scale_x_y (1 for [region]).
at::Tensor predicted_boxes(const HeadView& v, const at::Tensor& anchor_w, const at::Tensor& anchor_h, double s = 1.0) {
  at::NoGradGuard no_grad;
  const at::Tensor col = at::arange(v.w, at::kFloat).view({1, 1, 1, v.w});
  const at::Tensor row = at::arange(v.h, at::kFloat).view({1, 1, v.h, 1});
  const at::Tensor x = (s * at::sigmoid(v.tx) - 0.5 * (s - 1.0) + col) / static_cast<double>(v.w);
  const at::Tensor y = (s * at::sigmoid(v.ty) - 0.5 * (s - 1.0) + row) / static_cast<double>(v.h);
  const at::Tensor w = at::exp(v.tw) * anchor_w.view({1, v.a, 1, 1});
  const at::Tensor h = at::exp(v.th) * anchor_h.view({1, v.a, 1, 1});
  return at::stack({x, y, w, h}, -1);
}

/// IoU of boxes (..., 4) against one box (cx, cy, w, h), elementwise.
at::Tensor iou_with(const at::Tensor& boxes, const LabeledBox& t) {
  const at::Tensor x = boxes.select(-1, 0), y = boxes.select(-1, 1), w = boxes.select(-1, 2), h = boxes.select(-1, 3);
  const double tx0 = t.cx - 0.5 * t.w, tx1 = t.cx + 0.5 * t.w, ty0 = t.cy - 0.5 * t.h, ty1 = t.cy + 0.5 * t.h;
  const at::Tensor iw = ((x + w / 2).clamp_max(tx1) - (x - w / 2).clamp_min(tx0)).clamp_min(0);
  const at::Tensor ih = ((y + h / 2).clamp_max(ty1) - (y - h / 2).clamp_min(ty0)).clamp_min(0);
  const at::Tensor inter = iw * ih;
  return inter / (w * h + static_cast<double>(t.w) * t.h - inter).clamp_min(1e-12);
}

double box_iou(double ax, double ay, double aw, double ah, const LabeledBox& t) {
  const double iw =
      std::max(0.0, std::min(ax + aw / 2, double(t.cx) + t.w / 2.0) - std::max(ax - aw / 2, double(t.cx) - t.w / 2.0));
  const double ih =
      std::max(0.0, std::min(ay + ah / 2, double(t.cy) + t.h / 2.0) - std::max(ay - ah / 2, double(t.cy) - t.h / 2.0));
  const double inter = iw * ih;
  const double uni = aw * ah + double(t.w) * t.h - inter;
  return uni > 0 ? inter / uni : 0.0;
}

/// IoU of two boxes of sizes (w1, h1), (w2, h2) with the same centre.
double shape_iou(double w1, double h1, double w2, double h2) {
  const double inter = std::min(w1, w2) * std::min(h1, h2);
  const double uni = w1 * h1 + w2 * h2 - inter;
  return uni > 0 ? inter / uni : 0.0;
}

/// Predictions whose IoU with some truth of their image exceeds `thresh` (N x A x H x W, bool).
at::Tensor ignore_mask(const at::Tensor& pred, const std::vector<std::vector<LabeledBox>>& truths, double thresh) {
  at::NoGradGuard no_grad;
  at::Tensor best = at::zeros(pred.sizes().slice(0, 4), at::kFloat);
  for (size_t n = 0; n < truths.size(); ++n) {
    at::Tensor b = best.select(0, static_cast<int64_t>(n));
    const at::Tensor p = pred.select(0, static_cast<int64_t>(n));
    for (const LabeledBox& t : truths[n]) b.copy_(at::max(b, iou_with(p, t)));
  }
  return best > thresh;
}

/// A responsible prediction: image, anchor slot, row, column and its truth.
struct Assignment {
  int64_t n, a, row, col;
  LabeledBox truth;
};

/// Keeps one assignment per (n, a, row, col): the later truth wins.
std::vector<Assignment> unique_slots(const std::vector<Assignment>& all) {
  std::map<std::tuple<int64_t, int64_t, int64_t, int64_t>, size_t> slot;
  for (size_t i = 0; i < all.size(); ++i) slot[{all[i].n, all[i].a, all[i].row, all[i].col}] = i;
  std::vector<size_t> keep;
  for (const auto& kv : slot) keep.push_back(kv.second);
  std::sort(keep.begin(), keep.end());
  std::vector<Assignment> out;
  for (size_t i : keep) out.push_back(all[i]);
  return out;
}

int64_t cell_of(float f, int64_t cells) {
  return std::clamp<int64_t>(static_cast<int64_t>(std::floor(f * cells)), 0, cells - 1);
}

}  // namespace

LossTerms region_loss(const at::Tensor& raw, const detector::Layer& region,
                      const std::vector<std::vector<LabeledBox>>& truths) {
  const HeadView v = split_head(raw, region, truths.size());
  std::vector<float> aw(static_cast<size_t>(v.a)), ah(static_cast<size_t>(v.a));
  for (int64_t a = 0; a < v.a; ++a) {
    aw[a] = region.anchors[2 * a] / static_cast<float>(v.w);  // anchors: grid cells -> image fractions
    ah[a] = region.anchors[2 * a + 1] / static_cast<float>(v.h);
  }
  const at::Tensor anchor_w = at::tensor(aw), anchor_h = at::tensor(ah);
  const at::Tensor pred = predicted_boxes(v, anchor_w, anchor_h);
  const at::Tensor ignore = ignore_mask(pred, truths, region.thresh);

  std::vector<Assignment> all;
  for (size_t n = 0; n < truths.size(); ++n)
    for (const LabeledBox& t : truths[n]) {
      int64_t best = 0;
      double best_iou = -1.0;
      for (int64_t a = 0; a < v.a; ++a) {
        const double iou = shape_iou(t.w, t.h, aw[a], ah[a]);
        if (iou > best_iou) best_iou = iou, best = a;
      }
      all.push_back({static_cast<int64_t>(n), best, cell_of(t.cy, v.h), cell_of(t.cx, v.w), t});
    }
  const std::vector<Assignment> resp = unique_slots(all);

  const at::Tensor conf = at::sigmoid(v.to);
  // No-object term over every prediction that is neither responsible nor ignored.
  at::Tensor noobj = at::logical_not(ignore).to(at::kFloat);
  for (const Assignment& r : resp) noobj[r.n][r.a][r.row][r.col] = 0.0f;
  LossTerms out;
  const at::Tensor noobject = static_cast<double>(region.noobject_scale) * (noobj * conf * conf).sum();
  at::Tensor coord = at::zeros({}, raw.options());
  at::Tensor object = at::zeros({}, raw.options());
  at::Tensor cls = at::zeros({}, raw.options());
  if (!resp.empty()) {
    std::vector<int64_t> in, ia, ir, ic;
    std::vector<float> xt, yt, swt, sht, ct, iou_v;
    std::vector<int64_t> klass;
    for (const Assignment& r : resp) {
      in.push_back(r.n), ia.push_back(r.a), ir.push_back(r.row), ic.push_back(r.col);
      xt.push_back(r.truth.cx * v.w - r.col);
      yt.push_back(r.truth.cy * v.h - r.row);
      swt.push_back(std::sqrt(r.truth.w));
      sht.push_back(std::sqrt(r.truth.h));
      const at::Tensor p = pred[r.n][r.a][r.row][r.col];
      const double iou =
          box_iou(p[0].item<float>(), p[1].item<float>(), p[2].item<float>(), p[3].item<float>(), r.truth);
      iou_v.push_back(static_cast<float>(iou));
      ct.push_back(region.rescore != 0 ? static_cast<float>(iou) : 1.0f);
      klass.push_back(r.truth.cls);
      out.iou_sum += iou;
    }
    const at::Tensor N = at::tensor(in), A = at::tensor(ia), R = at::tensor(ir), C = at::tensor(ic);
    auto at_resp = [&](const at::Tensor& t) { return t.index({N, A, R, C}); };
    const at::Tensor x = at::sigmoid(at_resp(v.tx)), y = at::sigmoid(at_resp(v.ty));
    // sqrt(p_w e^{t_w} / W) = sqrt(p_w / W) e^{t_w / 2}
    const at::Tensor sw = at::sqrt(anchor_w.index({A})) * at::exp(at_resp(v.tw) * 0.5);
    const at::Tensor sh = at::sqrt(anchor_h.index({A})) * at::exp(at_resp(v.th) * 0.5);
    coord = static_cast<double>(region.coord_scale) * ((x - at::tensor(xt)).pow(2) + (y - at::tensor(yt)).pow(2) +
                                                       (sw - at::tensor(swt)).pow(2) + (sh - at::tensor(sht)).pow(2))
                                                          .sum();
    object = static_cast<double>(region.object_scale) * (at_resp(conf) - at::tensor(ct)).pow(2).sum();
    if (v.k > 0) {
      // cls: N x A x K x H x W -> responsible rows x K
      const at::Tensor logits = v.cls.permute({0, 1, 3, 4, 2}).index({N, A, R, C});
      const at::Tensor p = at::softmax(logits, 1);
      const at::Tensor onehot = at::one_hot(at::tensor(klass), v.k).to(at::kFloat);
      cls = static_cast<double>(region.class_scale) * (p - onehot).pow(2).sum();
    }
    out.responsible = static_cast<int64_t>(resp.size());
  }
  out.total = coord + object + noobject + cls;
  out.coord = coord.item<double>();
  out.object = object.item<double>();
  out.noobject = noobject.item<double>();
  out.cls = cls.item<double>();
  return out;
}

namespace {

/// GIoU, DIoU or CIoU (`kind`) of boxes (x, y, w, h: centre and size) against truths (tx, ty, tw, th), elementwise;
/// differentiable through the boxes (CIoU's alpha held constant, as in its paper and Darknet).
at::Tensor iou_family(const at::Tensor& x, const at::Tensor& y, const at::Tensor& w, const at::Tensor& h,
                      const at::Tensor& tx, const at::Tensor& ty, const at::Tensor& tw, const at::Tensor& th,
                      const std::string& kind) {
  constexpr double kEps = 1e-9;
  const at::Tensor ax0 = x - w / 2, ax1 = x + w / 2, ay0 = y - h / 2, ay1 = y + h / 2;
  const at::Tensor bx0 = tx - tw / 2, bx1 = tx + tw / 2, by0 = ty - th / 2, by1 = ty + th / 2;
  const at::Tensor iw = (at::minimum(ax1, bx1) - at::maximum(ax0, bx0)).clamp_min(0.0);
  const at::Tensor ih = (at::minimum(ay1, by1) - at::maximum(ay0, by0)).clamp_min(0.0);
  const at::Tensor inter = iw * ih;
  const at::Tensor uni = w * h + tw * th - inter;
  const at::Tensor iou = inter / (uni + kEps);
  const at::Tensor cw = at::maximum(ax1, bx1) - at::minimum(ax0, bx0);
  const at::Tensor ch = at::maximum(ay1, by1) - at::minimum(ay0, by0);
  if (kind == "giou") return iou - (cw * ch - uni) / (cw * ch + kEps);
  const at::Tensor diou = iou - ((x - tx).pow(2) + (y - ty).pow(2)) / (cw.pow(2) + ch.pow(2) + kEps);
  if (kind == "diou") return diou;
  if (kind != "ciou") throw std::invalid_argument("iou_family: kind '" + kind + "': expected giou, diou or ciou");
  const double k = 4.0 / (M_PI * M_PI);
  const at::Tensor v = k * (at::atan(tw / (th + kEps)) - at::atan(w / (h + kEps))).pow(2);
  const at::Tensor alpha = (v / (1.0 - iou + v + kEps)).detach();
  return diou - alpha * v;
}

}  // namespace

LossTerms yolo_loss(const at::Tensor& raw, const detector::Layer& yolo, int net_w, int net_h,
                    const std::vector<std::vector<LabeledBox>>& truths) {
  const HeadView v = split_head(raw, yolo, truths.size());
  const int64_t total_anchors = static_cast<int64_t>(yolo.anchors.size() / 2);
  std::vector<float> aw(static_cast<size_t>(v.a)), ah(static_cast<size_t>(v.a));
  for (int64_t a = 0; a < v.a; ++a) {
    aw[a] = yolo.anchors[2 * yolo.mask[a]] / static_cast<float>(net_w);  // pixels -> image fractions
    ah[a] = yolo.anchors[2 * yolo.mask[a] + 1] / static_cast<float>(net_h);
  }
  const at::Tensor anchor_w = at::tensor(aw), anchor_h = at::tensor(ah);
  const double s = yolo.scale_x_y;
  const at::Tensor pred = predicted_boxes(v, anchor_w, anchor_h, s);
  const at::Tensor ignore = ignore_mask(pred, truths, yolo.ignore_thresh);

  std::vector<Assignment> all;
  for (size_t n = 0; n < truths.size(); ++n)
    for (const LabeledBox& t : truths[n]) {
      int64_t best = 0;
      double best_iou = -1.0;
      for (int64_t k = 0; k < total_anchors; ++k) {
        const double iou = shape_iou(t.w, t.h, yolo.anchors[2 * k] / net_w, yolo.anchors[2 * k + 1] / net_h);
        if (iou > best_iou) best_iou = iou, best = k;
      }
      const auto it = std::find(yolo.mask.begin(), yolo.mask.end(), static_cast<int>(best));
      if (it == yolo.mask.end()) continue;  // another head's anchor
      all.push_back({static_cast<int64_t>(n), static_cast<int64_t>(it - yolo.mask.begin()), cell_of(t.cy, v.h),
                     cell_of(t.cx, v.w), t});
    }
  const std::vector<Assignment> resp = unique_slots(all);

  at::Tensor noobj = at::logical_not(ignore).to(at::kFloat);
  for (const Assignment& r : resp) noobj[r.n][r.a][r.row][r.col] = 0.0f;
  LossTerms out;
  // BCE(t, 0) = softplus(t); BCE(t, 1) = softplus(-t).
  const at::Tensor noobject = (noobj * at::softplus(v.to)).sum();
  at::Tensor coord = at::zeros({}, raw.options());
  at::Tensor object = at::zeros({}, raw.options());
  at::Tensor cls = at::zeros({}, raw.options());
  if (!resp.empty()) {
    std::vector<int64_t> in, ia, ir, ic, klass;
    std::vector<float> xt, yt, twt, tht, scale;
    for (const Assignment& r : resp) {
      in.push_back(r.n), ia.push_back(r.a), ir.push_back(r.row), ic.push_back(r.col);
      xt.push_back(r.truth.cx * v.w - r.col);
      yt.push_back(r.truth.cy * v.h - r.row);
      twt.push_back(std::log(r.truth.w / aw[r.a]));
      tht.push_back(std::log(r.truth.h / ah[r.a]));
      scale.push_back(2.0f - r.truth.w * r.truth.h);
      klass.push_back(r.truth.cls);
      const at::Tensor p = pred[r.n][r.a][r.row][r.col];
      out.iou_sum += box_iou(p[0].item<float>(), p[1].item<float>(), p[2].item<float>(), p[3].item<float>(), r.truth);
    }
    const at::Tensor N = at::tensor(in), A = at::tensor(ia), R = at::tensor(ir), C = at::tensor(ic);
    auto at_resp = [&](const at::Tensor& t) { return t.index({N, A, R, C}); };
    const at::Tensor x = s * at::sigmoid(at_resp(v.tx)) - 0.5 * (s - 1.0);
    const at::Tensor y = s * at::sigmoid(at_resp(v.ty)) - 0.5 * (s - 1.0);
    if (yolo.iou_loss == "mse") {
      coord =
          (at::tensor(scale) * ((x - at::tensor(xt)).pow(2) + (y - at::tensor(yt)).pow(2) +
                                (at_resp(v.tw) - at::tensor(twt)).pow(2) + (at_resp(v.th) - at::tensor(tht)).pow(2)))
              .sum();
    } else {
      std::vector<float> colv, rowv, tcx, tcy, tw, th;
      for (const Assignment& r : resp) {
        colv.push_back(static_cast<float>(r.col)), rowv.push_back(static_cast<float>(r.row));
        tcx.push_back(r.truth.cx), tcy.push_back(r.truth.cy), tw.push_back(r.truth.w), th.push_back(r.truth.h);
      }
      const at::Tensor bx = (x + at::tensor(colv)) / static_cast<double>(v.w);
      const at::Tensor by = (y + at::tensor(rowv)) / static_cast<double>(v.h);
      const at::Tensor bw = anchor_w.index({A}) * at::exp(at_resp(v.tw).clamp(-10.0, 10.0));
      const at::Tensor bh = anchor_h.index({A}) * at::exp(at_resp(v.th).clamp(-10.0, 10.0));
      const at::Tensor l =
          iou_family(bx, by, bw, bh, at::tensor(tcx), at::tensor(tcy), at::tensor(tw), at::tensor(th), yolo.iou_loss);
      coord = static_cast<double>(yolo.iou_normalizer) * (1.0 - l).sum();
    }
    object = at::softplus(-at_resp(v.to)).sum();
    if (v.k > 0) {
      const at::Tensor logits = v.cls.permute({0, 1, 3, 4, 2}).index({N, A, R, C});
      const at::Tensor onehot = at::one_hot(at::tensor(klass), v.k).to(at::kFloat);
      cls = at::binary_cross_entropy_with_logits(logits, onehot, {}, {}, at::Reduction::Sum);
    }
    out.responsible = static_cast<int64_t>(resp.size());
  }
  out.total = coord + object + noobject + cls;
  out.coord = coord.item<double>();
  out.object = object.item<double>();
  out.noobject = noobject.item<double>();
  out.cls = cls.item<double>();
  return out;
}

}  // namespace wingman::training
