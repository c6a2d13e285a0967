// SPDX-License-Identifier: MIT
// The wire format of every message type in lcmtypes/, walked before decoding (see message_limits.hpp).
#include "wingman/common/message_limits.hpp"

#include <fmt/format.h>

#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace wingman::common {
namespace {

/// LCM wire types (big-endian; boolean and byte are one byte; a string is an int32 length including the
/// terminating NUL, then that many bytes; nested structs carry no fingerprint).
enum class Wire { kI8, kI16, kI32, kI64, kF32, kF64, kBool, kByte, kString, kStruct };

struct WireStruct;

/// One field: `count` elements (1 for a scalar, N for a fixed array), or, when `length_field` is set, as many
/// as the earlier int32 field of that name says.
struct WireField {
  const char* name;
  Wire type;
  int count = 1;
  const char* length_field = nullptr;
  const WireStruct* nested = nullptr;
};

struct WireStruct {
  const char* name;
  std::vector<WireField> fields;
};

int fixed_size(Wire w) {
  switch (w) {
    case Wire::kI8:
    case Wire::kBool:
    case Wire::kByte:
      return 1;
    case Wire::kI16:
      return 2;
    case Wire::kI32:
    case Wire::kF32:
      return 4;
    case Wire::kI64:
    case Wire::kF64:
      return 8;
    default:
      return 0;
  }
}

// The schemas mirror lcmtypes/*.lcm field by field; tests/common/test_message_limits.cpp checks each against
// the generated encoder (the walk must end exactly at getEncodedSize()).
const WireStruct kChannelStats{"channel_stats_t",
                               {{"channel", Wire::kString},
                                {"direction", Wire::kI8},
                                {"count", Wire::kI64},
                                {"drops", Wire::kI64},
                                {"rate_hz", Wire::kF32},
                                {"last_utime", Wire::kI64}}};
const WireStruct kDetection{"detection_t",
                            {{"cx", Wire::kF32},
                             {"cy", Wire::kF32},
                             {"w", Wire::kF32},
                             {"h", Wire::kF32},
                             {"confidence", Wire::kF32},
                             {"class_id", Wire::kI16},
                             {"pass_kind", Wire::kI8},
                             {"drone_score", Wire::kF32}}};
const WireStruct kDetections{"detections_t",
                             {{"utime", Wire::kI64},
                              {"seq", Wire::kI64},
                              {"camera_id", Wire::kI32},
                              {"image_width", Wire::kI32},
                              {"image_height", Wire::kI32},
                              {"source", Wire::kI8},
                              {"inference_latency_us", Wire::kI32},
                              {"model_id", Wire::kString},
                              {"num_detections", Wire::kI32},
                              {"detections", Wire::kStruct, 0, "num_detections", &kDetection}}};
const WireStruct kVehicleTruth{"vehicle_truth_t",
                               {{"vehicle_id", Wire::kI32},
                                {"name", Wire::kString},
                                {"p_body_in_world", Wire::kF64, 3},
                                {"q_body_to_world", Wire::kF64, 4},
                                {"v_body_in_world", Wire::kF64, 3},
                                {"w_body_in_body", Wire::kF64, 3},
                                {"bounding_radius", Wire::kF64}}};
const WireStruct kTruthBox{"truth_box_t",
                           {{"vehicle_id", Wire::kI32},
                            {"camera_id", Wire::kI32},
                            {"cx", Wire::kF32},
                            {"cy", Wire::kF32},
                            {"w", Wire::kF32},
                            {"h", Wire::kF32},
                            {"visible", Wire::kBool},
                            {"range", Wire::kF64}}};
const WireStruct kGroundTruth{"ground_truth_t",
                              {{"utime", Wire::kI64},
                               {"frame", Wire::kI8},
                               {"image_seq", Wire::kI64},
                               {"num_vehicles", Wire::kI32},
                               {"vehicles", Wire::kStruct, 0, "num_vehicles", &kVehicleTruth},
                               {"num_boxes", Wire::kI32},
                               {"boxes", Wire::kStruct, 0, "num_boxes", &kTruthBox}}};
const WireStruct kImage{"image_t",
                        {{"utime", Wire::kI64},
                         {"seq", Wire::kI64},
                         {"camera_id", Wire::kI32},
                         {"width", Wire::kI32},
                         {"height", Wire::kI32},
                         {"stride", Wire::kI32},
                         {"pixel_format", Wire::kI8},
                         {"size", Wire::kI32},
                         {"data", Wire::kByte, 0, "size"}}};
const WireStruct kOwnPose{"own_pose_t",
                          {{"utime", Wire::kI64},
                           {"frame", Wire::kI8},
                           {"p_body_in_world", Wire::kF64, 3},
                           {"q_body_to_world", Wire::kF64, 4},
                           {"v_body_in_world", Wire::kF64, 3},
                           {"has_covariance", Wire::kBool},
                           {"cov_p_body_in_world", Wire::kF64, 6},
                           {"var_rpy_body", Wire::kF64, 3}}};
const WireStruct kSetpoint{"setpoint_t",
                           {{"utime", Wire::kI64},
                            {"mode", Wire::kI8},
                            {"frame", Wire::kI8},
                            {"position", Wire::kF64, 3},
                            {"velocity", Wire::kF64, 3},
                            {"yaw", Wire::kF64},
                            {"yaw_rate", Wire::kF64},
                            {"target_track_id", Wire::kI32},
                            {"detection_source", Wire::kI8}}};
const WireStruct kStatus{"status_t",
                         {{"utime", Wire::kI64},
                          {"process", Wire::kString},
                          {"pid", Wire::kI32},
                          {"state", Wire::kI8},
                          {"detail", Wire::kString},
                          {"uptime_us", Wire::kI64},
                          {"last_input_utime", Wire::kI64},
                          {"last_processed_seq", Wire::kI64},
                          {"messages_handled", Wire::kI64},
                          {"drops_total", Wire::kI64},
                          {"latency_p50_ms", Wire::kF32},
                          {"latency_p90_ms", Wire::kF32},
                          {"latency_p99_ms", Wire::kF32},
                          {"latency_max_ms", Wire::kF32},
                          {"last_error", Wire::kString},
                          {"num_channels", Wire::kI32},
                          {"channels", Wire::kStruct, 0, "num_channels", &kChannelStats}}};
const WireStruct kTarget{"target_t",
                         {{"track_id", Wire::kI32},
                          {"camera_id", Wire::kI32},
                          {"p_target_in_cam", Wire::kF64, 3},
                          {"p_target_in_world", Wire::kF64, 3},
                          {"v_target_in_world", Wire::kF64, 3},
                          {"position_covariance", Wire::kF64, 9},
                          {"velocity_covariance", Wire::kF64, 9},
                          {"world_valid", Wire::kBool},
                          {"range", Wire::kF64},
                          {"radius_m", Wire::kF64},
                          {"radius_sigma_m", Wire::kF64},
                          {"confidence", Wire::kF32},
                          {"age_s", Wire::kF32},
                          {"source_utime", Wire::kI64},
                          {"predicted_utime", Wire::kI64},
                          {"detection_source", Wire::kI8}}};
const WireStruct kTargets{"targets_t",
                          {{"utime", Wire::kI64},
                           {"frame", Wire::kI8},
                           {"num_targets", Wire::kI32},
                           {"targets", Wire::kStruct, 0, "num_targets", &kTarget}}};
const WireStruct kTrackWindow{"track_window_t",
                              {{"track_id", Wire::kI32},
                               {"confirmed", Wire::kBool},
                               {"cx", Wire::kF32},
                               {"cy", Wire::kF32},
                               {"vx", Wire::kF32},
                               {"vy", Wire::kF32},
                               {"w", Wire::kF32},
                               {"h", Wire::kF32},
                               {"sigma_px", Wire::kF32},
                               {"range_m", Wire::kF32},
                               {"confidence", Wire::kF32}}};
const WireStruct kTrackWindows{"track_windows_t",
                               {{"utime", Wire::kI64},
                                {"utime_predicted", Wire::kI64},
                                {"camera_id", Wire::kI32},
                                {"image_width", Wire::kI32},
                                {"image_height", Wire::kI32},
                                {"num_windows", Wire::kI32},
                                {"windows", Wire::kStruct, 0, "num_windows", &kTrackWindow}}};

const std::map<std::string, const WireStruct*>& schemas() {
  static const std::map<std::string, const WireStruct*> all = {{"channel_stats_t", &kChannelStats},
                                                               {"detection_t", &kDetection},
                                                               {"detections_t", &kDetections},
                                                               {"ground_truth_t", &kGroundTruth},
                                                               {"image_t", &kImage},
                                                               {"own_pose_t", &kOwnPose},
                                                               {"setpoint_t", &kSetpoint},
                                                               {"status_t", &kStatus},
                                                               {"target_t", &kTarget},
                                                               {"targets_t", &kTargets},
                                                               {"track_window_t", &kTrackWindow},
                                                               {"track_windows_t", &kTrackWindows},
                                                               {"truth_box_t", &kTruthBox},
                                                               {"vehicle_truth_t", &kVehicleTruth}};
  return all;
}

/// Walks one encoded struct; `top` holds the integer values of the top-level fields (for the image limits).
class Walker {
 public:
  Walker(const uint8_t* data, std::size_t size, std::int64_t max_elements = std::numeric_limits<std::int64_t>::max())
      : data_(data), size_(size), max_elements_(max_elements) {}

