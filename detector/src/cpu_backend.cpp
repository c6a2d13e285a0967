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
  // A [region] / [yolo] head has no weights: OpenCV gets the network without it, so its last layer is the
  // raw convolution output (OpenCV's own head would decode and reorder the tensor).
  DarknetModel body = model;
  const LayerType last = body.layers.back().type;
  if (last == LayerType::kRegion || last == LayerType::kYolo) {
    if (body.layers.size() == 1)
      throw DarknetFormatError(
          fmt::format("{}: a [{}] head needs a layer before it", model.cfg_path, layer_type_name(last)));
    body.layers.pop_back();
  }
  output_shape_ = body.layers.back().output;
  const std::string cfg = write_darknet_cfg(body);
  const std::vector<char> weights = serialize_darknet_weights(body);
  net_ = cv::dnn::readNetFromDarknet(cfg.data(), cfg.size(), weights.data(), weights.size());
  if (net_.empty()) throw std::runtime_error(fmt::format("{}: OpenCV DNN could not build the network", model.cfg_path));
  net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  const std::vector<std::string> outs = net_.getUnconnectedOutLayersNames();
  if (outs.size() != 1)
    throw std::runtime_error(
        fmt::format("{}: OpenCV DNN built a network with {} outputs, expected 1", model.cfg_path, outs.size()));
  output_name_ = outs.front();
}

void CpuBackend::forward(const float* input, int batch, std::vector<float>& output) {
  if (batch < 1 || batch > max_batch_)
    throw std::invalid_argument(fmt::format("CpuBackend::forward: batch = {}: must be in 1..{}", batch, max_batch_));
  const int dims[4] = {batch, input_shape_.c, input_shape_.h, input_shape_.w};
  // setInput copies the blob, so wrapping the caller's buffer is safe.
  const cv::Mat blob(4, dims, CV_32F, const_cast<float*>(input));
  net_.setInput(blob);
  const cv::Mat out = net_.forward();
  const size_t per_image = static_cast<size_t>(output_shape_.size());
  const size_t expected = per_image * static_cast<size_t>(batch);
  if (out.total() != expected || out.type() != CV_32F || !out.isContinuous())
    throw std::runtime_error(
        fmt::format("CpuBackend: layer {} returned {} values (type {}), expected {} x {}x{}x{} = {}", output_name_,
                    out.total(), out.type(), batch, output_shape_.c, output_shape_.h, output_shape_.w, expected));
  output.resize(expected);
  std::memcpy(output.data(), out.ptr<float>(), expected * sizeof(float));
}

}  // namespace wingman::detector
