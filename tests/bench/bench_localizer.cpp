// SPDX-License-Identifier: MIT
// The localizer's per-box cost: the exact sphere localization of one box as ground truth (ratio 1) and as the shipped
// model's box (the box relation looked up, per-edge radii), side by side; and one track's window for the next frame
// (tracker-driven windows: up to windows.max_windows per detections message); and a whole exposure through the
// Localizer (boxes, world frame, tracker, targets): one camera's detections_t against a four-camera rig's four.
// Numbers: docs/benchmarks.md.
#include <benchmark/benchmark.h>
#include <wingman/geometry/sphere_projection.hpp>
#include <wingman/localizer/box_relation.hpp>
#include <wingman/localizer/localizer.hpp>
#include <wingman/localizer/sphere_localizer.hpp>
#include <wingman/localizer/track_windows.hpp>

#include "../localizer/rig_scene.hpp"
#include "../localizer/sphere_scene.hpp"
#include "../support/test_support.hpp"

#include <cmath>
#include <memory>
#include <vector>

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

/// The exposures of a target circling the vehicle at 8 m (one turn in 12 s, 30 frames/s, ground-truth boxes) as `rig`
/// sees them, fed to a Localizer with own poses: per iteration one exposure (every camera's detections_t) in, its
/// targets_t out. After the prepared frames it starts again with a new Localizer (not timed).
void run_exposures(benchmark::State& state, const wingman::geometry::CameraRig& rig, bool as_rig) {
  using wingman::localizer::testing::RigScene;
  constexpr int kFrames = 3600;
  constexpr int64_t kT0 = 1700000000000000, kFrameUs = 33333;
  const RigScene scene(rig);
  std::vector<std::vector<wingman::detections_t>> frames(kFrames);
  for (int k = 0; k < kFrames; ++k) {
    const double a = 2.0 * M_PI * k / 360.0;
    const Eigen::Vector3d p(8.0 * std::cos(a), 8.0 * std::sin(a), 0.3);
    for (size_t i = 0; i < scene.models.size(); ++i) frames[k].push_back(scene.detections(i, kT0 + kFrameUs * k, {p}));
  }
  LocalizerOptions options;
  options.sphere.box_relation = "sphere";
  if (as_rig) options.cameras.rig = rig.source;
  std::unique_ptr<Localizer> loc;
  int k = kFrames;
  for (auto _ : state) {
    if (k == kFrames) {
      state.PauseTiming();
      loc = as_rig ? std::make_unique<Localizer>(options, rig)
                   : std::make_unique<Localizer>(options, scene.models.front());
      k = 0;
      state.ResumeTiming();
    }
    const int64_t t = kT0 + kFrameUs * k;
    loc->on_own_pose(wingman::localizer::testing::own_pose(t));
    if (as_rig) {
      for (const wingman::detections_t& d : frames[k]) benchmark::DoNotOptimize(loc->add_detections(d));
    } else {
      benchmark::DoNotOptimize(loc->on_detections(frames[k].front()));
    }
    ++k;
  }
}

void BM_ExposureOneCamera(benchmark::State& state) {
  wingman::geometry::CameraRig forward =
      wingman::geometry::load_camera_rig(wingman::testing::source_path("config/rigs/surround4.yaml"));
  forward.cameras.resize(1);  // the forward camera: it sees the target a quarter of the turn
  run_exposures(state, forward, false);
}
BENCHMARK(BM_ExposureOneCamera);

void BM_ExposureFourCameraRig(benchmark::State& state) {
  run_exposures(state, wingman::geometry::load_camera_rig(wingman::testing::source_path("config/rigs/surround4.yaml")),
                true);
}
BENCHMARK(BM_ExposureFourCameraRig);

}  // namespace

BENCHMARK_MAIN();
