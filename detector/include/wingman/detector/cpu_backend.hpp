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
/// single-layer comparisons). When it ends in [region] or [yolo], OpenCV would apply its own decode
/// (and reorder the tensor); instead the head (which has no weights) is left out of the OpenCV network,
/// so forward() returns the raw output of the layer before it (the last convolution): the tensor
/// decode_region() takes.
class CpuBackend : public InferenceBackend {
 public:
  /// @param model      network with its weights loaded or randomized (a convolution without weights
  ///                   is a DarknetFormatError).
  /// @param max_batch  largest batch forward() accepts, >= 1 (std::invalid_argument otherwise).
  explicit CpuBackend(const DarknetModel& model, int max_batch = 8);

  std::string name() const override { return "opencv-cpu"; }
  Shape input_shape() const override { return input_shape_; }
  Shape output_shape() const override { return output_shape_; }
  int max_batch() const override { return max_batch_; }
  void forward(const float* input, int batch, std::vector<float>& output) override;

  /// Name of the OpenCV DNN layer whose output forward() returns (for diagnostics; OpenCV's own naming).
  const std::string& output_layer_name() const { return output_name_; }

 private:
  cv::dnn::Net net_;
  Shape input_shape_;
  Shape output_shape_;
  int max_batch_ = 1;
  std::string output_name_;
};

}  // namespace wingman::detector
