// SPDX-License-Identifier: MIT
// Loading the detector's network and choosing its inference backend.
#include "wingman/detector/model_loader.hpp"

#include "wingman/detector/cpu_backend.hpp"
#include "wingman/detector/darknet_cfg.hpp"
#include "wingman/detector/darknet_weights.hpp"
#include "wingman/detector/opencl_backend.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <vector>

namespace wingman::detector {
namespace {

/// Median milliseconds of `runs` forwards of one zero image, after one warm-up forward.
double median_forward_ms(InferenceBackend& backend, int runs) {
  std::vector<float> input(static_cast<size_t>(backend.input_shape().size()), 0.0f);
  std::vector<float> output;
  backend.forward(input.data(), 1, output);
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    backend.forward(input.data(), 1, output);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

}  // namespace

DarknetModel load_model(const std::string& cfg_path, const std::string& weights_path) {
  DarknetModel model = cfg_path.empty()
                           ? parse_darknet_cfg_string(builtin_thesis_cfg(), "<built-in tiny-yolo-thesis.cfg>")
                           : parse_darknet_cfg(cfg_path);
  load_darknet_weights(model, weights_path);
  return model;
}

std::unique_ptr<InferenceBackend> make_backend(const std::string& kind, const DarknetModel& model,
                                               const OpenClOptions& opencl, int max_batch, std::string* why) {
  OpenClOptions ocl = opencl;
  ocl.max_batch = max_batch;
  if (kind == "cpu") {
    if (why) *why = "backend cpu (OpenCV DNN), as configured";
    return std::make_unique<CpuBackend>(model, max_batch);
  }
  if (kind == "opencl") {
    auto b = std::make_unique<OpenClBackend>(model, ocl);
    if (why) *why = "backend " + b->name() + ", as configured";
    return b;
  }
  if (kind != "auto") throw std::runtime_error("model.backend = '" + kind + "': must be auto, opencl or cpu");
  std::unique_ptr<OpenClBackend> gpu;
  std::string opencl_error;
  try {
    gpu = std::make_unique<OpenClBackend>(model, ocl);
  } catch (const std::exception& e) {
    opencl_error = e.what();
  }
  if (gpu && gpu->is_gpu()) {
    if (why) *why = "backend " + gpu->name() + " (auto: an OpenCL GPU)";
    return gpu;
  }
  auto cpu = std::make_unique<CpuBackend>(model, max_batch);
  if (!gpu) {
    if (why) *why = "backend cpu (auto: no usable OpenCL device: " + opencl_error + ")";
    return cpu;
  }
  const double ms_ocl = median_forward_ms(*gpu, 3), ms_cpu = median_forward_ms(*cpu, 3);
  if (why) {
    *why = fmt::format("backend {} (auto: no OpenCL GPU; measured {:.1f} ms opencl vs {:.1f} ms cpu per frame)",
                       ms_ocl <= ms_cpu ? gpu->name() : cpu->name(), ms_ocl, ms_cpu);
  }
  if (ms_ocl <= ms_cpu) return gpu;
  return cpu;
}

}  // namespace wingman::detector
