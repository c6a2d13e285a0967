// SPDX-License-Identifier: MIT
// The localizer's per-box cost: the exact sphere localization of one box as ground truth (ratio 1) and as the shipped
// model's box (the box relation looked up, per-edge radii), side by side. Numbers: docs/benchmarks.md.
#include <benchmark/benchmark.h>
#include <wingman/localizer/box_relation.hpp>
#include <wingman/localizer/sphere_localizer.hpp>
#include <wingman/localizer/sphere_projection.hpp>

namespace {

using namespace wingman::localizer;

struct Scene {
  CameraModel camera = CameraModel::pinhole(1280, 720, 640, 640, 639.5, 359.5);
  PixelBox box;
  SphereLocalizerOptions options;
  Scene() { box = project_sphere(camera, {0.8, -0.4, 8.0}, 0.348).pixel_box(); }
};

void BM_LocalizeSphereBox(benchmark::State& state) {
  const Scene s;
  for (auto _ : state) benchmark::DoNotOptimize(localize_box(s.box, s.camera, s.options));
}
BENCHMARK(BM_LocalizeSphereBox);

void BM_LocalizeCnnBoxWithRelation(benchmark::State& state) {
  const Scene s;
  const BoxRelation relation = BoxRelation::load("builtin:wingman-small");
  for (auto _ : state)
    benchmark::DoNotOptimize(localize_box(s.box, s.camera, s.options, relation.at(s.box.w, s.box.h, 1280)));
}
BENCHMARK(BM_LocalizeCnnBoxWithRelation);

}  // namespace

BENCHMARK_MAIN();
