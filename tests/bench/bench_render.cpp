// SPDX-License-Identifier: MIT
// The simulator's renderer: milliseconds per 1280x720 frame on Mesa's llvmpipe (EGL, no GPU), for the scene
// variants, supersampling, motion blur and drone count; and the cost of building a renderer (lens map, shaders).
// Run: build/tests/bench_render --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//      (LP_NUM_THREADS sets llvmpipe's thread count; it defaults to the number of cores). "Time" is wall-clock time,
//      "CPU" the CPU time of all the process's threads (what the frame costs, whatever else runs on the machine).
#include <benchmark/benchmark.h>
#include <wingman/sim/renderer.hpp>

namespace {

namespace sim = wingman::sim;
using wingman::geometry::CameraModel;
using wingman::geometry::Distortion;

/// A 1280x720 camera with a Raspberry Pi v2-like barrel lens.
CameraModel camera() {
  return CameraModel(1280, 720, 1000.0, 1000.0, 639.5, 359.5, Distortion::kRadTan, {-0.2, 0.08, 0.001, -0.001, 0.0});
}

Eigen::Isometry3d level_camera() {  // 12 m up, looking north, level
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  T.translation() = Eigen::Vector3d(0.0, 0.0, 12.0);
  return T;
}

/// Args: scene (0 uniform background, 1 sky/ground/trees), supersampling, motion-blur samples (0 off), drones.
void BM_RenderFrame(benchmark::State& state) {
  sim::RenderOptions options;
  if (state.range(0) == 0) options.background = "uniform";
  options.supersampling = static_cast<int>(state.range(1));
  if (state.range(2) > 0) {
    options.motion_blur_exposure_s = 0.01;
    options.motion_blur_samples = static_cast<int>(state.range(2));
  }
  sim::Renderer renderer(camera(), options);
  const sim::DroneModel model = sim::DroneModel::procedural(sim::DroneSpec{});
  std::vector<sim::DroneInstance> drones(static_cast<size_t>(state.range(3)));
  for (size_t i = 0; i < drones.size(); ++i) {
    drones[i].vehicle_id = static_cast<int>(i);
    drones[i].model = &model;
    drones[i].T_body_to_world.translation() = Eigen::Vector3d(-3.0 + 2.0 * i, 8.0 + 3.0 * i, 12.5);
    drones[i].v_body_in_world = Eigen::Vector3d(5.0, 0.0, 0.0);
    drones[i].prop_rate_rad_s = 600.0;
  }
  int64_t utime = 1'700'000'000'000'000;
  uint64_t seed = 1;
  for (auto _ : state) {
    sim::RenderResult result = renderer.render(level_camera(), drones, utime, seed++);
    benchmark::DoNotOptimize(result.bgr.data);
    utime += 33'333;
  }
  state.SetLabel(renderer.gl_renderer());
}
BENCHMARK(BM_RenderFrame)
    ->ArgNames({"scene", "ss", "blur", "drones"})
    ->Args({0, 2, 0, 1})
    ->Args({1, 1, 0, 1})
    ->Args({1, 2, 0, 1})
    ->Args({1, 3, 0, 1})
    ->Args({1, 2, 0, 4})
    ->Args({1, 2, 8, 1})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()  // llvmpipe renders on its own threads: count them all
    ->UseRealTime();

/// Building a renderer: EGL context, shaders, the lens map (one undistortion per pixel corner), render targets.
void BM_RendererConstruction(benchmark::State& state) {
  for (auto _ : state) {
    sim::Renderer renderer(camera(), sim::RenderOptions{});
    benchmark::DoNotOptimize(renderer.pinhole_size().width);
  }
}
BENCHMARK(BM_RendererConstruction)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
