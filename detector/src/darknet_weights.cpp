// SPDX-License-Identifier: MIT
// Darknet .weights reader and writer, and seeded random weights.
#include "wingman/detector/darknet_weights.hpp"

#include "wingman/detector/darknet_cfg.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>

namespace wingman::detector {

namespace {

static_assert(sizeof(float) == 4, "float32 expected");

/// Darknet's rule: version major.minor >= 0.2 stores `seen` in 64 bits. In 64-bit arithmetic: a fuzzed header with
/// major = -555855834 overflowed int.
bool seen_is_64bit(int32_t major, int32_t minor) { return int64_t{major} * 10 + minor >= 2; }

template <class T>
void put(std::vector<char>& out, T value) {
  // Little-endian hosts only (x86-64, aarch64): the bytes of the value are the file's bytes.
  const char* p = reinterpret_cast<const char*>(&value);
  out.insert(out.end(), p, p + sizeof(T));
}

template <class T>
T get(const std::vector<char>& in, size_t& pos) {
  T value;
  std::memcpy(&value, in.data() + pos, sizeof(T));
  pos += sizeof(T);
  return value;
}

void check_size(const Layer& l, size_t index, const std::string& what, const std::vector<float>& v, int64_t n,
                const DarknetModel& m) {
  if (static_cast<int64_t>(v.size()) != n)
    throw DarknetFormatError(fmt::format("{}: layer {} ([convolutional] at line {}) has {} {}, expected {}", m.cfg_path,
                                         index, l.cfg_line, v.size(), what, n));
}

/// Uniform in [0, 1) from 24 random bits: portable, unlike std::uniform_real_distribution.
float uniform01(std::mt19937& rng) { return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f); }

float normal(std::mt19937& rng) {
  // Box-Muller; u1 in (0, 1].
  const float u1 = 1.0f - uniform01(rng);
  const float u2 = uniform01(rng);
  return std::sqrt(-2.0f * std::log(u1)) * std::cos(6.2831853f * u2);
}

}  // namespace

int64_t darknet_weights_header_bytes(const DarknetModel& model) {
  return 12 + (seen_is_64bit(model.major, model.minor) ? 8 : 4);
}

namespace {

/// Floats of [convolutional] layer `l`'s parameters in a .weights file.
int64_t layer_floats(const Layer& l) {
  return int64_t{l.filters} * (l.batch_normalize ? 4 : 1) + int64_t{l.filters} * l.input.c * l.size * l.size;
}

/// The reader behind both loaders: with `prefix`, the file may end after any whole [convolutional] layer.
/// Returns the [convolutional] layers read.
int load_layers(DarknetModel& model, const std::vector<char>& bytes, const std::string& source_name, bool prefix) {
  if (bytes.size() < 12)
    throw DarknetFormatError(
        fmt::format("{}: {} bytes is too short for a .weights header (16 or 20 bytes)", source_name, bytes.size()));
  size_t pos = 0;
  const int32_t major = get<int32_t>(bytes, pos);
  const int32_t minor = get<int32_t>(bytes, pos);
  const int32_t revision = get<int32_t>(bytes, pos);
  const size_t header = 12 + (seen_is_64bit(major, minor) ? 8 : 4);
  const int64_t count = model.weight_count();
  const int64_t expected = static_cast<int64_t>(header) + 4 * count;
  const int64_t size = static_cast<int64_t>(bytes.size());
  // With a prefix: the layers whose parameters the file holds completely, and where they end.
  int layers = 0;
  int64_t end = static_cast<int64_t>(header);
  int total_layers = 0;
  for (const Layer& l : model.layers) {
    if (l.type != LayerType::kConvolutional) continue;
    ++total_layers;
    if (end + 4 * layer_floats(l) <= size && layers + 1 == total_layers) {
      end += 4 * layer_floats(l);
      ++layers;
    }
  }
  if (!prefix && size != expected)
    throw DarknetFormatError(fmt::format(
        "{}: wrong .weights length for {}: expected {} bytes ({}-byte header (version {}.{}.{}) + {} float32 "
        "values), got {} bytes",
        source_name, model.cfg_path, expected, header, major, minor, revision, count, size));
  if (prefix && (size < static_cast<int64_t>(header) || size != end || layers == 0))
    throw DarknetFormatError(fmt::format(
        "{}: {} bytes is not a {}-byte header (version {}.{}.{}) plus the first 1..{} [convolutional] layers of {} "
        "(the first {} fit in {} bytes; a file of the whole network has {})",
        source_name, size, header, major, minor, revision, total_layers, model.cfg_path, layers, end, expected));
  const uint64_t seen = seen_is_64bit(major, minor) ? get<uint64_t>(bytes, pos) : get<uint32_t>(bytes, pos);
  auto read = [&](std::vector<float>& v, int64_t n) {
    v.resize(static_cast<size_t>(n));
    std::memcpy(v.data(), bytes.data() + pos, static_cast<size_t>(n) * 4);
    pos += static_cast<size_t>(n) * 4;
  };
  int read_layers = 0;
  for (Layer& l : model.layers) {
    if (l.type != LayerType::kConvolutional) continue;
    if (read_layers == layers) break;
    ++read_layers;
    read(l.biases, l.filters);
    if (l.batch_normalize) {
      read(l.scales, l.filters);
      read(l.rolling_mean, l.filters);
      read(l.rolling_variance, l.filters);
    } else {
      l.scales.clear();
      l.rolling_mean.clear();
      l.rolling_variance.clear();
    }
    read(l.weights, static_cast<int64_t>(l.filters) * l.input.c * l.size * l.size);
  }
  model.major = major;
  model.minor = minor;
  model.revision = revision;
  model.seen = seen;
  return layers;
}

/// The file's bytes, refused before reading when it is not a regular file or is far larger than a .weights file of
/// `model` can be (header + every float32): a huge or endless file is one error, not an allocation of its size.
std::vector<char> read_all(const std::string& path, const DarknetModel& model) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status))
    throw DarknetFormatError(fmt::format("{}: cannot open the .weights file", path));
  if (!std::filesystem::is_regular_file(status))
    throw DarknetFormatError(fmt::format("{}: not a regular file (a .weights file is one)", path));
  const auto size = std::filesystem::file_size(path, ec);
  const int64_t largest = 20 + 4 * model.weight_count();  // the 64-bit "seen" header is the longer one
  // Refused unread only when far larger (1 MiB beyond): a near miss gets load_layers's message, which says which
  // layers the bytes would fill.
  if (!ec && static_cast<int64_t>(size) > largest + (int64_t{1} << 20))
    throw DarknetFormatError(fmt::format(
        "{}: {} bytes: larger than any .weights file of {} can be ({} bytes: a 20-byte header + {} float32 values)",
        path, size, model.cfg_path, largest, model.weight_count()));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw DarknetFormatError(fmt::format("{}: cannot open the .weights file", path));
  return std::vector<char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

}  // namespace

