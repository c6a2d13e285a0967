// SPDX-License-Identifier: MIT
// Darknet .weights files: read, write, and seeded random weights for tests and benchmarks.
#pragma once

#include "wingman/detector/darknet_model.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace wingman::detector {

/// Size in bytes of the .weights header of `model`: int32 major, minor, revision, then `seen` as uint64
/// when major * 10 + minor >= 2, else as uint32.
int64_t darknet_weights_header_bytes(const DarknetModel& model);

/// Reads a .weights file into the convolutional layers of `model` (shapes from its .cfg).
///
/// Layout after the header, per [convolutional] layer in order: biases (beta), then with batch_normalize
/// scales (gamma), rolling mean, rolling variance; then the weights in OIHW order; float32 little-endian.
/// Throws DarknetFormatError naming the file when it cannot be read or its length is not exactly
/// header + 4 * model.weight_count() bytes (the message gives the expected and the actual size).
void load_darknet_weights(DarknetModel& model, const std::string& path);

/// Same as load_darknet_weights from bytes in memory; `source_name` stands for the file name in messages.
void load_darknet_weights_from_buffer(DarknetModel& model, const std::vector<char>& bytes,
                                      const std::string& source_name);

/// Like load_darknet_weights, for a file that holds the first [convolutional] layers of `model` only: the .weights of
/// a network that `model` extends with layers appended to its .cfg (Darknet's partial weights, e.g. a stride-32 head
/// added to a trained two-head network). The file must end after a whole layer (at least one); the layers it holds
/// are loaded, the others are left as they are. A whole-network file loads completely. Returns the number of
/// [convolutional] layers loaded. Throws DarknetFormatError naming the file, its size and how many layers fit.
int load_darknet_weights_prefix(DarknetModel& model, const std::string& path);

/// The .weights bytes of `model` (header from model.major/minor/revision/seen).
/// Throws DarknetFormatError if a convolutional layer's weight vectors do not have their .cfg sizes
/// (e.g. weights were never loaded or randomized).
std::vector<char> serialize_darknet_weights(const DarknetModel& model);

/// Writes serialize_darknet_weights(model) to `path`; throws DarknetFormatError naming the file on failure.
void save_darknet_weights(const DarknetModel& model, const std::string& path);

/// Fills every convolutional layer with seeded random weights of realistic scale, so that activations of
/// random images stay bounded (order 1) through the thesis network:
/// weights ~ N(0, 2 / fan_in) (He), with batch_normalize gamma ~ U(0.8, 1.2), beta ~ N(0, 0.1^2),
/// rolling mean ~ N(0, 0.1^2), rolling variance ~ U(0.5, 1.5) (positive); without it biases ~ N(0, 0.1^2).
/// Deterministic for a seed on every platform (std::mt19937 with our own Box-Muller, not std distributions).
void randomize_weights(DarknetModel& model, uint32_t seed);

}  // namespace wingman::detector
