// SPDX-License-Identifier: MIT
// `wingman bench detector`: a network (default: the thesis network) per frame on OpenCL, CpuBackend and bare OpenCV
// DNN; the pipeline.
#include "wingman/tools/bench.hpp"

#include <fmt/format.h>
#include <wingman/common/json.hpp>
#include <wingman/common/progress.hpp>
#include <wingman/detector/cpu_backend.hpp>
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>
#include <wingman/detector/detection_pipeline.hpp>
#include <wingman/detector/input_size.hpp>
#include <wingman/detector/model_loader.hpp>
#include <wingman/detector/opencl_backend.hpp>
#include <wingman/detector/opencl_device.hpp>
#include <wingman/detector/preprocess.hpp>

#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/core/version.hpp>
#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>

namespace wingman::tools {

namespace {

using detector::DarknetModel;
using detector::InferenceBackend;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

TimingMs summarize(std::vector<double> ms) {
  TimingMs t;
  if (ms.empty()) return t;
  std::sort(ms.begin(), ms.end());
  const size_t n = ms.size();
  t.median = n % 2 == 1 ? ms[n / 2] : 0.5 * (ms[n / 2 - 1] + ms[n / 2]);
  t.min = ms.front();
  t.max = ms.back();
  t.runs = static_cast<int>(n);
  return t;
}

std::string env_or_unset(const char* name) {
  const char* v = std::getenv(name);
  return v ? std::string(v) : std::string("(unset)");
}

std::string cpu_model_name() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(" \t", colon + 1));
    }
  }
  return "(unknown)";
}

/// A size option other than "cfg" ("416" for 416x416, or "640x352") as width x height, read as model.input_size's
/// WxH (detector::InputSize: each side a multiple of 32, 32..4096); {-1, -1} when malformed.
cv::Size parse_size(const std::string& text) {
  const bool square = !text.empty() && text.find('x') == std::string::npos;
  const std::optional<detector::InputSize> size = detector::InputSize::parse(square ? text + "x" + text : text);
  return size && size->mode == detector::InputSize::Mode::kFixed ? size->fixed : cv::Size(-1, -1);
}

/// "416" for a square input, else "640x352".
std::string size_label(int width, int height) {
  return width == height ? std::to_string(width) : fmt::format("{}x{}", width, height);
}

/// The network (`o.cfg`, the thesis network by default) at `size` ("N", "WxH" or "cfg"): its cfg with [net]
/// width/height changed (kept for "cfg").
DarknetModel bench_model(const std::string& size, const BenchDetectorOptions& o) {
  DarknetModel m = detector::load_cfg(o.cfg);
  if (size != "cfg") {
    const cv::Size net = parse_size(size);
    m.net.width = net.width;
    m.net.height = net.height;
  }
  detector::compute_shapes(m);
  if (o.weights.empty())
    detector::randomize_weights(m, o.seed);
  else
    detector::load_weights(m, o.weights);
  return m;
}

/// Frame `i` of the synthetic stream: a diagonal grey-blue gradient with a dark blob (a drone-ish
/// silhouette) moving left to right.
cv::Mat synthetic_frame(int width, int height, int i) {
  cv::Mat bgr(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    auto* row = bgr.ptr<cv::Vec3b>(y);
    for (int x = 0; x < width; ++x) {
      const int g = 90 + 120 * (x + y) / (width + height);
      row[x] = cv::Vec3b(static_cast<uchar>(std::min(255, g + 40)), static_cast<uchar>(g), static_cast<uchar>(g - 20));
    }
  }
  const cv::Point centre(width / 4 + (i * width / 16) % (width / 2), height / 2);
  const int r = std::max(4, height / 12);
  cv::ellipse(bgr, centre, cv::Size(r * 2, r / 2), 0, 0, 360, cv::Scalar(25, 25, 30), cv::FILLED);
  cv::circle(bgr, centre - cv::Point(r * 2, r / 2), r / 2, cv::Scalar(20, 20, 20), cv::FILLED);
  cv::circle(bgr, centre + cv::Point(r * 2, -r / 2), r / 2, cv::Scalar(20, 20, 20), cv::FILLED);
  return bgr;
}

