// SPDX-License-Identifier: MIT
// The inference backend interface: a batch of network-sized images in, the raw output tensor out.
#pragma once

#include "wingman/detector/darknet_model.hpp"

#include <string>
#include <vector>

namespace wingman::detector {

/// Runs one Darknet network on batches of images. Implementations: CpuBackend (OpenCV DNN, the reference)
/// and OpenClBackend. A backend is used from one thread at a time.
class InferenceBackend {
 public:
  virtual ~InferenceBackend() = default;

  /// Short name for logs and status ("opencv-cpu", "opencl", ...).
  virtual std::string name() const = 0;

  /// Shape of one input image: C x H x W = net.channels x net.height x net.width.
  virtual Shape input_shape() const = 0;

  /// Shape of one image's output: the output of the network's last layer, except that for a network
  /// ending in [region] or [yolo] it is the raw output of the layer before the head (the last
  /// convolution, before any region decode): e.g. 30 x 13 x 13 for the thesis network.
  virtual Shape output_shape() const = 0;

  /// Largest `batch` forward() accepts (>= 1).
  virtual int max_batch() const = 0;

  /// Runs the network.
  /// @param input  `batch` images, each C x H x W float32 (input_shape()), RGB planes scaled to [0, 1],
  ///               contiguous (batch x C x H x W).
  /// @param batch  1 <= batch <= max_batch().
  /// @param output resized to batch x output_shape().size() and filled with the raw output tensor
  ///               (N x C x H x W, before region decode). Reusing the same vector avoids allocations.
  /// Throws std::invalid_argument on a bad batch, std::runtime_error on a backend failure.
  virtual void forward(const float* input, int batch, std::vector<float>& output) = 0;
};

}  // namespace wingman::detector
