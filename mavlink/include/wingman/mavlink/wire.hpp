// SPDX-License-Identifier: MIT
// MAVLink payload serialization: little-endian fields in wire order, walked by a message's visit().
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>
#include <type_traits>

namespace wingman::mavlink {

/// Largest MAVLink payload, bytes.
constexpr size_t kMaxPayload = 255;

/// The MAVLink type name of a C++ field type, as the CRC_EXTRA computation spells it.
template <class T>
constexpr std::string_view type_name() {
  if constexpr (std::is_same_v<T, char>)
    return "char";
  else if constexpr (std::is_same_v<T, uint8_t>)
    return "uint8_t";
  else if constexpr (std::is_same_v<T, int8_t>)
    return "int8_t";
  else if constexpr (std::is_same_v<T, uint16_t>)
    return "uint16_t";
  else if constexpr (std::is_same_v<T, int16_t>)
    return "int16_t";
  else if constexpr (std::is_same_v<T, uint32_t>)
    return "uint32_t";
  else if constexpr (std::is_same_v<T, int32_t>)
    return "int32_t";
  else if constexpr (std::is_same_v<T, uint64_t>)
    return "uint64_t";
  else if constexpr (std::is_same_v<T, int64_t>)
    return "int64_t";
  else if constexpr (std::is_same_v<T, float>)
    return "float";
  else if constexpr (std::is_same_v<T, double>)
    return "double";
  else
    static_assert(sizeof(T) == 0, "not a MAVLink field type");
}

/// The unsigned integer of a field type's size (its bits on the wire).
template <class T>
using WireBits = std::conditional_t<
    sizeof(T) == 1, uint8_t,
    std::conditional_t<sizeof(T) == 2, uint16_t, std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>>>;

/// The unsigned integer of a field type's size (its bits on the wire).
template <class T>
using WireBits = std::conditional_t<
    sizeof(T) == 1, uint8_t,
    std::conditional_t<sizeof(T) == 2, uint16_t, std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>>>;

/// Writes fields little-endian one after the other into a payload buffer (a message's visit() calls field()).
/// Precondition: the message's fields fit kMaxPayload (they do for every message of messages.hpp).
class PayloadWriter {
 public:
  explicit PayloadWriter(uint8_t* out) : out_(out) {}
  template <class T>
  void field(std::string_view /*name*/, const T& value) {
    put(value);
  }
  template <class T, size_t N>
  void field(std::string_view /*name*/, const std::array<T, N>& values) {
    for (const T& v : values) put(v);
  }
  void extensions() {}
  size_t size() const { return size_; }

 private:
  template <class T>
  void put(T value) {
    static_assert(std::is_arithmetic_v<T>);
    using U = WireBits<T>;
    U bits;
    std::memcpy(&bits, &value, sizeof(T));
    for (size_t i = 0; i < sizeof(T); ++i) out_[size_++] = static_cast<uint8_t>(bits >> (8 * i));
  }
  uint8_t* out_;
  size_t size_ = 0;
};

/// Reads fields little-endian from a zero-filled kMaxPayload buffer (bytes a v2 sender truncated read as zero).
class PayloadReader {
 public:
  explicit PayloadReader(const uint8_t* in) : in_(in) {}
  template <class T>
  void field(std::string_view /*name*/, T& value) {
    get(value);
  }
  template <class T, size_t N>
  void field(std::string_view /*name*/, std::array<T, N>& values) {
    for (T& v : values) get(v);
  }
  void extensions() {}

 private:
  template <class T>
  void get(T& value) {
    static_assert(std::is_arithmetic_v<T>);
    using U = WireBits<T>;
    U bits = 0;
    for (size_t i = 0; i < sizeof(T); ++i) bits = static_cast<U>(bits | (static_cast<U>(in_[pos_++]) << (8 * i)));
    std::memcpy(&value, &bits, sizeof(T));
  }
  const uint8_t* in_;
  size_t pos_ = 0;
};

}  // namespace wingman::mavlink