/// Counts and times the forwards of the backend it wraps (the pipeline owns it; the stats outlive it).
struct ForwardStats {
  double ms = 0;
  int64_t calls = 0;
  int64_t images = 0;
};

class TimedBackend : public InferenceBackend {
 public:
  TimedBackend(std::unique_ptr<InferenceBackend> inner, ForwardStats* stats)
      : inner_(std::move(inner)), stats_(stats) {}
  std::string name() const override { return inner_->name(); }
  detector::Shape input_shape() const override { return inner_->input_shape(); }
  std::vector<detector::Shape> output_shapes() const override { return inner_->output_shapes(); }
  int max_batch() const override { return inner_->max_batch(); }
  void forward(const float* input, int batch, std::vector<float>& output) override {
    const auto t0 = Clock::now();
    inner_->forward(input, batch, output);
    stats_->ms += ms_since(t0);
    stats_->calls += 1;
    stats_->images += batch;
  }

 private:
  std::unique_ptr<InferenceBackend> inner_;
  ForwardStats* stats_;
};

common::Json json_timing(const TimingMs& t) {
  return {{"median", t.median}, {"min", t.min}, {"max", t.max}, {"runs", t.runs}};
}

ForwardResult forward_row(const std::string& backend, const std::string& size, int threads, const std::string& note) {
  ForwardResult r;
  r.backend = backend;
  r.size = size;
  r.threads = threads;
  r.threads_note = note;
  return r;
}

/// The OpenCL thread count PoCL's pthread device uses: POCL_MAX_PTHREAD_COUNT, else all cores.
int pocl_threads(int cores) {
  const char* v = std::getenv("POCL_MAX_PTHREAD_COUNT");
  if (v) {
    const int n = std::atoi(v);
    if (n > 0) return std::min(n, cores);
  }
  return cores;
}

}  // namespace

std::vector<std::string> BenchDetectorOptions::validate() const {
  std::vector<std::string> p;
  if (sizes.empty()) p.push_back("sizes = (empty): give at least one size");
  for (const std::string& s : sizes) {
    if (s == "cfg") continue;
    if (parse_size(s).width < 0)
      p.push_back(fmt::format("sizes = {}: expected N or WxH (each a multiple of 32, 32..4096) or cfg", s));
  }
  if (threads.empty()) p.push_back("threads = (empty): give at least one thread count");
  for (const int t : threads)
    if (t < 1) p.push_back(fmt::format("threads = {}: each must be >= 1", t));
  if (repetitions < 1) p.push_back(fmt::format("repetitions = {}: must be >= 1", repetitions));
  if (warmup < 0) p.push_back(fmt::format("warmup = {}: must be >= 0", warmup));
  if (stream_width < 32) p.push_back(fmt::format("stream_width = {}: must be >= 32", stream_width));
  if (stream_height < 32) p.push_back(fmt::format("stream_height = {}: must be >= 32", stream_height));
  if (pipeline_max_batch < 1) p.push_back(fmt::format("pipeline_max_batch = {}: must be >= 1", pipeline_max_batch));
  return p;
}