  std::size_t pos() const { return pos_; }

  std::int64_t read_be(int bytes) {
    std::uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) v = (v << 8) | data_[pos_ + static_cast<std::size_t>(i)];
    pos_ += static_cast<std::size_t>(bytes);
    // Sign-extend from `bytes` bytes.
    const int shift = 64 - 8 * bytes;
    return static_cast<std::int64_t>(v << shift) >> shift;
  }

  std::size_t left() const { return size_ - pos_; }

  /// "" or the problem; `values` receives each scalar integer field's value (index = field index).
  std::string walk(const WireStruct& s, const std::string& path, std::vector<std::int64_t>* values) {
    std::vector<std::int64_t> ints(s.fields.size(), 0);
    for (std::size_t i = 0; i < s.fields.size(); ++i) {
      const WireField& f = s.fields[i];
      const std::string name = path + "." + f.name;
      std::int64_t count = f.count;
      if (f.length_field) {
        std::size_t j = 0;
        while (j < i && std::string(s.fields[j].name) != f.length_field) ++j;
        if (j == i) throw std::logic_error("message_limits: no length field " + std::string(f.length_field));
        count = ints[j];
        const std::string length_name = path + "." + f.length_field;
        if (count < 0) return fmt::format("{} = {}: a length must not be negative", length_name, count);
        // Arrays of structs and strings (boxes, targets, channel stats) cost far more than their bytes to decode
        // and handle: bounded by count (MessageLimits::max_array_elements), before anything is decoded.
        if ((f.type == Wire::kStruct || f.type == Wire::kString) && count > max_elements_)
          return fmt::format("{} = {}: more than the {} elements accepted (max_array_elements)", length_name, count,
                             max_elements_);
        // Every element takes at least one byte: a count beyond the bytes left can never decode, and the
        // generated decoder would allocate `count` elements before finding that out.
        const std::size_t min_element = f.type == Wire::kStruct ? min_size(*f.nested) : fixed_size(f.type);
        if (static_cast<std::uint64_t>(count) * min_element > left())
          return fmt::format("{} = {}: {} needs at least {} bytes, only {} left in the message", length_name, count,
                             name, static_cast<std::uint64_t>(count) * min_element, left());
      }
      for (std::int64_t k = 0; k < count; ++k) {
        const std::string element = count > 1 || f.length_field ? fmt::format("{}[{}]", name, k) : name;
        if (f.type == Wire::kStruct) {
          std::string problem = walk(*f.nested, element, nullptr);
          if (!problem.empty()) return problem;
        } else if (f.type == Wire::kString) {
          if (left() < 4)
            return fmt::format("{}: truncated (the string length needs 4 bytes, {} left)", element, left());
          const std::int64_t len = read_be(4);
          if (len < 1)
            return fmt::format("{}: string length {} (must be at least 1, counting the terminating NUL)", element, len);
          if (static_cast<std::uint64_t>(len) > left())
            return fmt::format("{}: string length {} is more than the {} bytes left in the message", element, len,
                               left());
          pos_ += static_cast<std::size_t>(len);
        } else {
          const int n = fixed_size(f.type);
          if (f.length_field) {  // a primitive array: check all of it at once (the count fits, see above)
            pos_ += static_cast<std::size_t>(count) * static_cast<std::size_t>(n);
            break;
          }
          if (left() < static_cast<std::size_t>(n))
            return fmt::format("{}: truncated ({} bytes needed, {} left)", element, n, left());
          const std::int64_t v = read_be(n);
          if (f.count == 1 && f.type != Wire::kF32 && f.type != Wire::kF64) ints[i] = v;
        }
      }
    }
    if (values) *values = std::move(ints);
    return "";
  }

