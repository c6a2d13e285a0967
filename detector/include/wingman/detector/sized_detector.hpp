// SPDX-License-Identifier: MIT
// Algorithm 2 with the network input sized per image (model.input_size): one pipeline per input size.
#pragma once

#include "wingman/detector/backend.hpp"
#include "wingman/detector/darknet_model.hpp"
#include "wingman/detector/detection_pipeline.hpp"
#include "wingman/detector/input_size.hpp"

#include <opencv2/core.hpp>

#include <functional>
#include <memory>
#include <vector>

namespace wingman::detector {

/// Algorithm 2 (DetectionPipeline) with the network input chosen by InputSize: it builds a pipeline per network
/// input size that the images call for, through `make_backend`, and keeps the last few (images of a few sizes
/// alternating do not rebuild). With kCfg and kFixed there is one pipeline, built at construction; kAuto builds the
/// cfg-sized one at construction (so that a bad model or backend fails at start-up) and another when an image's
/// region calls for another size. With detection.coarse_pass each pipeline holds its coarse one (a second backend,
/// at coarse_net_size() of the pipeline's input).
class SizedDetector {
 public:
  /// Creates the backend for `model` at the model's (already set) net size; throws what it likes.
  using BackendFactory = std::function<std::unique_ptr<InferenceBackend>(const DarknetModel& model)>;
  /// Called after each pipeline build: the network input and the image size that asked for it (empty for the one
  /// built at construction).
  using BuildObserver = std::function<void(cv::Size net, cv::Size image)>;

  /// @param model  with weights loaded; its [net] size is the cfg's. Throws std::invalid_argument for a kFixed size
  ///               of 0 and what DetectionPipeline and `make_backend` throw.
  SizedDetector(DetectorPipelineOptions options, DarknetModel model, InputSize input_size, BackendFactory make_backend,
                BuildObserver on_build = {});

  /// Detects in `bgr_image` (CV_8UC3, non-empty; std::invalid_argument otherwise) with the pipeline for its size.
  std::vector<Box> detect(const cv::Mat& bgr_image);
  /// The pipeline `image` is detected with (built now if needed).
  DetectionPipeline& pipeline_for(cv::Size image);
  /// The network input an image of this size is detected at.
  cv::Size net_size_for(cv::Size image) const;
  /// Network pixels per image pixel of the single pass on an image of this size (net_size_for() over the width of
  /// its detection region): how large a box of the image looks to the network.
  double net_px_per_image_px(cv::Size image) const;
  /// Pipelines built so far (a rebuilt size counts again).
  int builds() const { return builds_; }
  const InputSize& input_size() const { return input_size_; }

  /// Pipelines kept at once.
  static constexpr size_t kMaxPipelines = 4;

 private:
  struct Entry {
    cv::Size net;
    std::unique_ptr<DetectionPipeline> pipeline;
  };
  DetectionPipeline& build(cv::Size net, cv::Size image);

  DetectorPipelineOptions options_;
  DarknetModel model_;
  cv::Size cfg_net_;
  InputSize input_size_;
  BackendFactory make_backend_;
  BuildObserver on_build_;
  std::vector<Entry> pipelines_;  ///< most recently used first, at most kMaxPipelines
  int builds_ = 0;
};

}  // namespace wingman::detector