void load_darknet_weights_from_buffer(DarknetModel& model, const std::vector<char>& bytes,
                                      const std::string& source_name) {
  load_layers(model, bytes, source_name, false);
}

void load_darknet_weights(DarknetModel& model, const std::string& path) {
  load_layers(model, read_all(path, model), path, false);
}

int load_darknet_weights_prefix(DarknetModel& model, const std::string& path) {
  return load_layers(model, read_all(path, model), path, true);
}

std::vector<char> serialize_darknet_weights(const DarknetModel& model) {
  std::vector<char> out;
  out.reserve(static_cast<size_t>(darknet_weights_header_bytes(model) + 4 * model.weight_count()));
  put<int32_t>(out, model.major);
  put<int32_t>(out, model.minor);
  put<int32_t>(out, model.revision);
  if (seen_is_64bit(model.major, model.minor))
    put<uint64_t>(out, model.seen);
  else
    put<uint32_t>(out, static_cast<uint32_t>(model.seen));
  auto write = [&](const std::vector<float>& v) {
    const char* p = reinterpret_cast<const char*>(v.data());
    out.insert(out.end(), p, p + v.size() * 4);
  };
  for (size_t i = 0; i < model.layers.size(); ++i) {
    const Layer& l = model.layers[i];
    if (l.type != LayerType::kConvolutional) continue;
    check_size(l, i, "biases", l.biases, l.filters, model);
    check_size(l, i, "weights", l.weights, static_cast<int64_t>(l.filters) * l.input.c * l.size * l.size, model);
    write(l.biases);
    if (l.batch_normalize) {
      check_size(l, i, "scales", l.scales, l.filters, model);
      check_size(l, i, "rolling_mean values", l.rolling_mean, l.filters, model);
      check_size(l, i, "rolling_variance values", l.rolling_variance, l.filters, model);
      write(l.scales);
      write(l.rolling_mean);
      write(l.rolling_variance);
    }
    write(l.weights);
  }
  return out;
}

void save_darknet_weights(const DarknetModel& model, const std::string& path) {
  const std::vector<char> bytes = serialize_darknet_weights(model);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw DarknetFormatError(fmt::format("{}: cannot create the .weights file", path));
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw DarknetFormatError(fmt::format("{}: writing {} bytes failed", path, bytes.size()));
}

void randomize_weights(DarknetModel& model, uint32_t seed) {
  std::mt19937 rng(seed);
  for (Layer& l : model.layers) {
    if (l.type != LayerType::kConvolutional) continue;
    const int fan_in = l.input.c * l.size * l.size;
    const float w_std = std::sqrt(2.0f / static_cast<float>(fan_in));
    l.biases.resize(l.filters);
    for (float& b : l.biases) b = 0.1f * normal(rng);
    if (l.batch_normalize) {
      l.scales.resize(l.filters);
      l.rolling_mean.resize(l.filters);
      l.rolling_variance.resize(l.filters);
      for (float& g : l.scales) g = 0.8f + 0.4f * uniform01(rng);
      for (float& m : l.rolling_mean) m = 0.1f * normal(rng);
      for (float& v : l.rolling_variance) v = 0.5f + uniform01(rng);
    } else {
      l.scales.clear();
      l.rolling_mean.clear();
      l.rolling_variance.clear();
    }
    l.weights.resize(static_cast<size_t>(l.filters) * fan_in);
    for (float& w : l.weights) w = w_std * normal(rng);
  }
}

}  // namespace wingman::detector
