// SPDX-License-Identifier: MIT
// The training loop: a Darknet .cfg network in libtorch, SGD with warm-up and steps, checkpoints, progress.
//
// This header does not include libtorch (the trainer keeps it behind a pointer), so the CLI can include it.
#pragma once

#include "wingman/training/detection_metrics.hpp"
#include "wingman/training/train_options.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace wingman::training {

/// Progress of one iteration (one weight update).
struct TrainProgress {
  int64_t iteration = 0;    ///< iterations done, 1 .. max_batches
  int64_t max_batches = 0;  ///< iterations to do in total
  double loss = 0.0;        ///< this iteration's loss per image (sum of the terms below)
  double loss_avg = 0.0;    ///< exponential average of loss (0.9 old + 0.1 new; Darknet's "avg")
  double coord = 0.0, object = 0.0, noobject = 0.0, cls = 0.0;  ///< the loss terms per image
  double mean_iou = 0.0;  ///< mean IoU of the responsible predictions with their truths
  int64_t truths = 0;     ///< truth boxes in this iteration's (augmented) images
  double learning_rate = 0.0;
  double images_per_s = 0.0;  ///< over the iterations of this run so far (data loading included)
  double data_share = 0.0;    ///< share of this run's time spent reading and augmenting images, 0..1
  double elapsed_s = 0.0;     ///< seconds since this run started (not counting earlier runs of a resume)
  double eta_s = 0.0;         ///< estimated seconds to max_batches at images_per_s

  std::string one_line() const;
};

/// What a run did.
struct TrainSummary {
  int64_t start_iteration = 0;  ///< iterations already done when this run started (resume)
  int64_t iteration = 0;        ///< iterations done when it stopped
  int64_t max_batches = 0;
  bool interrupted = false;   ///< stopped by the stop flag before max_batches (a checkpoint was written)
  double first_loss = 0.0;    ///< loss per image of this run's first iteration
  double loss_avg = 0.0;      ///< exponential average at the end
  double images_per_s = 0.0;  ///< training images per second over this run
  double elapsed_s = 0.0;
  std::string weights;      ///< the last .weights written (final, or last at an interruption)
  std::string raw_weights;  ///< with a weight average: <stem>_raw_final.weights, the trained weights at the end
  std::string checkpoint;   ///< the checkpoint file
  std::optional<DetectionMetrics> validation;  ///< on the val split at the end (when it has one)

  std::string one_line() const;
  std::string report() const;
};

/// A training run. Construction checks the options, parses the .cfg (and its head training keys), reads the
/// dataset, builds the network (seeded initial weights, or TrainOptions::init_weights) and, with resume,
/// restores out_dir/checkpoint.pt. run() trains until max_batches or the stop flag.
///
/// Reproducible: with the same options, seed and thread count, a run gives the same weights, and a run
/// stopped after k iterations and resumed gives the weights of an uninterrupted run (tested within float
/// tolerance). Image k of iteration i is image perm_e[(i * batch + k) mod n] of a seeded permutation per epoch
/// e; its augmentation is seeded by (seed, i * batch + k).
///
/// Files in out_dir: checkpoint.pt (weights, batch-norm statistics, momentum, iteration; written atomically),
/// <stem>.cfg (a copy of the .cfg), <stem>_last.weights at each checkpoint, <stem>_<iteration>.weights every
/// weights_interval, and <stem>_final.weights at the end; <stem> is the .cfg's file stem. With a weight average
/// (TrainOptions::ema) those .weights hold the average, the checkpoint holds it too, and <stem>_raw_<iteration>.weights
/// and <stem>_raw_final.weights hold the trained weights themselves.
class Trainer {
 public:
  /// Throws std::invalid_argument listing every invalid option; DatasetError / DarknetFormatError naming the
  /// file for bad data (the train and, when set, the val split are read here) or .cfg / .weights;
  /// std::runtime_error for a missing or mismatched checkpoint.
  explicit Trainer(TrainOptions options);
  ~Trainer();
  Trainer(const Trainer&) = delete;
  Trainer& operator=(const Trainer&) = delete;

  /// Trains from the current iteration to max_batches. `progress` (may be empty) is called every log_interval
  /// iterations; `stop` (may be null) is polled after each iteration: when set, a checkpoint is written and
  /// run() returns with interrupted = true. Validates on val_split at the end when it is set.
  TrainSummary run(const std::function<void(const TrainProgress&)>& progress = {},
                   const std::atomic<bool>* stop = nullptr);

  /// Writes the current weights (the weight average, when the run keeps one) as Darknet .weights (the detector's
  /// format).
  void save_weights(const std::string& path) const;

  /// Evaluates the current network (the weight average, when the run keeps one; inference mode, no augmentation:
  /// the detector's stretch) on `split` of the dataset, at most `max_images` images spread over it (0 = all): every
  /// head decoded with p_thresh 0.005, NMS 0.45, boxes in image pixels against the split's class-0 (drone) boxes.
  DetectionMetrics validate(const std::string& split, int max_images = 0) const;

  /// Iterations done so far (after construction: 0, or the checkpoint's with resume).
  int64_t iteration() const;
  const TrainOptions& options() const;
  /// Images in the training split.
  size_t train_images() const;
  /// [convolutional] layers taken from init_weights: all of the network's, or with init_partial the first this many;
  /// 0 without init_weights.
  int init_layers() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace wingman::training