BenchDetectorReport run_bench_detector(const BenchDetectorOptions& o, std::ostream* progress) {
  BenchDetectorReport report;
  report.repetitions = o.repetitions;
  report.warmup = o.warmup;
  report.stream_width = o.stream_width;
  report.stream_height = o.stream_height;
  report.weights = o.weights.empty() ? fmt::format("random (seed {})", o.seed) : o.weights;
  report.cfg = o.cfg;
  MachineInfo& m = report.machine;
  m.cpu_model = cpu_model_name();
  m.cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  try {
    m.opencl_devices = detector::list_opencl_devices();
  } catch (const std::exception& e) {
    m.opencl_devices.push_back(std::string("(none: ") + e.what() + ")");
  }
  m.pocl_affinity = env_or_unset("POCL_AFFINITY");
  m.pocl_max_pthread_count = env_or_unset("POCL_MAX_PTHREAD_COUNT");
  m.opencv_version = CV_VERSION;

  const int saved_threads = cv::getNumThreads();
  const int max_threads = *std::max_element(o.threads.begin(), o.threads.end());
  const int ocl_threads = pocl_threads(m.cores);
  const std::string ocl_note = fmt::format("POCL_MAX_PTHREAD_COUNT={}", m.pocl_max_pthread_count);
  auto say = [&](const std::string& line) {
    if (progress) *progress << "wingman bench detector: " << line << std::endl;
  };

  std::vector<cv::Mat> stream;
  for (int i = 0; i < 8; ++i) stream.push_back(synthetic_frame(o.stream_width, o.stream_height, i));
  // Steps: per size, the forward rows and the layer profile, then the 12 pipeline rows.
  const int64_t steps_per_size = 1 + (o.layers ? 1 : 0) + (o.pipeline ? 12 : 0);
  common::Progress steps("wingman bench detector", steps_per_size * static_cast<int64_t>(o.sizes.size()),
                         "measurements", progress);

  for (const std::string& size_option : o.sizes) {
    const DarknetModel model = bench_model(size_option, o);
    const double flops = model.flops();
    const cv::Size net(model.net.width, model.net.height);
    const std::string size = size_label(net.width, net.height);
    // The same frame for every backend: our CHW input, and the net-sized BGR image for bare cv::dnn.
    std::vector<float> chw(static_cast<size_t>(3) * net.area());
    cv::Mat resized;
    detector::to_network_input(stream[0], cv::Rect(0, 0, o.stream_width, o.stream_height), net, resized, chw.data());
    cv::Mat net_bgr;
    cv::resize(stream[0], net_bgr, net, 0, 0, cv::INTER_LINEAR);

    auto finish = [&](ForwardResult r) {
      if (r.error.empty() && r.ms.median > 0) r.gflop_per_s = flops / (r.ms.median * 1e-3) * 1e-9;
      say(r.error.empty()
              ? fmt::format("{:>10} {} px, {} thread(s): median {:.2f} ms", r.backend, size, r.threads, r.ms.median)
              : fmt::format("{:>10} {} px: {}", r.backend, size, r.error));
      report.forward.push_back(std::move(r));
    };

    // Every row's runner, created first; then the rows take turns, one forward each per round, so that
    // load from elsewhere on the machine hits every row alike.
    struct Row {
      ForwardResult result;
      std::function<void()> run;
      std::vector<double> ms;
    };
    std::vector<Row> rows;
    // Bare OpenCV DNN: readNetFromDarknet on the same cfg + weights bytes, blobFromImage + forward timed.
    const std::string cfg_text = detector::write_darknet_cfg(model);
    const std::vector<char> weight_bytes = detector::serialize_darknet_weights(model);
    cv::dnn::Net dnn;
    cv::Mat dnn_out;
    std::string dnn_error;
    try {
      dnn = cv::dnn::readNetFromDarknet(cfg_text.data(), cfg_text.size(), weight_bytes.data(), weight_bytes.size());
      dnn.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
      dnn.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
    } catch (const std::exception& e) {
      dnn_error = e.what();
    }
    for (const int t : o.threads) {
      Row row{forward_row("opencv-dnn", size, t, "cv::setNumThreads"), nullptr, {}};
      row.result.error = dnn_error;
      row.run = [&dnn, &dnn_out, &net_bgr, t] {
        cv::setNumThreads(t);
        dnn.setInput(cv::dnn::blobFromImage(net_bgr, 1.0 / 255.0, cv::Size(), cv::Scalar(), true, false, CV_32F));
        dnn_out = dnn.forward();
      };
      rows.push_back(std::move(row));
    }
    // CpuBackend (our wrapper of cv::dnn).
    std::unique_ptr<detector::CpuBackend> cpu;
    std::vector<float> cpu_out;
    std::string cpu_error;
    try {
      cpu = std::make_unique<detector::CpuBackend>(model, 1);
    } catch (const std::exception& e) {
      cpu_error = e.what();
    }
    for (const int t : o.threads) {
      Row row{forward_row("cpu", size, t, "cv::setNumThreads"), nullptr, {}};
      row.result.error = cpu_error;
      if (cpu) row.result.device = cpu->name();
      row.run = [&cpu, &cpu_out, &chw, t] {
        cv::setNumThreads(t);
        cpu->forward(chw.data(), 1, cpu_out);
      };
      rows.push_back(std::move(row));
    }
    // OpenCL: PoCL fixes its thread count at platform init, so one row, with the environment's count.
    std::unique_ptr<detector::OpenClBackend> ocl;
    std::vector<float> ocl_out;
    {
      Row row{forward_row("opencl", size, ocl_threads, ocl_note), nullptr, {}};
      try {
        detector::OpenClOptions options;
        options.max_batch = 1;
        ocl = std::make_unique<detector::OpenClBackend>(model, options);
        row.result.device = ocl->device_name();
      } catch (const std::exception& e) {
        row.result.error = e.what();
      }
      row.run = [&ocl, &ocl_out, &chw] { ocl->forward(chw.data(), 1, ocl_out); };
      rows.push_back(std::move(row));
    }
    auto run_row = [&](Row& row, bool timed) {
      if (!row.result.error.empty()) return;
      try {
        const auto t0 = Clock::now();
        row.run();
        if (timed) row.ms.push_back(ms_since(t0));
      } catch (const std::exception& e) {
        row.result.error = e.what();
      }
    };
    for (int i = 0; i < o.warmup; ++i)
      for (Row& row : rows) run_row(row, false);
    for (int i = 0; i < o.repetitions; ++i)
      for (Row& row : rows) run_row(row, true);
    for (Row& row : rows) {
      if (row.result.error.empty()) row.result.ms = summarize(row.ms);
      finish(std::move(row.result));
    }
    steps.step();

    // Per-layer device times of the OpenCL backend (OpenCL profiling events), after the timed rounds.
    if (o.layers && ocl) {
      try {
        ocl->set_profiling(true);
        for (int i = 0; i < o.repetitions; ++i) ocl->forward(chw.data(), 1, ocl_out);
        const std::vector<detector::KernelTiming> timings = ocl->profile();
        ocl->set_profiling(false);
        double total = 0;
        std::vector<LayerResult> layers;
        for (const detector::KernelTiming& k : timings) {
          LayerResult l;
          l.size = size;
          l.what = k.what;
          l.layer = k.layer;
          l.ms = summarize(k.ms);
          l.gflop_per_s = k.flops > 0 && l.ms.median > 0 ? k.flops / (l.ms.median * 1e-3) * 1e-9 : 0;
          total += l.ms.median;
          layers.push_back(std::move(l));
        }
        for (LayerResult& l : layers) {
          l.share = total > 0 ? l.ms.median / total : 0;
          report.layers.push_back(std::move(l));
        }
        say(fmt::format("opencl {} px: per-layer profile, sum of medians {:.2f} ms", size, total));
      } catch (const std::exception& e) {
        say(fmt::format("opencl {} px: per-layer profile failed: {}", size, e.what()));
      }
    }
    if (o.layers) steps.step();
  }
  // Speed-up vs bare OpenCV DNN at the same size and thread count (OpenCL: the DNN row with its thread
  // count, else the one with the most threads).
  for (ForwardResult& r : report.forward) {
    if (!r.error.empty() || r.ms.median <= 0) continue;
    const ForwardResult* best = nullptr;
    for (const ForwardResult& d : report.forward) {
      if (d.backend != "opencv-dnn" || d.size != r.size || !d.error.empty() || d.ms.median <= 0) continue;
      if (d.threads == r.threads) {
        best = &d;
        break;
      }
      if (r.backend == "opencl" && (!best || d.threads > best->threads)) best = &d;
    }
    if (best) r.speedup_vs_dnn = best->ms.median / r.ms.median;
  }

  // Whole pipeline on the synthetic stream, per size, OpenCL and CpuBackend (most threads), zoom-in off/on, each
  // with flip fusion off/on; then the coarse pass alone and with both.
  cv::setNumThreads(max_threads);
  for (const std::string& size_option : o.pipeline ? o.sizes : std::vector<std::string>{}) {
    const DarknetModel model = bench_model(size_option, o);
    const std::string size = size_label(model.net.width, model.net.height);
    for (const std::string kind : {"opencl", "cpu"}) {
      for (const int mode : {0, 1, 2, 3, 4, 7}) {
        const bool zoom = (mode & 1) != 0, flip = (mode & 2) != 0, coarse = (mode & 4) != 0;
        const std::string label = fmt::format("pipeline {} {} px zoom-in {} flip fusion {} coarse pass {}", kind, size,
                                              zoom ? "on" : "off", flip ? "on" : "off", coarse ? "on" : "off");
        PipelineResult r;
        r.backend = kind;
        r.size = size;
        r.threads = kind == "opencl" ? ocl_threads : max_threads;
        r.zoom_in = zoom;
        r.flip_fusion = flip;
        r.coarse_pass = coarse;
        try {
          ForwardStats stats;  // both pipelines' forwards with the coarse pass
          auto timed_backend = [&](const DarknetModel& m) -> std::unique_ptr<InferenceBackend> {
            std::unique_ptr<InferenceBackend> inner;
            if (kind == "opencl") {
              detector::OpenClOptions ocl;
              ocl.max_batch = o.pipeline_max_batch;
              inner = std::make_unique<detector::OpenClBackend>(m, ocl);
            } else {
              inner = std::make_unique<detector::CpuBackend>(m, o.pipeline_max_batch);
            }
            return std::make_unique<TimedBackend>(std::move(inner), &stats);
          };
          detector::DetectorPipelineOptions popt;
          popt.zoom_in = zoom;
          popt.flip_fusion = flip;
          popt.coarse_pass = coarse;
          std::unique_ptr<detector::DetectionPipeline> coarse_pipeline;
          if (coarse) {  // as SizedDetector builds it: the same weights at coarse_net_size()
            DarknetModel small = model;
            const cv::Size coarse_net =
                detector::coarse_net_size(cv::Size(model.net.width, model.net.height), popt.coarse_scale);
            small.net.width = coarse_net.width;
            small.net.height = coarse_net.height;
            detector::compute_shapes(small);
            coarse_pipeline = std::make_unique<detector::DetectionPipeline>(detector::coarse_pass_options(popt),
                                                                            timed_backend(small), small);
          }
          detector::DetectionPipeline pipeline(popt, timed_backend(model), model, std::move(coarse_pipeline));
          size_t frame = 0;
          int64_t boxes = 0;
          for (int i = 0; i < o.warmup; ++i) pipeline.detect(stream[frame++ % stream.size()]);
          stats = ForwardStats{};
          std::vector<double> ms;
          for (int i = 0; i < o.repetitions; ++i) {
            const auto t0 = Clock::now();
            boxes += static_cast<int64_t>(pipeline.detect(stream[frame++ % stream.size()]).size());
            ms.push_back(ms_since(t0));
          }
          r.ms = summarize(ms);
          double total = 0;
          for (const double v : ms) total += v;
          const double n = o.repetitions;
          r.frames_per_s = r.ms.median > 0 ? 1000.0 / r.ms.median : 0;
          r.forwards_per_frame = static_cast<double>(stats.calls) / n;
          r.images_per_frame = static_cast<double>(stats.images) / n;
          r.detections_per_frame = static_cast<double>(boxes) / n;
          r.non_forward_share = total > 0 ? std::max(0.0, (total - stats.ms) / total) : 0;
          say(fmt::format("{}: median {:.2f} ms/frame", label, r.ms.median));
        } catch (const std::exception& e) {
          r.error = e.what();
          say(fmt::format("{}: {}", label, r.error));
        }
        report.pipeline.push_back(std::move(r));
        steps.step();
      }
    }
  }
  steps.finish();
  cv::setNumThreads(saved_threads);
  return report;
}

