// SPDX-License-Identifier: MIT
// Options of `wingman train`: the network's .cfg [net] training keys, overridable, plus data and run settings.
#pragma once

#include "wingman/training/augment.hpp"
#include "wingman/training/lr_schedule.hpp"
#include "wingman/training/weight_average.hpp"

#include <wingman/detector/darknet_model.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace wingman::training {

/// Everything a training run needs. train_options_from_cfg() fills the optimisation and augmentation fields
/// from the .cfg's [net] section (one source of truth); the command line may then override any of them.
struct TrainOptions {
  std::string cfg;                    ///< Darknet .cfg of the network (required)
  std::string data;                   ///< data.yaml or YOLO-layout folder (required)
  std::string train_split = "train";  ///< split to train on
  std::string val_split = "val";      ///< split to validate on at the end ("" = none)
  std::string out_dir = "train-out";  ///< checkpoint, .weights and the .cfg copy go here
  std::string init_weights;           ///< start from these Darknet .weights ("" = random initialisation)
  /// init_weights may hold the first [convolutional] layers only (detector::load_darknet_weights_prefix: a trained
  /// network that the .cfg extends with appended layers); the others keep their seeded random weights.
  bool init_partial = false;
  bool resume = false;  ///< continue from out_dir/checkpoint.pt (an error if there is none)

  int batch = 64;        ///< [net] batch: images per iteration (per weight update), >= 1
  int subdivisions = 8;  ///< [net] subdivisions: the batch runs in this many forward/backward passes, divides batch
  int64_t max_batches = 40000;  ///< [net] max_batches: iterations to train, >= 1
  double momentum = 0.9;        ///< [net] momentum (SGD), 0..1
  double decay = 0.0005;        ///< [net] decay: weight decay on convolution kernels, >= 0
  LearningRateSchedule lr;      ///< [net] learning_rate, burn_in, power, steps, scales (policy must be steps/constant)
  AugmentOptions augment;  ///< [net] hue, saturation, exposure, jitter, flip, mosaic; the rest from the command line
  /// Exponential moving average of the weights (off by default). When on, every .weights the run writes
  /// (<stem>_last, _<iteration>, _final) and its validation use the average; <stem>_raw_<iteration>.weights and
  /// <stem>_raw_final.weights keep the trained weights themselves.
  WeightAverageOptions ema;

  uint64_t seed = 1;              ///< seeds the initial weights, the data order and every augmentation
  int threads = 2;                ///< libtorch intra-op threads, >= 1
  int checkpoint_interval = 100;  ///< write the checkpoint (and <stem>_last.weights) every this many iterations, >= 1
  int weights_interval = 1000;    ///< also keep <stem>_<iteration>.weights every this many iterations (0 = never)
  int log_interval = 1;           ///< report progress every this many iterations, >= 1
  int val_max_images = 0;         ///< validate on at most this many images, spread over the split (0 = all)

  /// One "field = value: rule" line per invalid field; empty when valid.
  std::vector<std::string> validate() const;
};

/// TrainOptions with `cfg` set and the fields read from the model's .cfg: the [net] training keys
/// (NetParams::other) batch, subdivisions, max_batches, momentum, decay, learning_rate, burn_in, power,
/// policy (steps or constant), steps, scales, hue, saturation, exposure, jitter, flip (1: half the images),
/// mosaic (1: half the samples); the crop jitter comes from [net] jitter when present, else (as in Darknet)
/// from the last head's jitter. Absent keys keep the defaults.
/// Throws std::invalid_argument naming `cfg_path`, the key and its value when a value is not a number, the
/// policy is unsupported, or [net] angle != 0 (rotation is not implemented). A head's `random` (multi-scale
/// training) is not implemented either: the trainer trains at the .cfg's size (see multi_scale_note()).
TrainOptions train_options_from_model(const detector::DarknetModel& model, const std::string& cfg_path);

/// "" or one line saying that a head asks for multi-scale training (random != 0), which the trainer does not do.
std::string multi_scale_note(const detector::DarknetModel& model);

}  // namespace wingman::training
