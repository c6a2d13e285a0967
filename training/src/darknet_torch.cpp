// SPDX-License-Identifier: MIT
// DarknetNet: the layers of a Darknet .cfg in libtorch, and weight transfer to and from a DarknetModel.
#include "wingman/training/darknet_torch.hpp"

#include <wingman/detector/darknet_cfg.hpp>

#include <fmt/format.h>
#include <torch/nn/functional/activation.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace wingman::training {

using detector::Activation;
using detector::Layer;
using detector::LayerType;

namespace {

std::string where(const detector::DarknetModel& m, size_t i) {
  return fmt::format("{}:{}: [{}] (layer {})", m.cfg_path, m.layers[i].cfg_line,
                     detector::layer_type_name(m.layers[i].type), i);
}

/// Copies `n` floats from `src` into the (contiguous, float32) tensor `dst` without recording autograd.
void copy_into(torch::Tensor dst, const std::vector<float>& src, const std::string& what) {
  if (static_cast<int64_t>(src.size()) != dst.numel())
    throw std::invalid_argument(fmt::format("{}: {} values, expected {}", what, src.size(), dst.numel()));
  torch::NoGradGuard no_grad;
  const torch::Tensor from = torch::from_blob(const_cast<float*>(src.data()), dst.sizes(), torch::kFloat32);
  dst.copy_(from);
}

std::string shape_text(const torch::Tensor& t) {
  std::string s;
  for (int64_t d = 0; d < t.dim(); ++d) s += (d ? " x " : "") + std::to_string(t.size(d));
  return s.empty() ? "(scalar)" : s;
}

std::vector<float> copy_out(const torch::Tensor& t) {
  const torch::Tensor c = t.detach().to(torch::kFloat32).contiguous();
  std::vector<float> v(static_cast<size_t>(c.numel()));
  std::memcpy(v.data(), c.data_ptr<float>(), v.size() * sizeof(float));
  return v;
}

/// The parameters then the buffers of `m`, in registration order, with their names.
std::vector<std::pair<std::string, torch::Tensor>> state_tensors(const torch::nn::Module& m) {
  std::vector<std::pair<std::string, torch::Tensor>> t;
  for (const auto& p : m.named_parameters()) t.emplace_back(p.key(), p.value());
  for (const auto& b : m.named_buffers()) t.emplace_back(b.key(), b.value());
  return t;
}

/// (average's, current's) tensor pairs; throws std::invalid_argument at the first that differs in name or shape.
std::vector<std::pair<torch::Tensor, torch::Tensor>> matched_state(const torch::nn::Module& average,
                                                                   const torch::nn::Module& current) {
  const auto a = state_tensors(average), c = state_tensors(current);
  if (a.size() != c.size())
    throw std::invalid_argument(
        fmt::format("weight average: {} parameters and buffers, the network has {}", a.size(), c.size()));
  std::vector<std::pair<torch::Tensor, torch::Tensor>> out;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].first != c[i].first || !a[i].second.sizes().equals(c[i].second.sizes()) ||
        a[i].second.scalar_type() != c[i].second.scalar_type())
      throw std::invalid_argument(fmt::format("weight average: '{}' ({}) does not match the network's '{}' ({})",
                                              a[i].first, shape_text(a[i].second), c[i].first,
                                              shape_text(c[i].second)));
    out.emplace_back(a[i].second, c[i].second);
  }
  return out;
}

void check_same_layers(const detector::DarknetModel& built, const detector::DarknetModel& other) {
  if (built.layers.size() != other.layers.size())
    throw std::invalid_argument(fmt::format("{}: {} layers, the network was built from {} ({} layers)", other.cfg_path,
                                            other.layers.size(), built.cfg_path, built.layers.size()));
  for (size_t i = 0; i < built.layers.size(); ++i) {
    const Layer& a = built.layers[i];
    const Layer& b = other.layers[i];
    if (a.type != b.type || !(a.input == b.input) || !(a.output == b.output) ||
        a.batch_normalize != b.batch_normalize || a.size != b.size)
      throw std::invalid_argument(fmt::format("{}: differs from layer {} of {} the network was built from",
                                              where(other, i), i, built.cfg_path));
  }
}

}  // namespace

