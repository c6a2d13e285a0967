// SPDX-License-Identifier: MIT
// `wingman bench detector`: per-frame timings of the thesis network on our backends vs bare OpenCV DNN, one run.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace wingman::tools {

/// Options of `wingman bench detector`. A benchmark, not a test: nothing here is asserted.
struct BenchDetectorOptions {
  /// Network input sizes: "N" (N x N) or "WxH", pixels, each side a multiple of 32 and >= 32; "cfg" = the
  /// network's own [net] width x height.
  std::vector<std::string> sizes{"416", "320", "256"};
  std::vector<int> threads{1, 2};                ///< CPU thread counts for OpenCV (cv::setNumThreads), each >= 1
  int repetitions = 7;                           ///< timed runs per measurement (median/min/max over these), >= 1
  int warmup = 2;                                ///< untimed runs before each measurement, >= 0
  bool json = false;                             ///< print one JSON object instead of the table
  std::string cfg = "builtin:tiny-yolo-thesis";  ///< network: a .cfg path or builtin:<name> (detector::load_model)
  std::string weights;         ///< Darknet .weights (path or builtin:<name>); "" = random weights, `seed`
  uint32_t seed = 42;          ///< seed of the random weights
  int stream_width = 1280;     ///< width of the synthetic BGR stream for the pipeline, pixels, >= 32
  int stream_height = 720;     ///< height of the synthetic BGR stream for the pipeline, pixels, >= 32
  int pipeline_max_batch = 4;  ///< backends' max_batch in the pipeline (zoom-in crops per forward), >= 1
  bool pipeline = true;        ///< also time DetectionPipeline::detect() (slow: zoom-in on the CPU)
  bool layers = true;          ///< also profile the OpenCL backend per layer (`repetitions` more runs)

  /// One "field = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
};

/// Milliseconds of `runs` timed runs.
struct TimingMs {
  double median = 0;
  double min = 0;
  double max = 0;
  int runs = 0;
};

/// One backend's forward pass (batch 1) at one size and thread count.
struct ForwardResult {
  std::string backend;        ///< "opencl", "cpu" (CpuBackend) or "opencv-dnn" (bare cv::dnn)
  std::string device;         ///< backend's own name (OpenCL device) or ""
  std::string size;           ///< network input: "416" (square) or "640x352" (width x height)
  int threads = 0;            ///< threads it ran with (OpenCL: the environment's, see `threads_note`)
  std::string threads_note;   ///< how `threads` was set: "cv::setNumThreads" or "POCL_MAX_PTHREAD_COUNT=..."
  TimingMs ms;                ///< per frame
  double gflop_per_s = 0;     ///< DarknetModel::flops() / median
  double speedup_vs_dnn = 0;  ///< bare OpenCV DNN median / this median at the same size and threads (0 = none)
  std::string error;          ///< non-empty when the backend could not run (then the numbers are 0)
};

/// One command of the OpenCL backend's forward (a layer's kernel, or moving the input or output), batch 1.
struct LayerResult {
  std::string size;        ///< network input: "416" (square) or "640x352" (width x height)
  int layer = -1;          ///< model layer index, -1 for input/output commands
  std::string what;        ///< e.g. "layer 13 [convolutional] (cfg line 123)"
  TimingMs ms;             ///< device time (OpenCL profiling events) per forward
  double gflop_per_s = 0;  ///< convolutions: FLOP / median
  double share = 0;        ///< median / sum of the medians of all commands at this size
};

/// DetectionPipeline::detect() on the synthetic stream, one backend, zoom-in and flip fusion each on or off.
struct PipelineResult {
  std::string backend;              ///< "opencl" or "cpu"
  std::string size;                 ///< network input: "416" (square) or "640x352" (width x height)
  int threads = 0;                  ///< threads (as in ForwardResult)
  bool zoom_in = false;             ///< DetectorPipelineOptions::zoom_in
  bool flip_fusion = false;         ///< DetectorPipelineOptions::flip_fusion (a second, mirrored pass)
  bool coarse_pass = false;         ///< DetectorPipelineOptions::coarse_pass (the pass at coarse_scale)
  TimingMs ms;                      ///< per frame (one detect() call)
  double frames_per_s = 0;          ///< 1000 / median
  double forwards_per_frame = 0;    ///< backend.forward() calls per frame, mean
  double images_per_frame = 0;      ///< network images per frame (sum of batch sizes), mean
  double detections_per_frame = 0;  ///< boxes detect() returned, mean
  double non_forward_share = 0;     ///< (detect time - forward time) / detect time, summed over the timed frames
  std::string error;                ///< non-empty when it could not run
};

/// Where it ran.
struct MachineInfo {
  std::string cpu_model;                    ///< "model name" of /proc/cpuinfo
  int cores = 0;                            ///< std::thread::hardware_concurrency()
  std::vector<std::string> opencl_devices;  ///< list_opencl_devices()
  std::string pocl_affinity;                ///< POCL_AFFINITY or "(unset)"
  std::string pocl_max_pthread_count;       ///< POCL_MAX_PTHREAD_COUNT or "(unset)"
  std::string opencv_version;               ///< CV_VERSION
};

/// Everything one `wingman bench detector` run measured.
struct BenchDetectorReport {
  MachineInfo machine;
  std::string cfg;      ///< the network's cfg (path or builtin:<name>)
  std::string weights;  ///< "random (seed N)" or the .weights path
  int repetitions = 0;
  int warmup = 0;
  int stream_width = 0;   ///< synthetic stream of the pipeline rows, pixels
  int stream_height = 0;  ///< likewise
  std::vector<ForwardResult> forward;
  std::vector<LayerResult> layers;  ///< OpenCL per layer, per size (empty with options.layers off)
  std::vector<PipelineResult> pipeline;

  /// Readable tables with the machine details and notes.
  std::string table() const;
  /// One JSON object.
  std::string json() const;
};

/// Runs the benchmark; one progress line per measurement on `progress` (if not null).
/// Throws on unreadable weights; a backend that cannot be created is reported in its rows' `error`.
/// Precondition: options.validate() is empty.
BenchDetectorReport run_bench_detector(const BenchDetectorOptions& options, std::ostream* progress);

/// The verb: validates, runs, prints the table or JSON on `out`, progress and errors on `err`.
/// Returns 0, 1 when it failed, 2 on bad options.
int run_bench_detector_verb(const BenchDetectorOptions& options, std::ostream& out, std::ostream& err);

}  // namespace wingman::tools
