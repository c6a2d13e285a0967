// SPDX-License-Identifier: MIT
// Growing a trained detector's [yolo] heads to more classes.
#include "wingman/detector/class_widening.hpp"

#include "wingman/detector/darknet_cfg.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

namespace wingman::detector {

DarknetModel widen_classes(const DarknetModel& model, int classes, float new_class_bias) {
  if (classes < 1) throw std::invalid_argument(fmt::format("widen_classes: classes = {}: must be >= 1", classes));
  if (!std::isfinite(new_class_bias))
    throw std::invalid_argument(fmt::format("widen_classes: new_class_bias = {}: must be finite", new_class_bias));
  DarknetModel out = model;
  for (const int h : model.heads()) {
    const Layer& head = model.layers[static_cast<size_t>(h)];
    if (head.type != LayerType::kYolo)
      throw DarknetFormatError(fmt::format(
          "{}:{}: [{}]: only [yolo] heads can be widened (a [region] head's single-class logit is never trained)",
          model.cfg_path, head.cfg_line, layer_type_name(head.type)));
    if (classes < head.classes)
      throw DarknetFormatError(fmt::format("{}:{}: [yolo] has classes = {}; widening to {} would drop classes",
                                           model.cfg_path, head.cfg_line, head.classes, classes));
    if (h == 0 || model.layers[static_cast<size_t>(h - 1)].type != LayerType::kConvolutional)
      throw DarknetFormatError(
          fmt::format("{}:{}: [yolo] does not follow a [convolutional] layer", model.cfg_path, head.cfg_line));
    const Layer& conv = model.layers[static_cast<size_t>(h - 1)];
    const int num = static_cast<int>(head.mask.size());
    const int old_per = 5 + head.classes, new_per = 5 + classes;
    if (conv.batch_normalize || conv.filters != num * old_per)
      throw DarknetFormatError(fmt::format(
          "{}:{}: the [convolutional] before the [yolo] at line {} must have no batch_normalize and num x (5 + "
          "classes) = {} filters (it has {}{})",
          model.cfg_path, conv.cfg_line, head.cfg_line, num * old_per, conv.filters,
          conv.batch_normalize ? ", batch_normalize" : ""));
    for (size_t k = 0; k < model.layers.size(); ++k)
      for (const int r : model.layers[k].route_layers)
        if (r == h - 1)
          throw DarknetFormatError(
              fmt::format("{}:{}: the [route] at line {} reads the head's [convolutional] at "
                          "line {}: its channels cannot grow",
                          model.cfg_path, model.layers[k].cfg_line, model.layers[k].cfg_line, conv.cfg_line));
    const size_t row = static_cast<size_t>(conv.input.c) * conv.size * conv.size;  // weights per output channel
    if (conv.biases.size() != static_cast<size_t>(conv.filters) || conv.weights.size() != row * conv.filters)
      throw DarknetFormatError(fmt::format("{}:{}: the [convolutional] before the [yolo] has no weights loaded",
                                           model.cfg_path, conv.cfg_line));
    Layer& wide = out.layers[static_cast<size_t>(h - 1)];
    wide.filters = num * new_per;
    wide.biases.assign(static_cast<size_t>(wide.filters), new_class_bias);
    wide.weights.assign(row * wide.filters, 0.0f);
    for (int a = 0; a < num; ++a)
      for (int j = 0; j < old_per; ++j) {
        const size_t from = static_cast<size_t>(a * old_per + j), to = static_cast<size_t>(a * new_per + j);
        wide.biases[to] = conv.biases[from];
        std::copy(conv.weights.begin() + static_cast<std::ptrdiff_t>(from * row),
                  conv.weights.begin() + static_cast<std::ptrdiff_t>((from + 1) * row),
                  wide.weights.begin() + static_cast<std::ptrdiff_t>(to * row));
      }
    out.layers[static_cast<size_t>(h)].classes = classes;
  }
  compute_shapes(out);
  return out;
}

}  // namespace wingman::detector