DarknetNetImpl::DarknetNetImpl(const detector::DarknetModel& model) : model_(model) {
  if (model_.layers.empty()) throw std::invalid_argument(fmt::format("{}: the network has no layers", model.cfg_path));
  convs_.resize(model_.layers.size(), torch::nn::Conv2d(nullptr));
  bns_.resize(model_.layers.size(), torch::nn::BatchNorm2d(nullptr));
  for (size_t i = 0; i < model_.layers.size(); ++i) {
    Layer& l = model_.layers[i];
    l.biases.clear();
    l.scales.clear();
    l.rolling_mean.clear();
    l.rolling_variance.clear();
    l.weights.clear();
    if (l.type == LayerType::kRegion || l.type == LayerType::kYolo) heads_.push_back(static_cast<int>(i));
    if (l.type != LayerType::kConvolutional) continue;
    convs_[i] = register_module(fmt::format("conv{}", i),
                                torch::nn::Conv2d(torch::nn::Conv2dOptions(l.input.c, l.filters, l.size)
                                                      .stride(l.stride)
                                                      .padding(l.padding)
                                                      .bias(!l.batch_normalize)));
    if (l.batch_normalize)
      bns_[i] = register_module(
          fmt::format("bn{}", i),
          torch::nn::BatchNorm2d(
              torch::nn::BatchNormOptions(l.filters).eps(kBatchNormEpsilon).momentum(kBatchNormMomentum)));
  }
  // A convolution that feeds a head starts near zero with a low objectness, so that every prediction starts as its
  // anchor at its cell's centre with confidence kHeadObjectnessPrior (libtorch's default initialisation gives
  // t_w, t_h of several units there: boxes e^3 = 20 times their anchor, which the sqrt-size loss barely corrects).
  for (int h : heads_) {
    const size_t c = static_cast<size_t>(h) - 1;
    if (h < 1 || model_.layers[c].type != LayerType::kConvolutional || model_.layers[c].batch_normalize) continue;
    const Layer& head = model_.layers[static_cast<size_t>(h)];
    torch::NoGradGuard no_grad;
    convs_[c]->weight.normal_(0.0, kHeadWeightStd);
    convs_[c]->bias.zero_();
    const double prior = std::log(kHeadObjectnessPrior / (1.0 - kHeadObjectnessPrior));
    for (int a = 0; a < head.num; ++a) convs_[c]->bias[a * (5 + head.classes) + 4] = prior;
  }
}

std::vector<torch::Tensor> DarknetNetImpl::forward(const torch::Tensor& input) {
  const detector::NetParams& net = model_.net;
  if (input.dim() != 4 || input.size(1) != net.channels || input.size(2) != net.height || input.size(3) != net.width)
    throw std::invalid_argument(fmt::format("DarknetNet::forward: input of shape {}, expected N x {} x {} x {}",
                                            shape_text(input), net.channels, net.height, net.width));
  std::vector<torch::Tensor> outputs(model_.layers.size());
  std::vector<torch::Tensor> heads;
  torch::Tensor x = input;
  for (size_t i = 0; i < model_.layers.size(); ++i) {
    const Layer& l = model_.layers[i];
    switch (l.type) {
      case LayerType::kConvolutional:
        x = convs_[i]->forward(x);
        if (l.batch_normalize) {
          if (is_training()) {
            // The exact mean of the batches so far until that is Darknet's 0.01 average: short runs get
            // usable rolling statistics too (starting from mean 0, variance 1 would take ~500 batches).
            const double seen = bns_[i]->num_batches_tracked.item<double>();
            bns_[i]->options.momentum(std::max(kBatchNormMomentum, 1.0 / (seen + 1.0)));
          }
          x = bns_[i]->forward(x);
        }
        if (l.activation == Activation::kLeaky)
          x = torch::leaky_relu(x, kLeakySlope);
        else if (l.activation == Activation::kLogistic)
          x = torch::sigmoid(x);
        break;
      case LayerType::kMaxpool: {
        // Darknet: offset -padding/2, windows may reach past the right/bottom edge (max over valid pixels).
        const int left = l.pool_padding / 2;
        const int right_w = std::max(0, (l.output.w - 1) * l.pool_stride + l.pool_size - l.input.w - left);
        const int right_h = std::max(0, (l.output.h - 1) * l.pool_stride + l.pool_size - l.input.h - left);
        torch::Tensor padded = x;
        if (left > 0 || right_w > 0 || right_h > 0)
          padded = torch::constant_pad_nd(x, {left, right_w, left, right_h}, -std::numeric_limits<float>::infinity());
        x = torch::max_pool2d(padded, {l.pool_size, l.pool_size}, {l.pool_stride, l.pool_stride});
        x = x.slice(2, 0, l.output.h).slice(3, 0, l.output.w);
        break;
      }
      case LayerType::kRoute: {
        std::vector<torch::Tensor> parts;
        for (int src : l.route_layers) parts.push_back(outputs[static_cast<size_t>(src)]);
        x = parts.size() == 1 ? parts.front() : torch::cat(parts, 1);
        break;
      }
      case LayerType::kUpsample:
        x = torch::upsample_nearest2d(x, {l.output.h, l.output.w});
        break;
      case LayerType::kRegion:
      case LayerType::kYolo:
        heads.push_back(x);
        break;
    }
    outputs[i] = x;
  }
  if (heads.empty()) heads.push_back(x);
  return heads;
}

