// SPDX-License-Identifier: MIT
// Algorithm 2 with the network input sized per image.
#include "wingman/detector/sized_detector.hpp"

#include "wingman/detector/darknet_cfg.hpp"
#include "wingman/detector/preprocess.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace wingman::detector {

SizedDetector::SizedDetector(DetectorPipelineOptions options, DarknetModel model, InputSize input_size,
                             BackendFactory make_backend, BuildObserver on_build)
    : options_(std::move(options)),
      model_(std::move(model)),
      cfg_net_(model_.net.width, model_.net.height),
      input_size_(input_size),
      make_backend_(std::move(make_backend)),
      on_build_(std::move(on_build)) {
  if (!make_backend_) throw std::invalid_argument("SizedDetector: make_backend is empty");
  if (input_size_.mode == InputSize::Mode::kFixed && (input_size_.fixed.width <= 0 || input_size_.fixed.height <= 0))
    throw std::invalid_argument(fmt::format("SizedDetector: input size {}x{} must be positive", input_size_.fixed.width,
                                            input_size_.fixed.height));
  const cv::Size first = input_size_.mode == InputSize::Mode::kFixed ? input_size_.fixed : cfg_net_;
  build(first, cv::Size());
}

cv::Size SizedDetector::net_size_for(cv::Size image) const {
  switch (input_size_.mode) {
    case InputSize::Mode::kCfg:
      return cfg_net_;
    case InputSize::Mode::kFixed:
      return input_size_.fixed;
    case InputSize::Mode::kAuto:
      break;
  }
  return fit_input_size(cfg_net_, detection_region(image, options_.subsquare).size());
}

double SizedDetector::net_px_per_image_px(cv::Size image) const {
  return static_cast<double>(net_size_for(image).width) / detection_region(image, options_.subsquare).width;
}

DetectionPipeline& SizedDetector::pipeline_for(cv::Size image) {
  const cv::Size net = net_size_for(image);
  for (size_t i = 0; i < pipelines_.size(); ++i) {
    if (pipelines_[i].net != net) continue;
    if (i != 0)
      std::rotate(pipelines_.begin(), pipelines_.begin() + static_cast<std::ptrdiff_t>(i),
                  pipelines_.begin() + static_cast<std::ptrdiff_t>(i) + 1);
    return *pipelines_.front().pipeline;
  }
  return build(net, image);
}

std::vector<Box> SizedDetector::detect(const cv::Mat& bgr_image) {
  if (bgr_image.empty() || bgr_image.type() != CV_8UC3)
    throw std::invalid_argument(fmt::format("SizedDetector::detect: image {}x{} type {}: must be non-empty CV_8UC3",
                                            bgr_image.cols, bgr_image.rows, bgr_image.type()));
  return pipeline_for(bgr_image.size()).detect(bgr_image);
}

DetectionPipeline& SizedDetector::build(cv::Size net, cv::Size image) {
  DarknetModel sized = model_;
  sized.net.width = net.width;
  sized.net.height = net.height;
  compute_shapes(sized);
  std::unique_ptr<DetectionPipeline> coarse;
  if (options_.coarse_pass) {  // step 6's pipeline, at coarse_scale of this network input
    DarknetModel small = model_;
    const cv::Size coarse_net = coarse_net_size(net, options_.coarse_scale);
    small.net.width = coarse_net.width;
    small.net.height = coarse_net.height;
    compute_shapes(small);
    coarse = std::make_unique<DetectionPipeline>(coarse_pass_options(options_), make_backend_(small), small);
  }
  auto pipeline = std::make_unique<DetectionPipeline>(options_, make_backend_(sized), sized, std::move(coarse));
  if (pipelines_.size() >= kMaxPipelines) pipelines_.pop_back();
  pipelines_.insert(pipelines_.begin(), Entry{net, std::move(pipeline)});
  ++builds_;
  if (on_build_) on_build_(net, image);
  return *pipelines_.front().pipeline;
}

}  // namespace wingman::detector