  /// Smallest encoded size of a struct: strings at their shortest (4 + 1 bytes), variable arrays empty.
  static std::size_t min_size(const WireStruct& s) {
    std::size_t n = 0;
    for (const WireField& f : s.fields) {
      if (f.length_field) continue;
      const std::size_t one = f.type == Wire::kStruct   ? min_size(*f.nested)
                              : f.type == Wire::kString ? 5
                                                        : static_cast<std::size_t>(fixed_size(f.type));
      n += one * static_cast<std::size_t>(f.count);
    }
    return n == 0 ? 1 : n;
  }

 private:
  const uint8_t* data_;
  std::size_t size_;
  std::int64_t max_elements_;
  std::size_t pos_ = 0;
};

}  // namespace

std::string MessageLimits::validate() const {
  if (max_message_bytes < 64) return fmt::format("max_message_bytes = {}: must be at least 64", max_message_bytes);
  if (image.max_width < 1 || image.max_height < 1)
    return fmt::format("image max_width x max_height = {} x {}: must be positive", image.max_width, image.max_height);
  if (max_image_bytes < 0)
    return fmt::format("max_image_bytes = {}: must be >= 0 (0 = from the size)", max_image_bytes);
  if (max_array_elements < 1) return fmt::format("max_array_elements = {}: must be >= 1", max_array_elements);
  return "";
}

