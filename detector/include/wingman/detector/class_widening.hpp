// SPDX-License-Identifier: MIT
// Growing a trained detector's heads to more classes, keeping everything it has learnt.
#pragma once

#include "wingman/detector/darknet_model.hpp"

namespace wingman::detector {

/// Logit of 0.01: a new class starts nearly absent (sigmoid(-4.595) = 0.01), so the widened network's drone boxes,
/// their confidence and their drone score are those of the network it came from until training says otherwise.
inline constexpr float kNewClassBias = -4.59512f;

/// A copy of `model` (a parsed .cfg with its weights loaded) whose [yolo] heads predict `classes` classes: each
/// head's `classes` is set and the [convolutional] layer right before it (which must feed that head only, without
/// batch_normalize, with num x (5 + old classes) filters) grows to num x (5 + classes) filters. For anchor a, output
/// channel a (5 + old) + j (j < 5 + old: t_x, t_y, t_w, t_h, t_o, the old classes) moves to a (5 + classes) + j with
/// its weights and bias unchanged; a new class's channel gets zero weights and bias `new_class_bias` (a logit).
/// Every other layer is copied as it is. The result computes the same raw values for the old channels, hence the
/// same boxes and drone scores as `model`, and the same class ids and confidences wherever an old class outscores
/// the new ones (a [yolo] head's classes are independent logistic outputs). A [region] head is refused: its softmax
/// makes a single class's logit meaningless (Darknet never trains it), so there is nothing to keep.
/// Preconditions: the weights are loaded; classes >= every head's current classes. Throws DarknetFormatError naming
/// the cfg line of the layer that breaks one (and std::invalid_argument for classes < 1 or a non-finite bias).
DarknetModel widen_classes(const DarknetModel& model, int classes, float new_class_bias = kNewClassBias);

}  // namespace wingman::detector
