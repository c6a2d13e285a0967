// SPDX-License-Identifier: MIT
// Loading the detector's network and choosing its inference backend.
#include "wingman/detector/model_loader.hpp"

#include "wingman/detector/cpu_backend.hpp"
#include "wingman/detector/darknet_cfg.hpp"
#include "wingman/detector/darknet_weights.hpp"
#include "wingman/detector/opencl_backend.hpp"

#include <fmt/format.h>
#include <openssl/evp.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <vector>

namespace wingman::detector {
namespace {

/// Milliseconds of each of `runs` forwards of one zero image, after an untimed warm-up forward if `warm_up`.
std::vector<double> forward_ms(InferenceBackend& backend, int runs, bool warm_up = true) {
  std::vector<float> input(static_cast<size_t>(backend.input_shape().size()), 0.0f);
  std::vector<float> output;
  if (warm_up) backend.forward(input.data(), 1, output);
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    backend.forward(input.data(), 1, output);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  return ms;
}

}  // namespace

std::vector<std::string> builtin_cfg_names() { return {"wingman-small", "tiny-yolo-thesis"}; }
std::vector<std::string> builtin_weights_names() { return {"wingman-small"}; }

namespace {

std::string builtin_name(const std::string& s) {
  const std::string prefix = kBuiltinPrefix;
  return s.rfind(prefix, 0) == 0 ? s.substr(prefix.size()) : "";
}

std::string known_names(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + std::string(kBuiltinPrefix) + n;
  return s;
}

}  // namespace

DarknetModel load_cfg(const std::string& cfg) {
  const std::string name = builtin_name(cfg);
  if (cfg.empty()) {
    throw std::runtime_error("model.cfg is empty: expected a Darknet .cfg path or one of " +
                             known_names(builtin_cfg_names()));
  }
  if (name == "wingman-small") return parse_darknet_cfg_string(builtin_small_cfg(), "<built-in wingman-small.cfg>");
  if (name == "tiny-yolo-thesis")
    return parse_darknet_cfg_string(builtin_thesis_cfg(), "<built-in tiny-yolo-thesis.cfg>");
  if (!name.empty()) {
    throw std::runtime_error("model.cfg = '" + cfg + "': no such built-in network; expected one of " +
                             known_names(builtin_cfg_names()) + " or a .cfg path");
  }
  return parse_darknet_cfg(cfg);
}

void load_weights(DarknetModel& model, const std::string& weights) {
  const std::string name = builtin_name(weights);
  if (name == "wingman-small") {
    const std::vector<char> bytes = builtin_small_weights();
    if (bytes.empty()) {
      throw std::runtime_error(
          "model.weights = 'builtin:wingman-small': this build has no built-in weights (models/wingman-small.weights "
          "was absent when it was built); give a .weights path");
    }
    load_darknet_weights_from_buffer(model, bytes, "<built-in wingman-small.weights>");
  } else if (!name.empty()) {
    throw std::runtime_error("model.weights = '" + weights + "': no such built-in model; expected " +
                             known_names(builtin_weights_names()) + " or a .weights path");
  } else {
    load_darknet_weights(model, weights);
  }
}

std::string weights_model_id(const std::string& weights) {
  if (weights.empty()) return "";
  std::vector<char> bytes;
  const std::string name = builtin_name(weights);
  if (name == "wingman-small") {
    bytes = builtin_small_weights();
  } else if (!name.empty()) {
    throw std::runtime_error("model.weights = '" + weights + "': no such built-in model; expected " +
                             known_names(builtin_weights_names()) + " or a .weights path");
  } else {
    std::ifstream in(weights, std::ios::binary);
    if (!in) throw std::runtime_error(weights + ": cannot read the weights file");
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int digest_size = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest, &digest_size, EVP_sha256(), nullptr) != 1 || digest_size < 8)
    throw std::runtime_error(weights + ": SHA-256 of the weights failed (OpenSSL)");
  std::string id = "sha256:";
  for (int i = 0; i < 8; ++i) id += fmt::format("{:02x}", digest[i]);
  return id;
}

DarknetModel load_model(const std::string& cfg, const std::string& weights) {
  DarknetModel model = load_cfg(cfg);
  load_weights(model, weights);
  return model;
}

std::unique_ptr<InferenceBackend> make_backend(const std::string& kind, const DarknetModel& model,
                                               const OpenClOptions& opencl, int max_batch, std::string* why,
                                               AutoChoice choice) {
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
  const char* auto_is = choice == AutoChoice::kRepeatable ? "auto, not timed" : "auto";
  if (!gpu) {
    if (why) *why = fmt::format("backend cpu ({}: no usable OpenCL device: {})", auto_is, opencl_error);
    return std::make_unique<CpuBackend>(model, max_batch);
  }
  if (choice == AutoChoice::kRepeatable) {
    if (why)
      *why =
          fmt::format("backend {} ({}: OpenCL whenever a device is usable, so that runs repeat)", gpu->name(), auto_is);
    return gpu;
  }
  // A GPU is timed too: the kernels are shaped for CPUs (PoCL), and on an NVIDIA H200 they ran the thesis network
  // at 416 3x slower than OpenCV DNN on that machine's CPU cores (docs/benchmarks.md).
  auto cpu = std::make_unique<CpuBackend>(model, max_batch);
  // Each warmed up once, then timed in turn, OpenCL then CPU, up to three times each, and each backend's fastest
  // forward compared: a load that changes during start-up (several detectors starting together on a small machine,
  // each timing its backends while the others do) weighs on both alike, and the fastest forward is the one it
  // disturbed least. (Timed one after the other, all of OpenCL's runs first, a load that eases during the timing
  // favours the backend timed last: in the load test's start-up of four detectors two of four once chose the CPU and
  // ran at half speed.) A clear loser (the CPU more than 1.5x slower in the first
  // turn) is not timed further: start-up cost.
  (void)forward_ms(*gpu, 0);
  (void)forward_ms(*cpu, 0);
  std::vector<double> ocl_ms, cpu_ms;
  for (int turn = 0; turn < 3; ++turn) {
    ocl_ms.push_back(forward_ms(*gpu, 1, /*warm_up=*/false)[0]);
    cpu_ms.push_back(forward_ms(*cpu, 1, /*warm_up=*/false)[0]);
    if (turn == 0 && cpu_ms[0] >= 1.5 * ocl_ms[0]) break;
  }
  const double ms_ocl = *std::min_element(ocl_ms.begin(), ocl_ms.end());
  const double ms_cpu = *std::min_element(cpu_ms.begin(), cpu_ms.end());
  if (why) {
    *why = fmt::format(
        "backend {} (auto: fastest of {} forward(s) each, in turn: {:.1f} ms opencl ({}) vs {:.1f} ms cpu per frame)",
        ms_ocl <= ms_cpu ? gpu->name() : cpu->name(), cpu_ms.size(), ms_ocl, gpu->is_gpu() ? "a GPU" : "not a GPU",
        ms_cpu);
  }
  if (ms_ocl <= ms_cpu) return gpu;
  return cpu;
}

}  // namespace wingman::detector