std::int64_t MessageLimits::image_bytes_limit() const {
  if (max_image_bytes > 0) return max_image_bytes;
  // Saturates instead of overflowing (2^31 - 1 x 2^31 - 1 x 4 once gave a negative limit: every frame dropped).
  std::int64_t bytes = 0;
  if (__builtin_mul_overflow(static_cast<std::int64_t>(image.max_width), static_cast<std::int64_t>(image.max_height),
                             &bytes) ||
      __builtin_mul_overflow(bytes, std::int64_t{4}, &bytes))
    return std::numeric_limits<std::int64_t>::max();
  return bytes;
}

bool knows_encoding(const std::string& type_name) { return schemas().count(type_name) > 0; }

std::string check_encoded(const std::string& type_name, std::int64_t fingerprint, const void* data, std::size_t size,
                          const MessageLimits& limits) {
  const auto it = schemas().find(type_name);
  if (it == schemas().end()) throw std::invalid_argument("check_encoded: unknown message type " + type_name);
  if (size > limits.max_message_bytes)
    return fmt::format("{} bytes: larger than the {} bytes accepted (max_message_bytes)", size,
                       limits.max_message_bytes);
  Walker w(static_cast<const uint8_t*>(data), size, limits.max_array_elements);
  if (size < 8) return fmt::format("{} bytes: too short for an LCM message (8-byte fingerprint)", size);
  if (w.read_be(8) != fingerprint)
    return fmt::format("{} bytes: fingerprint is not {}'s (wrong type on this channel)", size, type_name);
  const WireStruct& s = *it->second;
  if (&s == &kImage) {
    // Check the header before the walk, so an oversized image is rejected by its limits, not just its length.
    Walker header = w;
    const std::size_t header_bytes = 8 + 8 + 4 * 4 + 1 + 4;
    if (header.left() >= header_bytes) {
      header.read_be(8);
      header.read_be(8);
      header.read_be(4);
      const std::int64_t width = header.read_be(4);
      const std::int64_t height = header.read_be(4);
      header.read_be(4);
      header.read_be(1);
      const std::int64_t bytes = header.read_be(4);
      if (width > limits.image.max_width || height > limits.image.max_height)
        return fmt::format("image_t.width x height = {} x {}: larger than the {} x {} accepted", width, height,
                           limits.image.max_width, limits.image.max_height);
      if (bytes > limits.image_bytes_limit())
        return fmt::format("image_t.size = {}: larger than the {} bytes accepted", bytes, limits.image_bytes_limit());
    }
  }
  return w.walk(s, s.name, nullptr);
}

}  // namespace wingman::common