void DarknetNetImpl::load_weights(const detector::DarknetModel& model, int conv_layers) {
  check_same_layers(model_, model);
  int copied = 0;
  for (size_t i = 0; i < model.layers.size(); ++i) {
    const Layer& l = model.layers[i];
    if (l.type != LayerType::kConvolutional) continue;
    if (conv_layers >= 0 && copied++ >= conv_layers) break;
    const std::string w = where(model, i);
    copy_into(convs_[i]->weight, l.weights, w + " weights");
    if (l.batch_normalize) {
      copy_into(bns_[i]->bias, l.biases, w + " biases (beta)");
      copy_into(bns_[i]->weight, l.scales, w + " scales (gamma)");
      copy_into(bns_[i]->running_mean, l.rolling_mean, w + " rolling mean");
      copy_into(bns_[i]->running_var, l.rolling_variance, w + " rolling variance");
    } else {
      copy_into(convs_[i]->bias, l.biases, w + " biases");
    }
  }
}

void DarknetNetImpl::store_weights(detector::DarknetModel& model) const {
  check_same_layers(model_, model);
  for (size_t i = 0; i < model.layers.size(); ++i) {
    Layer& l = model.layers[i];
    if (l.type != LayerType::kConvolutional) continue;
    l.weights = copy_out(convs_[i]->weight);
    if (l.batch_normalize) {
      l.biases = copy_out(bns_[i]->bias);
      l.scales = copy_out(bns_[i]->weight);
      l.rolling_mean = copy_out(bns_[i]->running_mean);
      l.rolling_variance = copy_out(bns_[i]->running_var);
    } else {
      l.biases = copy_out(convs_[i]->bias);
    }
  }
}

std::vector<torch::Tensor> DarknetNetImpl::kernel_parameters() const {
  std::vector<torch::Tensor> out;
  for (const auto& c : convs_)
    if (c) out.push_back(c->weight);
  return out;
}

std::vector<torch::Tensor> DarknetNetImpl::other_parameters() const {
  std::vector<torch::Tensor> out;
  for (size_t i = 0; i < convs_.size(); ++i) {
    if (convs_[i] && convs_[i]->bias.defined()) out.push_back(convs_[i]->bias);
    if (bns_[i]) {
      out.push_back(bns_[i]->weight);
      out.push_back(bns_[i]->bias);
    }
  }
  return out;
}

void copy_weights(torch::nn::Module& average, const torch::nn::Module& current) {
  torch::NoGradGuard no_grad;
  for (auto& [a, c] : matched_state(average, current)) a.copy_(c);
}

void update_weight_average(torch::nn::Module& average, const torch::nn::Module& current, double d) {
  if (!(d >= 0.0 && d <= 1.0)) throw std::invalid_argument(fmt::format("weight average: decay {} not in [0, 1]", d));
  torch::NoGradGuard no_grad;
  for (auto& [a, c] : matched_state(average, current)) {
    if (a.is_floating_point())
      a.mul_(d).add_(c, 1.0 - d);
    else
      a.copy_(c);
  }
}

}  // namespace wingman::training
