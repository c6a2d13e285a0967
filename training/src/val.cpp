// SPDX-License-Identifier: MIT
// `wingman val`: dataset split + detector or predictions -> DetectionMetrics.
#include "wingman/training/val.hpp"

#include "wingman/training/yolo_dataset.hpp"

#include <wingman/detector/box.hpp>
#include <wingman/detector/input_size.hpp>
#include <wingman/detector/model_loader.hpp>
#include <wingman/detector/sized_detector.hpp>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <stdexcept>

namespace wingman::training {

namespace fs = std::filesystem;

detector::DetectorPipelineOptions ValOptions::low_threshold_detection() {
  detector::DetectorPipelineOptions d;
  d.p_thresh = 0.005;
  return d;
}

std::vector<std::string> ValOptions::validate() const {
  std::vector<std::string> p;
  if (data.empty()) p.push_back("data is empty: a data.yaml or YOLO-layout folder is required");
  if (weights.empty() == predictions.empty())
    p.push_back("weights / predictions: give exactly one (run the detector, or read saved predictions)");
  if (backend != "auto" && backend != "opencl" && backend != "cpu")
    p.push_back(fmt::format("backend = '{}': must be auto, opencl or cpu", backend));
  if (std::string why; !detector::InputSize::parse(input_size, &why)) p.push_back("input_size = " + why);
  if (class_id < 0) p.push_back(fmt::format("class_id = {}: must be >= 0", class_id));
  if (max_images < 0) p.push_back(fmt::format("max_images = {}: must be >= 0", max_images));
  for (const auto& s : detection.validate()) p.push_back(s);
  for (const auto& s : metrics.validate()) p.push_back("metrics." + s);
  return p;
}

DetectionMetrics run_val(const ValOptions& o, const std::function<void(size_t, size_t)>& progress,
                         const std::function<void(const std::string&)>& log) {
  const std::vector<std::string> problems = o.validate();
  if (!problems.empty()) {
    std::string msg = "run_val: invalid options:";
    for (const auto& p : problems) msg += "\n  " + p;
    throw std::invalid_argument(msg);
  }
  const YoloDataset ds = load_yolo_dataset(o.data, o.split);
  const std::vector<size_t> chosen = evenly_spaced(ds.images.size(), static_cast<size_t>(o.max_images));
  const size_t n = chosen.size();

  std::unique_ptr<detector::SizedDetector> pipeline;
  std::map<std::string, std::string> stems;  // predictions mode: stem -> image, to refuse ambiguous stems
  if (!o.weights.empty()) {
    auto make_backend = [&](const detector::DarknetModel& sized) {
      std::string why;
      auto backend = detector::make_backend(o.backend, sized, detector::OpenClOptions{}, 1, &why,
                                            detector::AutoChoice::kRepeatable);
      if (log) log(fmt::format("{} (network input {}x{})", why, sized.net.width, sized.net.height));
      return backend;
    };
    pipeline = std::make_unique<detector::SizedDetector>(o.detection, detector::load_model(o.cfg, o.weights),
                                                         *detector::InputSize::parse(o.input_size), make_backend);
  } else {
    if (!fs::is_directory(o.predictions))
      throw DatasetError(fmt::format("{}: the predictions folder does not exist", o.predictions));
    for (size_t i : chosen) {
      const std::string stem = fs::path(ds.images[i].image_path).stem().string();
      const auto [it, fresh] = stems.emplace(stem, ds.images[i].image_path);
      if (!fresh)
        throw DatasetError(fmt::format("{} and {} have the same stem '{}': their predictions would share {}.txt",
                                       it->second, ds.images[i].image_path, stem, stem));
    }
  }

  std::vector<ImageDetections> results;
  results.reserve(n);
  for (size_t k = 0; k < n; ++k) {
    const DatasetImage& img = ds.images[chosen[k]];
    const cv::Mat bgr = cv::imread(img.image_path, cv::IMREAD_COLOR);
    if (bgr.empty()) throw DatasetError(fmt::format("{}: cannot read the image", img.image_path));
    const double W = bgr.cols, H = bgr.rows;
    ImageDetections d;
    d.name = fs::path(img.image_path).lexically_normal().string(), d.width = bgr.cols, d.height = bgr.rows;
    for (const LabeledBox& t : img.boxes) {
      if (t.cls != o.class_id) continue;
      detector::Box b;
      b.cx = static_cast<float>(t.cx * W), b.cy = static_cast<float>(t.cy * H);
      b.w = static_cast<float>(t.w * W), b.h = static_cast<float>(t.h * H);
      d.truths.push_back(b);
    }
    if (pipeline) {
      // As `wingman predict` writes them: the visible part of each box (the labels' convention).
      // Boxes of class_id only: a multi-class model's distractor boxes are not drone predictions.
      for (const detector::Box& b :
           detector::clip_to_image(pipeline->detect(bgr), static_cast<float>(W), static_cast<float>(H)))
        if (b.class_id == o.class_id) d.predictions.push_back(b);
    } else {
      const std::string file = (fs::path(o.predictions) / (fs::path(img.image_path).stem().string() + ".txt")).string();
      if (!fs::is_regular_file(file))
        throw DatasetError(fmt::format("{}: no prediction file for {} (`wingman predict` writes one per image)", file,
                                       img.image_path));
      // Any class a model can write (detection_t.class_id is an int16): a multi-class model's distractor lines are
      // read and skipped below, whatever classes the dataset names.
      const int classes = std::max({static_cast<int>(ds.class_names.size()), o.class_id + 1, 32768});
      for (const PredictedBox& p : read_yolo_predictions(file, classes)) {
        if (p.box.cls != o.class_id) continue;
        detector::Box b;
        b.cx = static_cast<float>(p.box.cx * W), b.cy = static_cast<float>(p.box.cy * H);
        b.w = static_cast<float>(p.box.w * W), b.h = static_cast<float>(p.box.h * H);
        b.confidence = p.confidence;
        d.predictions.push_back(b);
      }
    }
    results.push_back(std::move(d));
    if (progress) progress(k + 1, n);
  }
  return evaluate_detections(results, o.metrics);
}

}  // namespace wingman::training
