// SPDX-License-Identifier: MIT
// Loading the detector's network and choosing its inference backend.
#pragma once

#include "wingman/detector/backend.hpp"
#include "wingman/detector/darknet_model.hpp"
#include "wingman/detector/opencl_options.hpp"

#include <memory>
#include <string>

namespace wingman::detector {

/// The thesis network's .cfg (models/tiny-yolo-thesis.cfg), embedded at build time.
const char* builtin_thesis_cfg();

/// Parses `cfg_path` ("" = the built-in thesis network) and loads `weights_path` into it. Throws
/// std::runtime_error naming the file, line and key (see parse_darknet_cfg, load_darknet_weights).
DarknetModel load_model(const std::string& cfg_path, const std::string& weights_path);

/// Creates the backend `kind` ("opencl", "cpu" or "auto") for `model`. auto takes OpenCL when its
/// device is a GPU; otherwise it times both backends on the model and takes the faster: OpenCL over 3
/// forwards after a warm-up, the CPU backend over 1 after a warm-up, or 3 when that one is within 1.5x
/// of OpenCL (docs/detector.md gives the start-up cost). `why` (if not null) receives one line saying
/// what was chosen and why.
/// Throws std::runtime_error when the named backend cannot be created (e.g. no OpenCL device).
std::unique_ptr<InferenceBackend> make_backend(const std::string& kind, const DarknetModel& model,
                                               const OpenClOptions& opencl, int max_batch, std::string* why);

}  // namespace wingman::detector
