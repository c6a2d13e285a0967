// SPDX-License-Identifier: MIT
// The [region] loss (eq. 13) and the [yolo] loss on tiny cases computed by hand, their gradients, and the anchor
// assignment and ignore rules.
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/training/detection_loss.hpp>

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <cmath>
#include <string>

namespace wingman::training {
namespace {

double sig(double x) { return 1.0 / (1.0 + std::exp(-x)); }
double softplus(double x) { return std::log1p(std::exp(x)); }

/// IoU of two (cx, cy, w, h) boxes, written out plainly.
double plain_iou(double ax, double ay, double aw, double ah, double bx, double by, double bw, double bh) {
  const double iw = std::max(0.0, std::min(ax + aw / 2, bx + bw / 2) - std::max(ax - aw / 2, bx - bw / 2));
  const double ih = std::max(0.0, std::min(ay + ah / 2, by + bh / 2) - std::max(ay - ah / 2, by - bh / 2));
  return iw * ih / (aw * ah + bw * bh - iw * ih);
}

/// A 2 x 2 grid [region] with two anchors (1 x 1 and 2 x 0.5 cells), one class, the thesis's weights.
detector::Layer region_layer(const char* thresh) {
  const detector::DarknetModel m = detector::parse_darknet_cfg_string(
      std::string("[net]\nwidth=2\nheight=2\nchannels=3\n[convolutional]\nfilters=12\nsize=1\nactivation=linear\n"
                  "[region]\nanchors=1,1, 2,0.5\nclasses=1\nnum=2\ncoords=4\nsoftmax=1\nobject_scale=5\n"
                  "noobject_scale=1\ncoord_scale=1\nclass_scale=1\nrescore=1\nthresh=") +
          thresh + "\n",
      "region.cfg");
  return m.layers[1];
}

// Raw tensor 1 x 12 x 2 x 2 (channel a * 6 + k): zero but for the responsible anchor 0 at row 1, col 0 and
// the objectness of anchor 1 at row 0, col 1.
torch::Tensor region_raw() {
  torch::Tensor raw = torch::zeros({1, 12, 2, 2});
  const float resp[5] = {0.5f, -0.3f, -0.2f, 0.1f, 0.4f};  // t_x, t_y, t_w, t_h, t_o
  for (int k = 0; k < 5; ++k) raw[0][k][1][0] = resp[k];
  raw[0][6 + 4][0][1] = 1.0f;
  return raw.requires_grad_(true);
}

// The truth: centre (0.3, 0.7), size 0.4 x 0.45 -> cell (col 0, row 1), offsets x_t = 0.6, y_t = 0.4.
// Anchor shapes as image fractions: 0.5 x 0.5 (IoU with the truth 0.18 / 0.25 = 0.72) and 1 x 0.25
// (0.1 / 0.33 = 0.30): anchor 0 is responsible.
const std::vector<std::vector<LabeledBox>> kRegionTruth = {{{0, 0.3f, 0.7f, 0.4f, 0.45f}}};

struct RegionHand {
  double coord, iou, object;
};

RegionHand region_by_hand() {
  const double x = sig(0.5), y = sig(-0.3), w = 0.5 * std::exp(-0.2), h = 0.5 * std::exp(0.1);
  RegionHand r;
  r.coord = std::pow(x - 0.6, 2) + std::pow(y - 0.4, 2) + std::pow(std::sqrt(w) - std::sqrt(0.4), 2) +
            std::pow(std::sqrt(h) - std::sqrt(0.45), 2);
  r.iou = plain_iou((x + 0) / 2, (y + 1) / 2, w, h, 0.3, 0.7, 0.4, 0.45);
  r.object = 5 * std::pow(sig(0.4) - r.iou, 2);  // rescore: the target is the IoU
  return r;
}

TEST(RegionLoss, HandComputedTinyCase) {
  const detector::Layer region = region_layer(".6");
  torch::Tensor raw = region_raw();
  const LossTerms t = region_loss(raw, region, kRegionTruth);
  const RegionHand hand = region_by_hand();
  // No other prediction overlaps the truth by more than 0.6 (the largest: anchor 1 at the truth's cell, 0.30),
  // so the no-object term has the 7 others: six at sigma(0)^2 and one at sigma(1)^2.
  const double noobject = 6 * 0.25 + sig(1.0) * sig(1.0);
  EXPECT_NEAR(t.coord, hand.coord, 1e-6);
  EXPECT_NEAR(t.object, hand.object, 1e-6);
  EXPECT_NEAR(t.noobject, noobject, 1e-6);
  EXPECT_NEAR(t.cls, 0.0, 1e-12);  // one class: the softmax is 1
  EXPECT_NEAR(t.total.item<double>(), hand.coord + hand.object + noobject, 1e-5);
  EXPECT_EQ(t.responsible, 1);
  EXPECT_NEAR(t.iou_sum, hand.iou, 1e-6);

  // Gradients: the confidence target (the IoU) carries none.
  t.total.backward();
  const torch::Tensor g = raw.grad();
  const double s04 = sig(0.4);
  EXPECT_NEAR(g[0][4][1][0].item<double>(), 5 * 2 * (s04 - hand.iou) * s04 * (1 - s04), 1e-5);
  EXPECT_NEAR(g[0][10][0][1].item<double>(), 2 * sig(1.0) * sig(1.0) * (1 - sig(1.0)), 1e-6);
  EXPECT_NEAR(g[0][0][1][0].item<double>(), 2 * (sig(0.5) - 0.6) * sig(0.5) * (1 - sig(0.5)), 1e-6);
  // d/dt_w (sqrt(0.5 e^{t_w}) - sqrt(0.4))^2 = (sqrt(w) - sqrt(0.4)) sqrt(w)
  const double sw = std::sqrt(0.5 * std::exp(-0.2));
  EXPECT_NEAR(g[0][2][1][0].item<double>(), (sw - std::sqrt(0.4)) * sw, 1e-6);
  EXPECT_EQ(g[0][6].abs().sum().item<double>(), 0.0);  // anchor 1's t_x: not responsible anywhere
}

TEST(RegionLoss, PredictionsOverlappingATruthAreIgnoredInTheNoObjectTerm) {
  const detector::Layer region = region_layer(".25");  // anchor 1 at the truth's cell overlaps by 0.30
  const LossTerms t = region_loss(region_raw(), region, kRegionTruth);
  EXPECT_NEAR(t.noobject, 5 * 0.25 + sig(1.0) * sig(1.0), 1e-6);
  EXPECT_NEAR(t.object, region_by_hand().object, 1e-6);
}

TEST(RegionLoss, TheBestShapedAnchorIsResponsible) {
  const detector::Layer region = region_layer(".6");
  torch::Tensor raw = torch::zeros({2, 12, 2, 2}).requires_grad_(true);
  // Image 0: a wide box (0.9 x 0.2) -> anchor 1 (1 x 0.25); image 1: nothing.
  const LossTerms t = region_loss(raw, region, {{{0, 0.7f, 0.2f, 0.9f, 0.2f}}, {}});
  EXPECT_EQ(t.responsible, 1);
  t.total.backward();
  const torch::Tensor g = raw.grad();
  EXPECT_NE(g[0][6][0][1].item<double>(), 0.0);  // anchor 1's t_x at col 1, row 0
  EXPECT_EQ(g[0][0].abs().sum().item<double>(), 0.0);
  EXPECT_EQ(g[1].slice(0, 0, 4).abs().sum().item<double>(), 0.0);  // image 1: only objectness is pushed down
  EXPECT_GT(g[1][4].abs().sum().item<double>(), 0.0);
  EXPECT_THROW(region_loss(raw, region, {{}}), std::invalid_argument);  // 2 images, 1 truth list
}

/// A 2 x 2 grid [yolo] head of an 8 x 8 network using anchor 1 (6 x 3 px) of {2 x 2, 6 x 3}.
detector::Layer yolo_layer(const char* ignore) {
  const detector::DarknetModel m = detector::parse_darknet_cfg_string(
      std::string("[net]\nwidth=8\nheight=8\nchannels=3\n[convolutional]\nfilters=6\nsize=1\nstride=4\n"
                  "activation=linear\n[yolo]\nmask=1\nanchors=2,2, 6,3\nclasses=1\nnum=2\nignore_thresh=") +
          ignore + "\n",
      "yolo.cfg");
  return m.layers[1];
}

TEST(YoloLoss, HandComputedTinyCase) {
  const detector::Layer yolo = yolo_layer(".5");
  torch::Tensor raw = torch::zeros({1, 6, 2, 2});
  const float resp[5] = {0.2f, -0.1f, 0.3f, -0.2f, 0.5f};  // t_x, t_y, t_w, t_h, t_o at row 0, col 1
  for (int k = 0; k < 5; ++k) raw[0][k][0][1] = resp[k];
  raw.requires_grad_(true);
  // Truth 1: 2 x 2 px -> anchor 0, another head's: nothing here. Truth 2: 6 x 3 px -> anchor 1 (this head),
  // centre (0.6, 0.2) -> col 1, row 0, x_t = 0.2, y_t = 0.4, t_w = log(6 / 6) = 0, t_h = log(3 / 3) = 0,
  // weight 2 - 0.75 * 0.375 = 1.71875.
  const std::vector<std::vector<LabeledBox>> truths = {{{0, 0.3f, 0.7f, 0.25f, 0.25f}, {0, 0.6f, 0.2f, 0.75f, 0.375f}}};
  const LossTerms t = yolo_loss(raw, yolo, 8, 8, truths);
  const double coord = 1.71875 * (std::pow(sig(0.2) - 0.2, 2) + std::pow(sig(-0.1) - 0.4, 2) + 0.3 * 0.3 + 0.2 * 0.2);
  // The three other cells predict 6 x 3 px boxes; the largest IoU with a truth is 0.30 (< 0.5): all three in
  // the no-object term, BCE(0, 0) = log 2 each. One class: BCE(0, 1) = log 2.
  EXPECT_EQ(t.responsible, 1);
  EXPECT_NEAR(t.coord, coord, 1e-6);
  EXPECT_NEAR(t.object, softplus(-0.5), 1e-6);
  EXPECT_NEAR(t.noobject, 3 * std::log(2.0), 1e-6);
  EXPECT_NEAR(t.cls, std::log(2.0), 1e-6);
  EXPECT_NEAR(t.total.item<double>(), coord + softplus(-0.5) + 4 * std::log(2.0), 1e-5);
  t.total.backward();
  // d BCE(t_o, 1) / d t_o = sigma(t_o) - 1
  EXPECT_NEAR(raw.grad()[0][4][0][1].item<double>(), sig(0.5) - 1.0, 1e-6);
  EXPECT_NEAR(raw.grad()[0][2][0][1].item<double>(), 1.71875 * 2 * 0.3, 1e-5);

  // With ignore_thresh 0.25 the cell at (col 0, row 0) (IoU 0.30 with truth 2) leaves the no-object term.
  const LossTerms ignored = yolo_loss(raw, yolo_layer(".25"), 8, 8, truths);
  EXPECT_NEAR(ignored.noobject, 2 * std::log(2.0), 1e-6);
}

/// The same head with iou_loss = `kind` and iou_normalizer 0.5.
detector::Layer yolo_iou_layer(const std::string& kind) {
  const detector::DarknetModel m = detector::parse_darknet_cfg_string(
      "[net]\nwidth=8\nheight=8\nchannels=3\n[convolutional]\nfilters=6\nsize=1\nstride=4\n"
      "activation=linear\n[yolo]\nmask=1\nanchors=2,2, 6,3\nclasses=1\nnum=2\nignore_thresh=.5\niou_loss=" +
          kind + "\niou_normalizer=0.5\n",
      "yolo-iou.cfg");
  return m.layers[1];
}

/// GIoU, DIoU and CIoU of two (cx, cy, w, h) boxes, written out plainly.
double plain_iou_family(const std::string& kind, double ax, double ay, double aw, double ah, double bx, double by,
                        double bw, double bh) {
  const double iou = plain_iou(ax, ay, aw, ah, bx, by, bw, bh);
  const double left = std::min(ax - aw / 2, bx - bw / 2), right = std::max(ax + aw / 2, bx + bw / 2);
  const double top = std::min(ay - ah / 2, by - bh / 2), bottom = std::max(ay + ah / 2, by + bh / 2);
  const double cw = right - left, ch = bottom - top;
  const double inter = iou * (aw * ah + bw * bh) / (1 + iou);  // from iou = I / (A + B - I)
  const double uni = aw * ah + bw * bh - inter;
  if (kind == "giou") return iou - (cw * ch - uni) / (cw * ch);
  const double diou = iou - ((ax - bx) * (ax - bx) + (ay - by) * (ay - by)) / (cw * cw + ch * ch);
  if (kind == "diou") return diou;
  const double v = 4 / (M_PI * M_PI) * std::pow(std::atan(bw / bh) - std::atan(aw / ah), 2);
  return diou - v / (1 - iou + v) * v;
}

TEST(YoloLoss, IouLossesComputedByHandAndTheirGradients) {
  // The tiny case above: the responsible prediction at col 1, row 0 of the 2 x 2 grid; anchor 1 is 6 x 3 px of the
  // 8 x 8 input (0.75 x 0.375); truth 2 is (0.6, 0.2, 0.75, 0.375).
  const float resp[5] = {0.2f, -0.1f, 0.3f, -0.2f, 0.5f};
  const std::vector<std::vector<LabeledBox>> truths = {{{0, 0.3f, 0.7f, 0.25f, 0.25f}, {0, 0.6f, 0.2f, 0.75f, 0.375f}}};
  auto make_raw = [&](int channel, float delta) {
    torch::Tensor raw = torch::zeros({1, 6, 2, 2});
    for (int k = 0; k < 5; ++k) raw[0][k][0][1] = resp[k] + (k == channel ? delta : 0.0f);
    return raw.requires_grad_(true);
  };
  const double bx = (1 + sig(0.2)) / 2, by = (0 + sig(-0.1)) / 2, bw = 0.75 * std::exp(0.3),
               bh = 0.375 * std::exp(-0.2);
  const LossTerms mse = yolo_loss(make_raw(-1, 0), yolo_layer(".5"), 8, 8, truths);
  for (const std::string kind : {"giou", "diou", "ciou"}) {
    SCOPED_TRACE(kind);
    const detector::Layer yolo = yolo_iou_layer(kind);
    torch::Tensor raw = make_raw(-1, 0);
    const LossTerms t = yolo_loss(raw, yolo, 8, 8, truths);
    const double by_hand = 0.5 * (1 - plain_iou_family(kind, bx, by, bw, bh, 0.6, 0.2, 0.75, 0.375));
    EXPECT_EQ(t.responsible, 1);
    EXPECT_NEAR(t.coord, by_hand, 1e-6);
    // The other terms are the squared-error loss's.
    EXPECT_NEAR(t.object, mse.object, 1e-9);
    EXPECT_NEAR(t.noobject, mse.noobject, 1e-9);
    EXPECT_NEAR(t.cls, mse.cls, 1e-9);
    EXPECT_NEAR(t.iou_sum, mse.iou_sum, 1e-9);
    t.total.backward();
    const torch::Tensor g = raw.grad();
    // Central differences of the box term in t_x .. t_h (CIoU's alpha is held constant by the gradient, so
    // there the difference only bounds it).
    for (int c = 0; c < 4; ++c) {
      const double eps = 1e-3;
      const double up = yolo_loss(make_raw(c, eps), yolo, 8, 8, truths).coord;
      const double down = yolo_loss(make_raw(c, -eps), yolo, 8, 8, truths).coord;
      const double numeric = (up - down) / (2 * eps), analytic = g[0][c][0][1].item<double>();
      if (kind == "ciou")
        EXPECT_NEAR(analytic, numeric, 0.05 * std::abs(numeric) + 1e-3) << "channel " << c;
      else
        EXPECT_NEAR(analytic, numeric, 1e-3) << "channel " << c;
    }
    // A gradient step on the box moves the prediction towards the truth: the term falls.
    torch::Tensor stepped = make_raw(-1, 0).detach();
    for (int c = 0; c < 4; ++c) stepped[0][c][0][1] -= 0.5 * g[0][c][0][1];
    stepped.requires_grad_(true);
    EXPECT_LT(yolo_loss(stepped, yolo, 8, 8, truths).coord, t.coord);
  }
  // A perfect box: every variant's box term is 0.
  torch::Tensor perfect = torch::zeros({1, 6, 2, 2});
  // x offset 0.2 in the cell = sigma(t_x) -> t_x = logit(0.2); y offset 0.4; t_w = t_h = 0 (the anchor's shape).
  perfect[0][0][0][1] = std::log(0.2 / 0.8);
  perfect[0][1][0][1] = std::log(0.4 / 0.6);
  for (const std::string kind : {"giou", "diou", "ciou"})
    EXPECT_NEAR(yolo_loss(perfect, yolo_iou_layer(kind), 8, 8, truths).coord, 0.0, 1e-6) << kind;
}

}  // namespace
}  // namespace wingman::training
