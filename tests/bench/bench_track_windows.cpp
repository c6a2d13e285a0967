// SPDX-License-Identifier: MIT
// Tracker-driven windows: the detector's time per 1280x720 frame with the shipped model (builtin:wingman-small, its
// network 640x352 for this size) on the OpenCL backend, the single pass alone and with 1 and 2 windows (256x256
// full-resolution crops, each through its own 256x256 network), side by side in one run. Run with POCL_AFFINITY=1.
// The image is random texture (the time does not depend on what it shows). Report the median aggregates; the ratio
// windows / single pass is the figure (docs/benchmarks.md, "Tracker-driven windows"). BM_MotionCue1280x720: the motion
// cue's own time per frame (motion.*, its defaults) on a panning sequence, without the windows it proposes.
// The figures are measured with --benchmark_repetitions=7 --benchmark_min_time=0.5 (CTest runs it once, briefly).
#include <benchmark/benchmark.h>

#include "wingman/detector/detector_options.hpp"
#include "wingman/detector/model_loader.hpp"
#include "wingman/detector/motion_cue.hpp"
#include "wingman/detector/sized_detector.hpp"
#include "wingman/detector/track_windows.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <memory>
#include <vector>

namespace {

using namespace wingman::detector;

void BM_DetectFrame1280x720(benchmark::State& state) {
  const int n_windows = static_cast<int>(state.range(0));
  DetectorOptions o;
  o.windows.enabled = true;
  // As the process builds them: batches of up to opencl.max_batch (the windows' crops go in one forward).
  auto make = [&](const DarknetModel& sized) {
    return make_backend("opencl", sized, o.opencl, o.opencl.max_batch, nullptr);
  };
  const DarknetModel model = load_model(o.cfg, o.weights);
  SizedDetector pipeline(o.detection, model, *InputSize::parse(o.input_size), make);
  WindowDetector windows(o.windows, o.detection, model, make);
  cv::Mat image(720, 1280, CV_8UC3);
  cv::theRNG().state = 7;
  cv::randu(image, cv::Scalar::all(0), cv::Scalar::all(255));
  // Windows far apart (each its own crop), as two far tracks would be.
  std::vector<Window> w;
  for (int i = 0; i < n_windows; ++i) w.push_back(Window{300.0 + 600.0 * i, 360, 12, 8, 3, true, i + 1});
  std::vector<Box> boxes = pipeline.detect(image);  // warm-up: networks built, buffers allocated
  if (n_windows > 0) boxes = windows.detect(image, std::move(boxes), w);
  WindowStats stats;
  for (auto _ : state) {
    boxes = pipeline.detect(image);
    if (n_windows > 0) boxes = windows.detect(image, std::move(boxes), w, &stats);
    benchmark::DoNotOptimize(boxes.data());
  }
  state.counters["crops/frame"] = benchmark::Counter(static_cast<double>(stats.crops) /
                                                     static_cast<double>(std::max<int64_t>(1, state.iterations())));
}

BENCHMARK(BM_DetectFrame1280x720)
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->ReportAggregatesOnly(true);

void BM_MotionCue1280x720(benchmark::State& state) {
  // A smooth random texture panned 3 px right and 1 px down a frame (the camera turning), 30 Hz.
  cv::Mat noise(900, 1600, CV_8UC3);
  cv::theRNG().state = 7;
  cv::randu(noise, cv::Scalar::all(0), cv::Scalar::all(255));
  cv::Mat scene;
  cv::GaussianBlur(noise, scene, cv::Size(0, 0), 5.0);
  cv::normalize(scene, scene, 0, 255, cv::NORM_MINMAX);  // cloud-like contrast: the alignment has texture to work on
  std::vector<cv::Mat> frames;
  for (int k = 0; k < 60; ++k) frames.push_back(scene(cv::Rect(3 * k, k, 1280, 720)).clone());
  MotionCue cue(MotionOptions{});
  int64_t utime = 0;
  const size_t n = frames.size();
  size_t k = 0;
  const auto next = [&] {
    utime += 33333;
    // Forth and back over the frames: the pan reverses at the ends, as a camera turning back would.
    const size_t i = k++ % (2 * n - 2);
    return cue.find(frames[i < n ? i : 2 * n - 2 - i], utime, {});
  };
  // Warm-up: the 2 lag_frames frames before the first comparison (every timed frame compares).
  for (int i = 0; i <= 2 * MotionOptions{}.lag_frames; ++i) next();
  for (auto _ : state) {
    benchmark::DoNotOptimize(next());
  }
  state.counters["compared/frame"] =
      static_cast<double>(cue.stats().compared) / static_cast<double>(std::max<int64_t>(1, cue.stats().frames));
}

BENCHMARK(BM_MotionCue1280x720)->Unit(benchmark::kMillisecond)->UseRealTime()->ReportAggregatesOnly(true);

}  // namespace

BENCHMARK_MAIN();
