// SPDX-License-Identifier: MIT
// Darknet .cfg files: parse into a DarknetModel (with Darknet's shape arithmetic) and write back.
#pragma once

#include "wingman/detector/darknet_model.hpp"

#include <stdexcept>
#include <string>

namespace wingman::detector {

/// A malformed or unsupported .cfg or .weights file. what() is one line naming the file, and where it
/// applies the line, the key, and the expected vs actual value or size.
class DarknetFormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads a Darknet .cfg file and computes every layer's input and output shape as Darknet does.
///
/// Supported sections and keys (anything else is a DarknetFormatError naming file, line and key):
/// - [net]/[network]: width, height, channels; the training keys (batch, subdivisions, momentum, decay,
///   learning_rate, burn_in, max_batches, policy, steps, scales, hue, saturation, exposure, jitter, angle, ...)
///   are kept verbatim in NetParams::other.
/// - [convolutional]: batch_normalize, filters, size, stride, pad (1 = size/2), padding, activation
///   (leaky, linear, logistic).
/// - [maxpool]: size, stride, padding (default size - 1: Darknet pads right/bottom, so size 2 stride 1
///   keeps the spatial size).
/// - [region]: anchors, classes, num, coords (must be 4), softmax, and the training-only keys object_scale,
///   noobject_scale, class_scale, coord_scale, rescore, bias_match, absolute, thresh, jitter, random (kept
///   on the Layer, written back by write_darknet_cfg).
/// - [route]: layers (relative negative or absolute indices); [upsample]: stride;
///   [yolo]: mask, anchors, classes, num, scale_x_y (>= 1), and the training-only keys ignore_thresh,
///   truth_thresh, jitter, random (kept and written back).
/// Throws DarknetFormatError if the file cannot be read, on an unknown section or key, a bad value, or
/// inconsistent shapes (e.g. a [region] whose input channels are not num * (5 + classes)).
DarknetModel parse_darknet_cfg(const std::string& path);

/// Same as parse_darknet_cfg, from the text of a .cfg; `source_name` stands for the file name in messages
/// and becomes DarknetModel::cfg_path.
DarknetModel parse_darknet_cfg_string(const std::string& cfg_text, const std::string& source_name = "<cfg>");

/// Recomputes every layer's input and output shape from net.{channels,height,width} and the layer
/// parameters (Darknet's arithmetic). Called by the parsers; call it after editing a model in memory.
/// Throws DarknetFormatError naming the layer's cfg line on impossible shapes.
void compute_shapes(DarknetModel& model);

/// The .cfg text of a model; parse_darknet_cfg_string(write_darknet_cfg(m)) gives the same layers, shapes
/// and net parameters (route layers are written as absolute indices; weights are not part of a .cfg).
std::string write_darknet_cfg(const DarknetModel& model);

/// Darknet section name of a layer type ("convolutional", "maxpool", ...).
const char* layer_type_name(LayerType type);
/// Darknet name of an activation ("linear", "leaky", "logistic").
const char* activation_name(Activation activation);

}  // namespace wingman::detector
