// SPDX-License-Identifier: MIT
// The localizer's per-box cost: the exact sphere localization of one box as ground truth (ratio 1) and as the shipped
// model's box (the box relation looked up, per-edge radii), side by side; and one track's window for the next frame
// (tracker-driven windows: up to windows.max_windows per detections message). Numbers: docs/benchmarks.md.
#include <benchmark/benchmark.h>
#include <wingman/geometry/sphere_projection.hpp>
#include <wingman/localizer/box_relation.hpp>
#include <wingman/localizer/sphere_localizer.hpp>
#include <wingman/localizer/track_windows.hpp>

namespace {

using namespace wingman::localizer;
using wingman::geometry::CameraModel;
using wingman::geometry::PixelBox;
using wingman::geometry::project_sphere;

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

void BM_PredictTrackWindow(benchmark::State& state) {
  const Scene s;
  const BoxRelation relation = BoxRelation::load("builtin:wingman-small");
  TrackOutput track;  // 20 m ahead of a camera at the origin looking along the world's x (the camera's z)
  track.p_target_in_world = Eigen::Vector3d(20.0, 1.0, -0.5);
  track.v_target_in_world = Eigen::Vector3d(0.0, 1.0, 0.0);
  track.cov_p = 0.04 * Eigen::Matrix3d::Identity();
  CameraAtExposure cam;
  cam.R_cam_to_world << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  for (auto _ : state) benchmark::DoNotOptimize(predict_track_window(track, 0.348, s.camera, cam, relation));
}
BENCHMARK(BM_PredictTrackWindow);

}  // namespace

BENCHMARK_MAIN();
