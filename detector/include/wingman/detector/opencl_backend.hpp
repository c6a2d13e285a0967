// SPDX-License-Identifier: MIT
// Tiny-YOLO inference on OpenCL: our own kernels on a 16-channel blocked layout (see docs/detector.md).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "wingman/detector/backend.hpp"
#include "wingman/detector/darknet_model.hpp"
#include "wingman/detector/opencl_options.hpp"

namespace wingman::detector {

/// Device time of one command of OpenClBackend::forward() (a layer's kernel, or moving the input or output)
/// over the forwards profiled since OpenClBackend::set_profiling(true).
struct KernelTiming {
  std::string what;        ///< "layer 12 [convolutional] (cfg line 114)", "input: ...", "output: ..."
  int layer = -1;          ///< index of the model layer, -1 for input/output commands
  double flops = 0;        ///< per image: 2 x multiply-adds of a convolution, 0 otherwise, FLOP
  std::vector<double> ms;  ///< device time (CL_PROFILING_COMMAND_END - START) of each profiled forward, ms
  int64_t images = 0;      ///< images over those forwards (batch sizes summed)
};

/// Runs a DarknetModel ([convolutional] with batch normalisation folded in and bias + activation fused,
/// a following 2x2 stride-2 [maxpool] fused in, 3x3 stride-1 layers on many channels as Winograd
/// F(2x2, 3x3); [maxpool], [route], [upsample]; [region]/[yolo] heads pass their input through, decoding
/// stays on the host) on one OpenCL 1.2 device. docs/detector.md describes the kernels.
///
/// Everything is prepared in the constructor: device selection, program builds (PoCL caches binaries
/// under POCL_CACHE_DIR), weight folding and packing, every buffer for `max_batch` images and every
/// kernel's arguments. forward() only enqueues: it allocates nothing on the device.
class OpenClBackend : public InferenceBackend {
 public:
  /// Throws std::invalid_argument if the options are invalid or the model has a layer this backend
  /// does not run or weights of the wrong size, std::runtime_error naming the available platforms and
  /// devices if none matches, or an OpenCL build/runtime error with the build log.
  OpenClBackend(const DarknetModel& model, const OpenClOptions& options);
  ~OpenClBackend() override;
  OpenClBackend(const OpenClBackend&) = delete;
  OpenClBackend& operator=(const OpenClBackend&) = delete;

  std::string name() const override;  ///< "opencl: <device name>"
  Shape input_shape() const override;
  std::vector<Shape> output_shapes() const override;
  int max_batch() const override;
  /// input: `batch` CHW float images, contiguous; output: see InferenceBackend::forward().
  /// Precondition: 1 <= batch <= max_batch(). Throws std::invalid_argument otherwise.
  void forward(const float* input, int batch, std::vector<float>& output) override;

  /// The selected device, e.g. "pthread-skylake-avx512-Intel(R) Xeon(R) Processor".
  std::string device_name() const;
  /// True when the selected device is a GPU (CL_DEVICE_TYPE_GPU).
  bool is_gpu() const;

  /// What forward() enqueues, in order, one line per command: "input: ...", "layer 12 [convolutional] (cfg
  /// line 114) winograd: 16 products ...", "output 0: ..." (the names profile() uses).
  std::vector<std::string> commands() const;

  /// Starts (clearing what was recorded) or stops recording the device time of every command of forward().
  /// Profiling gives every command an OpenCL event and reads its timestamps after each forward; leave it
  /// off in production. Throws std::runtime_error on an OpenCL error.
  void set_profiling(bool on);
  /// The commands of forward() in launch order, each with its time in every forward since
  /// set_profiling(true); empty when profiling never ran.
  std::vector<KernelTiming> profile() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace wingman::detector
