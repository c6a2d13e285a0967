// SPDX-License-Identifier: MIT
// The inference backend interface: a batch of network-sized images in, the raw output tensor out.
#pragma once

#include "wingman/detector/darknet_model.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace wingman::detector {

/// Floats of one image's outputs: the sum of the shapes' sizes.
inline int64_t output_size(const std::vector<Shape>& shapes) {
  int64_t n = 0;
  for (const Shape& s : shapes) n += s.size();
  return n;
}

/// Runs one Darknet network on batches of images. Implementations: CpuBackend (OpenCV DNN, the reference)
/// and OpenClBackend. A backend is used from one thread at a time.
class InferenceBackend {
 public:
  virtual ~InferenceBackend() = default;

  /// Short name for logs and status ("opencv-cpu", "opencl", ...).
  virtual std::string name() const = 0;

  /// Shape of one input image: C x H x W = net.channels x net.height x net.width.
  virtual Shape input_shape() const = 0;

  /// Shapes of one image's output tensors, in order. For a network with [region]/[yolo] heads: the raw
  /// input of each head (the output of the layer before it, before any decode), in cfg order, e.g. one
  /// 30 x 13 x 13 tensor for the thesis network, two (13 x 13 and 26 x 26) for a tiny-YOLOv3. For a
  /// network without heads: the output of its last layer.
  virtual std::vector<Shape> output_shapes() const = 0;

  /// Largest `batch` forward() accepts (>= 1).
  virtual int max_batch() const = 0;

  /// Runs the network.
  /// @param input  `batch` images, each C x H x W float32 (input_shape()), RGB planes scaled to [0, 1],
  ///               contiguous (batch x C x H x W).
  /// @param batch  1 <= batch <= max_batch().
  /// @param output resized to batch x output_size(output_shapes()) and filled, image after image, with
  ///               each image's output tensors (C x H x W each, in output_shapes() order, before any
  ///               decode). Reusing the same vector avoids allocations.
  /// Throws std::invalid_argument on a bad batch, std::runtime_error on a backend failure.
  virtual void forward(const float* input, int batch, std::vector<float>& output) = 0;
};

}  // namespace wingman::detector
