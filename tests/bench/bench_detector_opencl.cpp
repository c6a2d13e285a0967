// SPDX-License-Identifier: MIT
// The thesis network (random weights) per frame: our OpenCL backend vs CpuBackend vs bare cv::dnn, one run.
//
// Run with POCL_AFFINITY=1 (docs/pocl-performance.md). Counters: GFLOP/s from DarknetModel::flops()
// (convolutions only), per image. Report the median aggregates.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <opencv2/dnn.hpp>
#include <random>
#include <string>
#include <vector>

#include "wingman/detector/cpu_backend.hpp"
#include "wingman/detector/darknet_cfg.hpp"
#include "wingman/detector/darknet_weights.hpp"
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

std::vector<float> images(int size, int batch) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<float> v(static_cast<size_t>(3) * size * size * batch);
  for (auto& f : v) f = u(rng);
  return v;
}

void run_backend(benchmark::State& state, InferenceBackend& backend, int size, int batch) {
  const auto input = images(size, batch);
  std::vector<float> output;
  backend.forward(input.data(), batch, output);  // warm-up
  for (auto _ : state) {
    backend.forward(input.data(), batch, output);
    benchmark::DoNotOptimize(output.data());
  }
  state.counters["GFLOP/s"] =
      benchmark::Counter(model(size).flops() * batch * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["frames/s"] = benchmark::Counter(batch, benchmark::Counter::kIsIterationInvariantRate);
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
  b->Unit(benchmark::kMillisecond)->UseRealTime()->Repetitions(5)->ReportAggregatesOnly(true)->MinTime(0.5);
}

BENCHMARK(BM_OpenCl)->Apply(sizes);
BENCHMARK(BM_CpuBackend)->Apply(sizes);
BENCHMARK(BM_BareOpenCvDnn)
    ->Args({416, 1})
    ->Args({320, 1})
    ->Args({256, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Repetitions(5)
    ->ReportAggregatesOnly(true)
    ->MinTime(0.5);

}  // namespace

BENCHMARK_MAIN();
