// SPDX-License-Identifier: MIT
// The CPU inference backend: OpenCV DNN's Darknet importer on the same .cfg and .weights (the reference).
#pragma once

#include "wingman/detector/backend.hpp"
#include "wingman/detector/darknet_model.hpp"

#include <opencv2/dnn.hpp>

#include <string>
#include <vector>

namespace wingman::detector {

/// InferenceBackend on OpenCV DNN (DNN_BACKEND_OPENCV, DNN_TARGET_CPU), built from a DarknetModel in memory
/// (its .cfg text from write_darknet_cfg and its .weights bytes, through readNetFromDarknet's buffer
/// overload; no temporary files). It is the reference the OpenCL backend is checked against.
///
/// The network may end in any supported layer (convolutional, maxpool, route, upsample; useful for
/// single-layer comparisons). OpenCV would apply its own decode to [region] and [yolo] heads (and reorder
/// the tensor); instead each head (which has no weights) becomes a one-layer [route] to the layer before
/// it, so forward() returns the raw input of every head: the tensors decode_region() / decode_yolo() take.
class CpuBackend : public InferenceBackend {
 public:
  /// @param model      network with its weights loaded or randomized (a convolution without weights
  ///                   is a DarknetFormatError).
  /// @param max_batch  largest batch forward() accepts, >= 1 (std::invalid_argument otherwise).
  explicit CpuBackend(const DarknetModel& model, int max_batch = 8);

  std::string name() const override { return "opencv-cpu"; }
  Shape input_shape() const override { return input_shape_; }
  std::vector<Shape> output_shapes() const override { return output_shapes_; }
  int max_batch() const override { return max_batch_; }
  void forward(const float* input, int batch, std::vector<float>& output) override;

  /// Names of the OpenCV DNN layers whose outputs forward() returns (for diagnostics; OpenCV's naming).
  const std::vector<std::string>& output_layer_names() const { return output_names_; }

 private:
  cv::dnn::Net net_;
  Shape input_shape_;
  std::vector<Shape> output_shapes_;
  int max_batch_ = 1;
  std::vector<std::string> output_names_;
  std::vector<cv::Mat> outs_;  ///< forward() scratch
};

}  // namespace wingman::detector
