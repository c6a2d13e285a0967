// SPDX-License-Identifier: MIT
// Camera images on the bus, per 1280x720 frame: what each transport costs the camera driver (output.encoding mjpeg:
// the JPEG encode; output.max_width 640: the downscale) and the detector (detector::image_to_bgr: raw copy or MJPEG
// decode), on the fixed-seed scene of the unit tests. docs/benchmarks.md, "Camera images on the bus".
// Run: build/tests/bench_mjpeg_transport --benchmark_repetitions=7 --benchmark_report_aggregates_only=true
#include "test_video.hpp"

#include <benchmark/benchmark.h>
#include <wingman/camera_driver/camera_driver.hpp>
#include <wingman/detector/preprocess.hpp>

#include <cstring>

namespace {

namespace cd = wingman::camera_driver;

cd::Frame scene_frame(int width, int height) {
  const cv::Mat scene = cd::testing::seeded_scene(width, height, 31);
  cd::Frame f;
  f.utime = 1'700'000'000'000'000;
  f.seq = 1;
  f.width = width;
  f.height = height;
  f.stride = width * 3;
  f.format = cd::PixelFormat::kBgr8;
  f.data.resize(static_cast<size_t>(f.stride) * static_cast<size_t>(height));
  for (int r = 0; r < height; ++r)
    std::memcpy(f.data.data() + static_cast<size_t>(r) * static_cast<size_t>(f.stride), scene.ptr(r),
                static_cast<size_t>(f.stride));
  return f;
}

/// The camera driver's encode at quality state.range(0): bytes per frame as a counter.
void BM_DriverEncodeMjpeg(benchmark::State& state) {
  const cd::Frame raw = scene_frame(1280, 720);
  cd::Frame jpeg;
  for (auto _ : state) {
    if (!cd::encode_mjpeg(raw, static_cast<int>(state.range(0)), jpeg).empty()) state.SkipWithError("encode failed");
    benchmark::DoNotOptimize(jpeg.data.data());
  }
  state.counters["bytes"] = static_cast<double>(jpeg.data.size());
}
BENCHMARK(BM_DriverEncodeMjpeg)->Arg(90)->Arg(75)->Unit(benchmark::kMillisecond);

/// The camera driver's downscale to 640 px wide (output.max_width).
void BM_DriverDownscale640(benchmark::State& state) {
  const cd::Frame raw = scene_frame(1280, 720);
  cd::Frame small;
  for (auto _ : state) {
    cd::downscale_frame(raw, 640, small);
    benchmark::DoNotOptimize(small.data.data());
  }
  state.counters["bytes"] = static_cast<double>(small.data.size());
}
BENCHMARK(BM_DriverDownscale640)->Unit(benchmark::kMillisecond);

/// The detector's image_t -> BGR of each transport: raw 1280x720 (a copy), MJPEG q90 (decode), raw 640x360.
void BM_DetectorImageToBgr(benchmark::State& state) {
  const cd::Frame raw = scene_frame(1280, 720);
  cd::Frame in = raw;
  if (state.range(0) == 1) cd::encode_mjpeg(raw, 90, in);
  if (state.range(0) == 2) cd::downscale_frame(raw, 640, in);
  const wingman::image_t msg = cd::to_image_message(in, 0);
  for (auto _ : state) {
    std::string error;
    cv::Mat bgr = wingman::detector::image_to_bgr(msg, &error);
    if (bgr.empty()) state.SkipWithError(error.c_str());
    benchmark::DoNotOptimize(bgr.data);
  }
  state.SetLabel(state.range(0) == 0 ? "raw 1280x720" : state.range(0) == 1 ? "mjpeg q90 1280x720" : "raw 640x360");
}
BENCHMARK(BM_DetectorImageToBgr)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