std::string BenchDetectorReport::table() const {
  std::ostringstream s;
  s << "wingman bench detector: network " << cfg << ", weights " << weights << "\n";
  s << fmt::format("machine: {}, {} cores; OpenCV {}\n", machine.cpu_model, machine.cores, machine.opencv_version);
  for (const auto& d : machine.opencl_devices) s << "OpenCL device: " << d << "\n";
  s << fmt::format("POCL_AFFINITY={}  POCL_MAX_PTHREAD_COUNT={}\n", machine.pocl_affinity,
                   machine.pocl_max_pthread_count);
  s << fmt::format("{} warm-up + {} timed runs per row; ms per frame (batch 1)\n\n", warmup, repetitions);
  s << fmt::format("{:<11} {:>7} {:>7} {:>9} {:>9} {:>9} {:>8} {:>8}\n", "backend", "size", "threads", "median", "min",
                   "max", "GFLOP/s", "vs DNN");
  for (const ForwardResult& r : forward) {
    if (!r.error.empty()) {
      s << fmt::format("{:<11} {:>7} {:>7}  error: {}\n", r.backend, r.size, r.threads, r.error);
      continue;
    }
    s << fmt::format("{:<11} {:>7} {:>6}{} {:>9.2f} {:>9.2f} {:>9.2f} {:>8.2f} {:>7.2f}x\n", r.backend, r.size,
                     r.threads, r.backend == "opencl" ? "*" : " ", r.ms.median, r.ms.min, r.ms.max, r.gflop_per_s,
                     r.speedup_vs_dnn);
  }
  s << "\n* OpenCL (PoCL) threads are not set per row: PoCL reads POCL_MAX_PTHREAD_COUNT once at platform init\n"
       "  (unset = all cores). Its 'vs DNN' compares with OpenCV DNN at that thread count (else the most measured).\n"
       "  vs DNN = bare OpenCV DNN median / row median (> 1: faster). Bare DNN time includes blobFromImage.\n"
       "  GFLOP/s = DarknetModel::flops() (convolutions) / median. Rows take turns: one forward each per round.\n\n";
  if (!layers.empty()) {
    s << "OpenCL per layer: device time of each command (OpenCL profiling events), medians of the profiled runs\n";
    s << fmt::format("{:>7} {:>9} {:>9} {:>8} {:>7}  {}\n", "size", "median", "min", "GFLOP/s", "share", "command");
    std::string last_size;
    double sum = 0;
    auto total_line = [&] {
      if (!last_size.empty())
        s << fmt::format("{:>7} {:>9.3f} {:>9} {:>8} {:>7}  sum of medians\n", last_size, sum, "", "", "");
    };
    for (const LayerResult& l : layers) {
      if (l.size != last_size) {
        total_line();
        last_size = l.size;
        sum = 0;
      }
      sum += l.ms.median;
      s << fmt::format("{:>7} {:>9.3f} {:>9.3f} {:>8.1f} {:>6.1f}%  {}\n", l.size, l.ms.median, l.ms.min, l.gflop_per_s,
                       100.0 * l.share, l.what);
    }
    total_line();
    s << "\n";
  }
  if (pipeline.empty()) return s.str();
  s << fmt::format("pipeline: DetectionPipeline::detect() on a synthetic {}x{} BGR stream (default options)\n",
                   stream_width, stream_height);
  s << fmt::format("{:<8} {:>7} {:>7} {:>5} {:>5} {:>6} {:>9} {:>9} {:>9} {:>7} {:>9} {:>8} {:>6} {:>10}\n", "backend",
                   "size", "threads", "zoom", "flip", "coarse", "median", "min", "max", "fps", "forwards", "images",
                   "boxes", "not-fwd %");
  for (const PipelineResult& r : pipeline) {
    if (!r.error.empty()) {
      s << fmt::format("{:<8} {:>7} {:>7} {:>5} {:>5} {:>6}  error: {}\n", r.backend, r.size, r.threads,
                       r.zoom_in ? "on" : "off", r.flip_fusion ? "on" : "off", r.coarse_pass ? "on" : "off", r.error);
      continue;
    }
    s << fmt::format(
        "{:<8} {:>7} {:>7} {:>5} {:>5} {:>6} {:>9.2f} {:>9.2f} {:>9.2f} {:>7.2f} {:>9.2f} {:>8.2f} {:>6.2f} "
        "{:>9.1f}%\n",
        r.backend, r.size, r.threads, r.zoom_in ? "on" : "off", r.flip_fusion ? "on" : "off",
        r.coarse_pass ? "on" : "off", r.ms.median, r.ms.min, r.ms.max, r.frames_per_s, r.forwards_per_frame,
        r.images_per_frame, r.detections_per_frame, 100.0 * r.non_forward_share);
  }
  s << "\n  ms per frame; forwards/images/boxes: mean per frame; not-fwd %: share of detect() time outside\n"
       "  backend.forward() (resize, decode, NMS), summed over the timed frames. images - 1 = zoom-in crops: only\n"
       "  boxes that fit the crop and overlap no more confident box are zoomed (random weights' boxes rarely are).\n"
       "  flip: detection.flip_fusion, a second pass (and its crops) on the mirrored frame, boxes fused.\n"
       "  coarse: detection.coarse_pass, one more pass (two with flip) at coarse_scale of the network input.\n";
  return s.str();
}

