// SPDX-License-Identifier: MIT
// The detector's frame loop without LCM.
#include "wingman/detector/detector.hpp"

#include "wingman/detector/detection_message.hpp"
#include "wingman/detector/model_loader.hpp"
#include "wingman/detector/preprocess.hpp"

#include <fmt/format.h>

#include <chrono>
#include <stdexcept>
#include <utility>

namespace wingman::detector {

namespace {

const DetectorOptions& validated(const DetectorOptions& o) {
  const auto problems = o.validate();
  if (!problems.empty()) {
    std::string all = "invalid DetectorOptions:";
    for (const auto& q : problems) all += " " + q + ";";
    throw std::invalid_argument(all);
  }
  return o;
}

}  // namespace

Detector::Detector(const DetectorOptions& options)
    : options_(validated(options)),
      clock_(options_.time),
      image_input_(clock_.add_input("image_t.utime", "image", true)) {
  if (options_.weights.empty()) return;  // images are checked only

  DarknetModel model = load_model(options_.cfg, options_.weights);
  model_id_ = weights_model_id(options_.weights);
  const InputSize input_size = *InputSize::parse(options_.input_size);  // validated with the options
  // model.backend = opencl: no usable OpenCL device, or a kernel that fails to build, throws here.
  // The first network is built now (the cfg's size, or model.input_size's WxH); with input_size auto, frames of
  // another aspect build another one when the first of them arrives.
  auto on_build = [this, input_size](cv::Size net, cv::Size image) {
    if (image.empty()) return;  // the start-up build: build_backend said it
    note({DetectorNote::Level::kInfo,
          fmt::format("model.input_size {}: network input {}x{} for {}x{} images", input_size.to_string(), net.width,
                      net.height, image.width, image.height),
          ""});
  };
  auto factory = [this](const DarknetModel& sized) { return build_backend(sized); };
  // Tracker-driven windows: the localizer's predictions, and a second network at the crop size, built after the single
  // pass's (with model.backend auto, the single pass's network decides the backend and the window's takes the same).
  std::optional<DarknetModel> window_model;
  if (options_.windows.enabled || options_.motion.enabled) window_model = model;
  pipeline_ = std::make_unique<SizedDetector>(options_.detection, std::move(model), input_size, factory, on_build);
  if (window_model)
    window_detector_ = std::make_unique<WindowDetector>(options_.windows, options_.detection, *window_model, factory);
  // The motion cue's windows go through the same window network, with their own budget.
  if (options_.motion.enabled) {
    motion_ = std::make_unique<MotionCue>(options_.motion);
    motion_window_options_ = options_.windows;
    motion_window_options_.max_per_frame = options_.motion.max_windows;
  }
}

Detector::~Detector() = default;

std::unique_ptr<InferenceBackend> Detector::build_backend(const DarknetModel& sized) {
  std::string why;
  const auto t_backend = std::chrono::steady_clock::now();
  // model.backend auto chooses (it measures both) at start-up; a network for another frame size later takes the
  // same kind without measuring again (seconds in which no frame would be detected).
  const std::string& backend = options_.backend;
  const bool reuse = backend == "auto" && !auto_kind_.empty();
  // Replay mode: the choice must not depend on timing, or two replays of one log (two lockstep flights) could run
  // different backends, whose boxes differ in the 4th decimal, and a closed loop carries that on.
  const AutoChoice choice = options_.mode == "replay" ? AutoChoice::kRepeatable : AutoChoice::kFastest;
  auto made =
      make_backend(reuse ? auto_kind_ : backend, sized, options_.opencl, options_.opencl.max_batch, &why, choice);
  if (reuse) {
    // The heartbeat keeps naming the first network and why its backend was chosen; this one is added to it.
    why = fmt::format("{}; the same backend also runs the {}x{} network", auto_why_, sized.net.width, sized.net.height);
  } else if (backend == "auto") {
    auto_kind_ = made->name().rfind("opencl", 0) == 0 ? "opencl" : "cpu";
    auto_why_ = why;
  }
  const double backend_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_backend).count();
  const std::string net = fmt::format("network input {}x{}", sized.net.width, sized.net.height);
  // The heartbeat says which backend runs, and why, for as long as nothing else needs saying.
  if (why.find("no usable OpenCL device") != std::string::npos && !built_once_) {
    // auto fell back: warned once
    note({DetectorNote::Level::kWarn,
          fmt::format("{}; running on the CPU (chosen in {:.2f} s; {})", why, backend_s, net), why});
  } else {
    note({DetectorNote::Level::kInfo, fmt::format("{} (chosen in {:.2f} s; {})", why, backend_s, net), why});
  }
  built_once_ = true;
  return made;
}

