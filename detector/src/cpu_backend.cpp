// SPDX-License-Identifier: MIT
// CpuBackend: OpenCV DNN on a DarknetModel in memory.
#include "wingman/detector/cpu_backend.hpp"

#include "wingman/detector/darknet_cfg.hpp"
#include "wingman/detector/darknet_weights.hpp"

#include <fmt/format.h>

#include <cstring>
#include <stdexcept>

namespace wingman::detector {

CpuBackend::CpuBackend(const DarknetModel& model, int max_batch) : max_batch_(max_batch) {
  if (max_batch < 1) throw std::invalid_argument(fmt::format("CpuBackend: max_batch = {}: must be >= 1", max_batch));
  if (model.layers.empty()) throw DarknetFormatError(fmt::format("{}: the network has no layers", model.cfg_path));
  input_shape_ = {model.net.channels, model.net.height, model.net.width};
  // A [region] / [yolo] head has no weights, and OpenCV's own head would decode and reorder the tensor:
  // each head becomes a one-layer [route] to the layer before it (OpenCV: an Identity layer named
  // "identity_<index>", indices unchanged), whose output is the head's raw input.
  DarknetModel body = model;
  for (const int h : model.heads()) {
    if (h == 0)
      throw DarknetFormatError(fmt::format("{}: a [{}] head needs a layer before it", model.cfg_path,
                                           layer_type_name(model.layers[h].type)));
    Layer identity;
    identity.type = LayerType::kRoute;
    identity.cfg_line = model.layers[h].cfg_line;
    identity.route_layers = {h - 1};
    body.layers[h] = identity;
    output_names_.push_back(fmt::format("identity_{}", h));
    output_shapes_.push_back(model.layers[h].input);
  }
  const std::string cfg = write_darknet_cfg(body);
  const std::vector<char> weights = serialize_darknet_weights(body);
  net_ = cv::dnn::readNetFromDarknet(cfg.data(), cfg.size(), weights.data(), weights.size());
  if (net_.empty()) throw std::runtime_error(fmt::format("{}: OpenCV DNN could not build the network", model.cfg_path));
  net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  if (output_names_.empty()) {
    const std::vector<std::string> outs = net_.getUnconnectedOutLayersNames();
    if (outs.size() != 1)
      throw std::runtime_error(fmt::format("{}: OpenCV DNN built a network without heads with {} outputs, expected 1",
                                           model.cfg_path, outs.size()));
    output_names_ = outs;
    output_shapes_.push_back(body.layers.back().output);
  }
  for (const std::string& name : output_names_)
    if (net_.getLayerId(name) < 0)
      throw std::runtime_error(
          fmt::format("{}: OpenCV DNN has no layer '{}' (its Darknet importer's naming)", model.cfg_path, name));
}

void CpuBackend::forward(const float* input, int batch, std::vector<float>& output) {
  if (batch < 1 || batch > max_batch_)
    throw std::invalid_argument(fmt::format("CpuBackend::forward: batch = {}: must be in 1..{}", batch, max_batch_));
  const int dims[4] = {batch, input_shape_.c, input_shape_.h, input_shape_.w};
  // setInput copies the blob, so wrapping the caller's buffer is safe.
  const cv::Mat blob(4, dims, CV_32F, const_cast<float*>(input));
  net_.setInput(blob);
  net_.forward(outs_, output_names_);
  const size_t per_image = static_cast<size_t>(output_size(output_shapes_));
  output.resize(per_image * static_cast<size_t>(batch));
  size_t offset = 0;  // of this tensor inside one image's outputs
  for (size_t k = 0; k < outs_.size(); ++k) {
    const cv::Mat& out = outs_[k];
    const Shape& s = output_shapes_[k];
    const size_t one = static_cast<size_t>(s.size());
    if (out.total() != one * batch || out.type() != CV_32F || !out.isContinuous())
      throw std::runtime_error(
          fmt::format("CpuBackend: layer {} returned {} values (type {}), expected {} x {}x{}x{} = {}",
                      output_names_[k], out.total(), out.type(), batch, s.c, s.h, s.w, one * batch));
    for (int n = 0; n < batch; ++n)
      std::memcpy(output.data() + n * per_image + offset, out.ptr<float>() + n * one, one * sizeof(float));
    offset += one;
  }
}

}  // namespace wingman::detector