std::string BenchDetectorReport::json() const {
  using common::Json;
  Json j;
  j["benchmark"] = "detector";
  j["cfg"] = cfg;
  j["weights"] = weights;
  j["repetitions"] = repetitions;
  j["warmup"] = warmup;
  j["stream"] = {stream_width, stream_height};
  j["machine"] = {{"cpu_model", machine.cpu_model},
                  {"cores", machine.cores},
                  {"opencl_devices", machine.opencl_devices},
                  {"pocl_affinity", machine.pocl_affinity},
                  {"pocl_max_pthread_count", machine.pocl_max_pthread_count},
                  {"opencv_version", machine.opencv_version}};
  Json& fwd = j["forward"] = Json::array();
  for (const ForwardResult& r : forward)
    fwd.push_back({{"backend", r.backend},
                   {"device", r.device},
                   {"size", r.size},
                   {"threads", r.threads},
                   {"threads_note", r.threads_note},
                   {"ms", json_timing(r.ms)},
                   {"gflop_per_s", r.gflop_per_s},
                   {"speedup_vs_dnn", r.speedup_vs_dnn},
                   {"error", r.error}});
  Json& lay = j["layers"] = Json::array();
  for (const LayerResult& l : layers)
    lay.push_back({{"size", l.size},
                   {"layer", l.layer},
                   {"what", l.what},
                   {"ms", json_timing(l.ms)},
                   {"gflop_per_s", l.gflop_per_s},
                   {"share", l.share}});
  Json& pipe = j["pipeline"] = Json::array();
  for (const PipelineResult& r : pipeline)
    pipe.push_back({{"backend", r.backend},
                    {"size", r.size},
                    {"threads", r.threads},
                    {"zoom_in", r.zoom_in},
                    {"flip_fusion", r.flip_fusion},
                    {"coarse_pass", r.coarse_pass},
                    {"ms", json_timing(r.ms)},
                    {"frames_per_s", r.frames_per_s},
                    {"forwards_per_frame", r.forwards_per_frame},
                    {"images_per_frame", r.images_per_frame},
                    {"detections_per_frame", r.detections_per_frame},
                    {"non_forward_share", r.non_forward_share},
                    {"error", r.error}});
  return common::json_text(j) + "\n";
}

int run_bench_detector_verb(const BenchDetectorOptions& options, std::ostream& out, std::ostream& err) {
  const std::string prefix = "wingman bench detector: error: ";
  const std::vector<std::string> problems = options.validate();
  if (!problems.empty()) {
    for (const auto& p : problems) err << prefix << p << "\n";
    return 2;
  }
  try {
    const BenchDetectorReport report = run_bench_detector(options, &err);
    out << (options.json ? report.json() : report.table()) << std::flush;
  } catch (const std::exception& e) {
    err << prefix << e.what() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace wingman::tools