void Detector::note(DetectorNote n) {
  std::lock_guard<std::mutex> lock(mutex_);
  notes_.push_back(std::move(n));
}

std::vector<DetectorNote> Detector::take_notes() {
  std::vector<DetectorNote> taken;
  std::lock_guard<std::mutex> lock(mutex_);
  taken.swap(notes_);
  return taken;
}

void Detector::admit(const wingman::image_t& image) {
  image_camera_id_ = image.camera_id;  // even for a frame refused below
  const common::TimeAdmission a = clock_.admit(image_input_, image.utime);
  if (!a.accepted()) throw std::invalid_argument(a.problem);
  if (a.resynced()) note({DetectorNote::Level::kWarn, a.problem, ""});
}

void Detector::on_windows(const wingman::track_windows_t& windows) {
  if (image_camera_id_ >= 0 && windows.camera_id != image_camera_id_)
    throw std::invalid_argument(
        fmt::format("track_windows_t.camera_id = {}: the frames are camera {}", windows.camera_id, image_camera_id_));
  if (!windows_enabled()) return;
  auto fresh = std::make_shared<const wingman::track_windows_t>(windows);
  std::lock_guard<std::mutex> lock(mutex_);
  newest_windows_ = std::move(fresh);
}

FrameDetections Detector::detect(const wingman::image_t& image) {
  if (!pipeline_) throw std::logic_error("Detector::detect: no model (model.weights is \"\")");
  std::string error;
  const cv::Mat bgr = image_to_bgr(image, &error);
  if (!error.empty()) throw std::invalid_argument(error);
  const auto t0 = std::chrono::steady_clock::now();
  FrameDetections d;
  d.boxes = pipeline_->detect(bgr);
  if (windows_enabled()) {
    std::shared_ptr<const wingman::track_windows_t> windows;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      windows = newest_windows_;
    }
    if (windows) {
      const cv::Size size(bgr.cols, bgr.rows);
      const std::vector<Window> search = windows_to_search(*windows, image.utime, size, image.camera_id,
                                                           pipeline_->net_px_per_image_px(size), options_.windows);
      if (!search.empty()) d.boxes = window_detector_->detect(bgr, std::move(d.boxes), search, &window_stats_);
    }
  }
  if (motion_) {
    // Where something small moves and no box is yet: the window network looks there at full resolution.
    const std::vector<Window> moving = motion_->windows(bgr, image.utime, d.boxes);
    if (!moving.empty())
      d.boxes =
          window_detector_->detect(bgr, std::move(d.boxes), moving, motion_window_options_, &motion_window_stats_);
  }
  d.latency_us = std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - t0).count();
  return d;
}

wingman::detections_t Detector::message(const wingman::image_t& image, const FrameDetections& found) const {
  wingman::detections_t out{};
  out.utime = image.utime;
  out.seq = image.seq;
  out.camera_id = image.camera_id;
  out.image_width = image.width;
  out.image_height = image.height;
  out.source = wingman::detections_t::SOURCE_CNN;
  out.inference_latency_us = static_cast<int32_t>(found.latency_us);
  out.model_id = model_id_;
  // Every box, drone or distractor (class_id != 0 with a multi-class model): the consumers choose.
  for (const auto& b : found.boxes) out.detections.push_back(to_detection(b));
  out.num_detections = static_cast<int32_t>(out.detections.size());
  return out;
}

std::optional<wingman::detections_t> Detector::on_image(const wingman::image_t& image) {
  admit(image);  // a frame dated ahead or out of order is refused here: never detected
  if (!has_model()) return std::nullopt;
  return message(image, detect(image));
}

}  // namespace wingman::detector
