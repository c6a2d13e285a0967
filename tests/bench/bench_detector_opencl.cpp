// SPDX-License-Identifier: MIT
// The thesis network (random weights) per frame: our OpenCL backend vs CpuBackend vs bare cv::dnn, one run; the
// shipped model (builtin:wingman-small at its cfg size, 640x352) on both backends.
//
// Run with POCL_AFFINITY=1 (docs/pocl-performance.md). Counters: GFLOP/s from DarknetModel::flops()
// (convolutions only), per image. Report the median aggregates of --benchmark_repetitions=5
// --benchmark_min_time=0.5 (the figures' flags; CTest runs it once, briefly).
// --per-layer (this program's own flag, taken out before Google Benchmark's): after the benchmarks, the OpenCL
// device time of every command of one forward (median of 10 profiled forwards) for the thesis network at 416 and
// 256 and the shipped model, one line each, to stdout.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <opencv2/dnn.hpp>
#include <random>
#include <string>
#include <vector>

#include "wingman/detector/cpu_backend.hpp"
#include "wingman/detector/darknet_cfg.hpp"
#include "wingman/detector/darknet_weights.hpp"
#include "wingman/detector/model_loader.hpp"
#include "wingman/detector/opencl_backend.hpp"

namespace {

using namespace wingman::detector;

/// models/tiny-yolo-thesis.cfg at another input size: 6 x (3x3 conv+BN+leaky, maxpool; the sixth pool
/// size 2 stride 1), 2 x 3x3 conv 1024, 1x1 linear conv to 30, [region].
std::string thesis_cfg(int size) {
  std::string cfg = "[net]\nwidth=" + std::to_string(size) + "\nheight=" + std::to_string(size) + "\nchannels=3\n\n";
  auto conv = [](int filters, int ksize, bool bn, const char* act) {
    return std::string("[convolutional]\n") + (bn ? "batch_normalize=1\n" : "") + "filters=" + std::to_string(filters) +
           "\nsize=" + std::to_string(ksize) + "\nstride=1\npad=1\nactivation=" + act + "\n\n";
  };
  const int filters[] = {16, 32, 64, 128, 256, 512};
  for (int i = 0; i < 6; ++i)
    cfg += conv(filters[i], 3, true, "leaky") + "[maxpool]\nsize=2\nstride=" + (i < 5 ? "2" : "1") + "\n\n";
  cfg += conv(1024, 3, true, "leaky") + conv(1024, 3, true, "leaky") + conv(30, 1, false, "linear");
  cfg += "[region]\nanchors=1.08,1.19, 3.42,4.41, 6.63,11.38, 9.42,5.11, 16.62,10.52\nclasses=1\ncoords=4\nnum=5\n";
  return cfg;
}

const DarknetModel& model(int size) {
  static std::map<int, DarknetModel> models;
  auto it = models.find(size);
  if (it == models.end()) {
    DarknetModel m = parse_darknet_cfg_string(thesis_cfg(size), "thesis-" + std::to_string(size));
    randomize_weights(m, 42);
    it = models.emplace(size, std::move(m)).first;
  }
  return it->second;
}

/// The shipped model with its trained weights, at its cfg's input size (640x352).
const DarknetModel& shipped() {
  static const DarknetModel m = load_model("builtin:wingman-small", "builtin:wingman-small");
  return m;
}

/// Seeded uniform [0, 1) CHW images: `batch` of channels x height x width.
std::vector<float> images(int width, int height, int batch) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<float> v(static_cast<size_t>(3) * width * height * batch);
  for (auto& f : v) f = u(rng);
  return v;
}
std::vector<float> images(int size, int batch) { return images(size, size, batch); }

