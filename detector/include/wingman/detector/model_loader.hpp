// SPDX-License-Identifier: MIT
// Loading the detector's network and choosing its inference backend.
#pragma once

#include "wingman/detector/backend.hpp"
#include "wingman/detector/darknet_model.hpp"
#include "wingman/detector/opencl_options.hpp"

#include <memory>
#include <string>
#include <vector>

namespace wingman::detector {

/// The thesis network's .cfg (models/tiny-yolo-thesis.cfg), embedded at build time.
const char* builtin_thesis_cfg();

/// The shipped model's .cfg (models/wingman-small.cfg), embedded at build time.
const char* builtin_small_cfg();

/// The shipped model's Darknet .weights (models/wingman-small.weights) as built in; empty when the source tree had
/// no such file at build time.
std::vector<char> builtin_small_weights();

/// Prefix of a built-in model name in model.cfg / model.weights, e.g. "builtin:wingman-small".
inline constexpr const char* kBuiltinPrefix = "builtin:";

/// The names after "builtin:" that model.cfg accepts (wingman-small, tiny-yolo-thesis) and model.weights accepts
/// (wingman-small).
std::vector<std::string> builtin_cfg_names();
std::vector<std::string> builtin_weights_names();

/// The identity of a model's weights as detections_t.model_id carries it: "sha256:" and the first 16 hex digits of
/// the SHA-256 of the .weights bytes (`weights`: a path or "builtin:wingman-small"); "" for "". A box relation
/// (localizer/box_relation.hpp) names the model it was measured for this way. Throws std::runtime_error as
/// load_weights does for a missing file or unknown built-in.
std::string weights_model_id(const std::string& weights);

/// Loads a network: `cfg` is a .cfg path or "builtin:<name>" (builtin_cfg_names()); `weights` is a .weights path or
/// "builtin:wingman-small" (the shipped model; its .cfg must be builtin:wingman-small or a copy of it). Throws
/// std::runtime_error naming the file, line and key (see parse_darknet_cfg, load_darknet_weights), or the unknown
/// built-in name and the known ones.
DarknetModel load_model(const std::string& cfg, const std::string& weights);

/// The .cfg half of load_model: a path or "builtin:<name>".
DarknetModel load_cfg(const std::string& cfg);

/// The .weights half of load_model: a path or "builtin:wingman-small", into `model` (shapes computed).
void load_weights(DarknetModel& model, const std::string& weights);

/// How make_backend's "auto" chooses between OpenCL and the CPU backend.
enum class AutoChoice {
  /// Times both on the model and takes the faster (realtime: speed matters). Two runs can choose differently when
  /// the two are close, and the backends' boxes differ in the 4th decimal.
  kFastest,
  /// OpenCL whenever a device is usable, else the CPU backend, without timing: the same backend, so the same boxes,
  /// on every run (replays, lockstep flights, offline evaluations).
  kRepeatable,
};

/// Creates the backend `kind` ("opencl", "cpu" or "auto") for `model`. auto with AutoChoice::kFastest times both
/// backends on the model, a warm-up each and then in turn up to 3 forwards each, and takes the one whose fastest
/// forward was faster (the CPU backend more than 1.5x slower in the first turn is not timed further; a GPU is timed
/// too: the kernels are shaped for CPUs); with AutoChoice::kRepeatable it takes OpenCL whenever a device is usable.
/// Either way, without a usable OpenCL device auto takes the CPU backend and `why` says "no usable OpenCL device"
/// and the cause. `why` (if not null) receives one line saying what was chosen and why.
/// Throws std::runtime_error when the named backend cannot be created (e.g. opencl without a usable device).
std::unique_ptr<InferenceBackend> make_backend(const std::string& kind, const DarknetModel& model,
                                               const OpenClOptions& opencl, int max_batch, std::string* why,
                                               AutoChoice choice = AutoChoice::kFastest);

}  // namespace wingman::detector
