// SPDX-License-Identifier: MIT
// A Darknet network (.cfg) as a libtorch module, with its weights read from and written to a DarknetModel.
//
// This header includes libtorch: include it only from the trainer's own sources and tests, never from a
// header that other modules include (a libtorch translation unit costs ~1 GB and ~30 s to compile).
#pragma once

#include <wingman/detector/darknet_model.hpp>

#include <torch/nn/module.h>
#include <torch/nn/modules/batchnorm.h>
#include <torch/nn/modules/conv.h>
#include <torch/nn/pimpl.h>

#include <vector>

namespace wingman::training {

/// Darknet's batch-normalization epsilon as the detector's backends use it: gamma / sqrt(var + eps)
/// (OpenCV's Darknet importer and the OpenCL backend), so a trained network runs the same everywhere.
constexpr double kBatchNormEpsilon = 1e-6;
/// Darknet's rolling-statistics update: rolling = 0.99 rolling + 0.01 batch (torch's momentum 0.01). During the
/// first 100 batches the factor is 1 / (batches so far) instead (the exact mean), so that short runs also get
/// usable statistics.
constexpr double kBatchNormMomentum = 0.01;
/// Slope of Darknet's leaky activation for x < 0.
constexpr double kLeakySlope = 0.1;
/// Initial weights of a (linear, bias) convolution that feeds a head: N(0, kHeadWeightStd^2), biases 0 except
/// objectness, whose bias is logit(kHeadObjectnessPrior).
constexpr double kHeadWeightStd = 0.01;
constexpr double kHeadObjectnessPrior = 0.01;

/// The network of a Darknet .cfg, layer by layer as the detector computes it:
///  - [convolutional]: Conv2d (bias only without batch_normalize) + BatchNorm2d (eps kBatchNormEpsilon,
///    momentum max(kBatchNormMomentum, 1 / batches so far)) + leaky (0.1) / linear / logistic;
///  - [maxpool]: Darknet's padding: -inf padding of padding/2 on the left/top, the rest on the right/bottom,
///    output (in + padding - size) / stride + 1, so size 2 stride 1 keeps the size;
///  - [route]: concatenation along channels; [upsample]: nearest neighbour;
///  - [region] / [yolo]: no computation; forward() returns their input (the raw head tensor).
/// The module is in training mode after construction (batch statistics); call eval() for inference.
class DarknetNetImpl : public torch::nn::Module {
 public:
  /// Builds the layers from `model`'s shapes (its weights, if any, are ignored: see load_weights()).
  /// Parameters start with libtorch's default initialisation (seed it with torch::manual_seed()), except the
  /// convolution right before each head: small weights and a low objectness bias (kHeadWeightStd,
  /// kHeadObjectnessPrior), so that training starts from the anchors.
  /// Throws std::invalid_argument if the model has no layers.
  explicit DarknetNetImpl(const detector::DarknetModel& model);

  /// Runs the network on `input` (N x net.channels x net.height x net.width, float32).
  /// Returns, for each [region] / [yolo] layer in order, the tensor it takes (N x num*(5+classes) x H x W,
  /// raw: no sigmoid or exp applied); for a network without a head, the last layer's output.
  std::vector<torch::Tensor> forward(const torch::Tensor& input);

  /// Copies the weights of `model`'s convolutional layers (loaded with detector::load_darknet_weights or
  /// randomized) into the module; with `conv_layers` >= 0 only the first that many (the rest keep theirs: a
  /// detector::load_darknet_weights_prefix file). Throws std::invalid_argument naming the layer when a weight vector
  /// does not have its .cfg size or the model's layers differ from the ones this module was built from.
  void load_weights(const detector::DarknetModel& model, int conv_layers = -1);

  /// Writes the module's weights into `model`'s convolutional layers (biases or beta, gamma, rolling mean,
  /// rolling variance, OIHW weights), ready for detector::save_darknet_weights. `model` must have the
  /// layers this module was built from (std::invalid_argument otherwise).
  void store_weights(detector::DarknetModel& model) const;

  /// The layers this module was built from (shapes; weight vectors empty).
  const detector::DarknetModel& model() const { return model_; }
  /// Indices of the [region] / [yolo] layers, in order (forward()'s outputs).
  const std::vector<int>& head_layers() const { return heads_; }
  /// The convolution kernels (the parameters Darknet applies weight decay to).
  std::vector<torch::Tensor> kernel_parameters() const;
  /// Every other parameter: convolution biases, batch-norm gamma and beta (no weight decay in Darknet).
  std::vector<torch::Tensor> other_parameters() const;

 private:
  detector::DarknetModel model_;
  std::vector<torch::nn::Conv2d> convs_;     // per layer; empty holder for non-convolutional layers
  std::vector<torch::nn::BatchNorm2d> bns_;  // per layer; empty holder without batch_normalize
  std::vector<int> heads_;
};
TORCH_MODULE(DarknetNet);

/// Sets every parameter and buffer of `average` to `current`'s. Both must be the same network (the same
/// parameters and buffers, in order, of the same shapes and types): std::invalid_argument naming the first mismatch.
void copy_weights(torch::nn::Module& average, const torch::nn::Module& current);

/// One step of a weight average (WeightAverageOptions, weight_average.hpp): average = d average + (1 - d) current
/// for every parameter and floating-point buffer (batch-norm's rolling mean and variance); integer buffers
/// (batch-norm's batch count) are copied. Records no gradient. Preconditions as copy_weights(); `d` in [0, 1]
/// (std::invalid_argument otherwise).
void update_weight_average(torch::nn::Module& average, const torch::nn::Module& current, double d);

}  // namespace wingman::training