void run_backend(benchmark::State& state, InferenceBackend& backend, const DarknetModel& m, int batch) {
  const auto input = images(m.net.width, m.net.height, batch);
  std::vector<float> output;
  backend.forward(input.data(), batch, output);  // warm-up
  for (auto _ : state) {
    backend.forward(input.data(), batch, output);
    benchmark::DoNotOptimize(output.data());
  }
  state.counters["GFLOP/s"] =
      benchmark::Counter(m.flops() * batch * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["frames/s"] = benchmark::Counter(batch, benchmark::Counter::kIsIterationInvariantRate);
}
void run_backend(benchmark::State& state, InferenceBackend& backend, int size, int batch) {
  run_backend(state, backend, model(size), batch);
}

void BM_OpenCl(benchmark::State& state) {
  const int size = static_cast<int>(state.range(0)), batch = static_cast<int>(state.range(1));
  OpenClOptions options;
  options.max_batch = batch;
  OpenClBackend backend(model(size), options);
  state.SetLabel(backend.device_name());
  run_backend(state, backend, size, batch);
}

void BM_CpuBackend(benchmark::State& state) {
  const int size = static_cast<int>(state.range(0)), batch = static_cast<int>(state.range(1));
  CpuBackend backend(model(size), batch);
  run_backend(state, backend, size, batch);
}

void BM_OpenClShipped(benchmark::State& state) {
  OpenClBackend backend(shipped(), OpenClOptions{});
  state.SetLabel(backend.device_name());
  run_backend(state, backend, shipped(), 1);
}

void BM_CpuBackendShipped(benchmark::State& state) {
  CpuBackend backend(shipped(), 1);
  run_backend(state, backend, shipped(), 1);
}

/// cv::dnn straight from the .cfg/.weights bytes, forward() to its own output (region decode included).
void BM_BareOpenCvDnn(benchmark::State& state) {
  const int size = static_cast<int>(state.range(0));
  const std::string cfg = write_darknet_cfg(model(size));
  const std::vector<char> weights = serialize_darknet_weights(model(size));
  cv::dnn::Net net = cv::dnn::readNetFromDarknet(cfg.data(), cfg.size(), weights.data(), weights.size());
  net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  const auto input = images(size, 1);
  const int dims[4] = {1, 3, size, size};
  const cv::Mat blob(4, dims, CV_32F, const_cast<float*>(input.data()));
  net.setInput(blob);
  cv::Mat out = net.forward();
  for (auto _ : state) {
    net.setInput(blob);
    out = net.forward();
    benchmark::DoNotOptimize(out.data);
  }
  state.counters["GFLOP/s"] =
      benchmark::Counter(model(size).flops() * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["frames/s"] = benchmark::Counter(1, benchmark::Counter::kIsIterationInvariantRate);
}

void sizes(benchmark::internal::Benchmark* b) {
  for (int s : {416, 320, 256}) b->Args({s, 1});
  b->Args({416, 4});  // zoom-in crops as one batch
  b->Unit(benchmark::kMillisecond)->UseRealTime()->ReportAggregatesOnly(true);
}

BENCHMARK(BM_OpenCl)->Apply(sizes);
BENCHMARK(BM_CpuBackend)->Apply(sizes);
BENCHMARK(BM_BareOpenCvDnn)
    ->Args({416, 1})
    ->Args({320, 1})
    ->Args({256, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->ReportAggregatesOnly(true);
BENCHMARK(BM_OpenClShipped)->Unit(benchmark::kMillisecond)->UseRealTime()->ReportAggregatesOnly(true);
BENCHMARK(BM_CpuBackendShipped)->Unit(benchmark::kMillisecond)->UseRealTime()->ReportAggregatesOnly(true);

/// One line per command of an OpenCL forward: median device time of 10 profiled forwards, share, GFLOP/s.
void print_per_layer(const std::string& label, const DarknetModel& m) {
  OpenClBackend backend(m, OpenClOptions{});
  const auto input = images(m.net.width, m.net.height, 1);
  std::vector<float> output;
  backend.forward(input.data(), 1, output);  // warm-up (program build, first transfers)
  backend.set_profiling(true);
  for (int i = 0; i < 10; ++i) backend.forward(input.data(), 1, output);
  const std::vector<KernelTiming> timings = backend.profile();
  backend.set_profiling(false);
  std::vector<double> medians;
  double total = 0;
  for (const KernelTiming& k : timings) {
    std::vector<double> ms = k.ms;
    std::sort(ms.begin(), ms.end());
    medians.push_back(ms.empty() ? 0.0 : ms[ms.size() / 2]);
    total += medians.back();
  }
  std::printf("per-layer %s on %s: sum of medians %.3f ms\n", label.c_str(), backend.device_name().c_str(), total);
  for (size_t i = 0; i < timings.size(); ++i) {
    const double gflops = timings[i].flops > 0 && medians[i] > 0 ? timings[i].flops / (medians[i] * 1e-3) * 1e-9 : 0;
    std::printf("  %8.3f ms %5.1f %% %8.1f GFLOP/s  %s\n", medians[i], total > 0 ? 100 * medians[i] / total : 0.0,
                gflops, timings[i].what.c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  bool per_layer = false;
  int kept = 0;
  for (int i = 0; i < argc; ++i) {
    if (std::strcmp(argv[i], "--per-layer") == 0) {
      per_layer = true;
      continue;
    }
    argv[kept++] = argv[i];
  }
  argc = kept;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  if (per_layer) {
    print_per_layer("thesis network 416", model(416));
    print_per_layer("thesis network 256", model(256));
    print_per_layer("wingman-small 640x352", shipped());
  }
  return 0;
}
