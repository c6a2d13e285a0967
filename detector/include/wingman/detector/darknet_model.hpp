// SPDX-License-Identifier: MIT
// A Darknet network in memory: the layers of a .cfg with their shapes and (after loading) weights.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace wingman::detector {

/// Layer kinds the detector supports (Darknet section names in brackets).
enum class LayerType {
  kConvolutional,  ///< [convolutional]
  kMaxpool,        ///< [maxpool]
  kRegion,         ///< [region] (YOLOv2 head)
  kRoute,          ///< [route]
  kUpsample,       ///< [upsample]
  kYolo,           ///< [yolo] (YOLOv3 head)
};

enum class Activation { kLinear, kLeaky, kLogistic };

/// A tensor shape, channels-first: C x H x W (batch is separate).
struct Shape {
  int c = 0;
  int h = 0;
  int w = 0;
  int64_t size() const { return static_cast<int64_t>(c) * h * w; }
  bool operator==(const Shape& o) const { return c == o.c && h == o.h && w == o.w; }
};

/// One layer of the network, with its parameters as Darknet computes them.
struct Layer {
  LayerType type = LayerType::kConvolutional;
  int cfg_line = 0;  ///< line of the section header in the .cfg (for messages)
  Shape input;       ///< shape of the layer's input (for route: of its output)
  Shape output;      ///< shape of the layer's output

  // [convolutional]
  int filters = 0;
  int size = 1;  ///< kernel size (square)
  int stride = 1;
  int padding = 0;  ///< pixels of zero padding on each side (pad=1 means size/2)
  bool batch_normalize = false;
  Activation activation = Activation::kLinear;
  // Weights as stored in a .weights file (float32). With batch_normalize: biases = beta,
  // scales = gamma, rolling_mean, rolling_variance; without: biases only. weights: OIHW.
  std::vector<float> biases, scales, rolling_mean, rolling_variance, weights;

  // [maxpool]: output = (input + padding - size) / stride + 1, padding defaults to size - 1
  // (Darknet pads the right/bottom edge, so size 2 stride 1 keeps the spatial size).
  int pool_size = 2;
  int pool_stride = 2;
  int pool_padding = 1;

  // [route]: absolute indices of the layers whose outputs are concatenated along channels.
  std::vector<int> route_layers;
  // [upsample]: nearest-neighbour factor.
  int upsample_stride = 2;

  // [region] / [yolo]
  std::vector<float> anchors;  ///< all anchors (w, h pairs): grid cells for [region], pixels for [yolo]
  std::vector<int> mask;       ///< [yolo]: which anchors this head uses
  int classes = 1;
  int num = 5;             ///< anchors per cell ([region]: num; [yolo]: mask size)
  float scale_x_y = 1.0f;  ///< [yolo]: b_x = (sigma(t_x) * s - (s - 1) / 2 + c_x) / W (1: YOLOv3)

  // [region] / [yolo] training-only keys, at Darknet's defaults. Inference ignores them; they are kept so
  // that a written .cfg trains like the one read (write_darknet_cfg writes them all).
  float object_scale = 1.0f;    ///< [region] loss weight of objectness where an object is
  float noobject_scale = 1.0f;  ///< [region] loss weight of objectness where none is
  float class_scale = 1.0f;     ///< [region] loss weight of the class probabilities
  float coord_scale = 1.0f;     ///< [region] loss weight of the box coordinates
  int rescore = 0;              ///< [region] 1: objectness target is the IoU with the truth, 0: 1
  int bias_match = 0;           ///< [region] 1: match truths to anchors by shape only
  int absolute = 0;             ///< [region] Darknet's `absolute` switch (kept verbatim)
  float thresh = 0.5f;          ///< [region] IoU above which a prediction is not pushed to "no object"
  float ignore_thresh = 0.5f;   ///< [yolo] IoU above which a prediction is not pushed to "no object"
  float truth_thresh = 1.0f;    ///< [yolo] IoU above which a prediction also learns that truth
  float jitter = 0.2f;          ///< [region]/[yolo] random crop augmentation, fraction of the image
  float random = 0.0f;          ///< [region]/[yolo] != 0: multi-scale training (Darknet resizes the network)
  /// [yolo] box term of the loss (AlexeyAB Darknet's key): "mse" (YOLOv3's squared error on the offsets, the
  /// default), "giou", "diou" or "ciou" (iou_normalizer * (1 - that IoU) of the predicted box with the truth).
  std::string iou_loss = "mse";
  float iou_normalizer = 0.75f;  ///< [yolo] weight of the giou/diou/ciou box term (AlexeyAB Darknet's default)
};

/// The [net] section: input size and the training settings (kept for the trainer).
struct NetParams {
  int width = 416;
  int height = 416;
  int channels = 3;
  std::map<std::string, std::string> other;  ///< every other [net] key as written (batch, learning_rate, ...)
};

/// A whole network. Shapes are computed when the .cfg is parsed; weights are empty until loaded.
struct DarknetModel {
  NetParams net;
  std::vector<Layer> layers;
  std::string cfg_path;  ///< for messages
  // .weights header
  int32_t major = 0;
  int32_t minor = 2;
  int32_t revision = 0;
  uint64_t seen = 0;  ///< images seen in training (uint64 when major*10+minor >= 2, else uint32)

  /// Number of float32 values a .weights file must hold after its header.
  int64_t weight_count() const;
  /// Indices of the [region] and [yolo] layers (the detection heads), in cfg order.
  std::vector<int> heads() const;
  /// Multiply-adds x 2 of one forward pass at the net's input size (convolutions only), FLOP.
  double flops() const;
};

}  // namespace wingman::detector
