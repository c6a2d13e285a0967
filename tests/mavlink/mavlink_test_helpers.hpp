// SPDX-License-Identifier: MIT
// Test helpers for the MAVLink codec: seeded random messages, payload bytes, and messages as name=value text.
#pragma once

#include <wingman/mavlink/frame.hpp>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <type_traits>

namespace wingman::mavlink::test {

/// Fills every field of a message with seeded random values; each field is zero with probability `zero_p`, so
/// trailing fields are often zero (v2 truncation) and extensions often absent.
class Randomizer {
 public:
  Randomizer(std::mt19937& rng, double zero_p) : rng_(rng), zero_p_(zero_p) {}
  template <class T>
  void field(std::string_view, T& v) {
    v = draw<T>();
  }
  template <class T, size_t N>
  void field(std::string_view, std::array<T, N>& a) {
    for (T& v : a) v = draw<T>();
  }
  void extensions() {}

 private:
  template <class T>
  T draw() {
    if (std::uniform_real_distribution<double>(0, 1)(rng_) < zero_p_) return T{};
    if constexpr (std::is_floating_point_v<T>)
      return static_cast<T>(std::uniform_real_distribution<double>(-2000.0, 2000.0)(rng_));
    else
      return static_cast<T>(std::uniform_int_distribution<uint64_t>(1, ~uint64_t{0})(rng_));
  }
  std::mt19937& rng_;
  double zero_p_;
};

/// A message's payload bytes (kMaxPayload, zero past its fields): two messages are equal when these are.
template <class Msg>
std::array<uint8_t, kMaxPayload> payload_bytes(const Msg& msg) {
  std::array<uint8_t, kMaxPayload> out{};
  PayloadWriter w(out.data());
  const_cast<Msg&>(msg).visit(w);
  return out;
}

/// Writes fields as " name=value" (floats exactly, as %.17g of the float's double; arrays comma-separated).
class TextWriter {
 public:
  template <class T>
  void field(std::string_view name, const T& v) {
    out_ << ' ' << name << '=' << text(v);
  }
  template <class T, size_t N>
  void field(std::string_view name, const std::array<T, N>& a) {
    out_ << ' ' << name << '=';
    for (size_t i = 0; i < N; ++i) out_ << (i ? "," : "") << text(a[i]);
  }
  void extensions() {}
  std::string str() const { return out_.str(); }

 private:
  template <class T>
  static std::string text(T v) {
    if constexpr (std::is_floating_point_v<T>) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.17g", static_cast<double>(v));
      return buf;
    } else if constexpr (std::is_signed_v<T>) {
      return std::to_string(static_cast<int64_t>(v));
    } else {
      return std::to_string(static_cast<uint64_t>(v));
    }
  }
  std::ostringstream out_;
};

/// Reads fields from name=value pairs (as TextWriter writes them); names missing from the map are listed in
/// missing().
class TextReader {
 public:
  explicit TextReader(const std::map<std::string, std::string>& values) : values_(values) {}
  template <class T>
  void field(std::string_view name, T& v) {
    auto it = values_.find(std::string(name));
    if (it == values_.end()) {
      missing_ += std::string(name) + " ";
      return;
    }
    v = parse<T>(it->second);
  }
  template <class T, size_t N>
  void field(std::string_view name, std::array<T, N>& a) {
    auto it = values_.find(std::string(name));
    if (it == values_.end()) {
      missing_ += std::string(name) + " ";
      return;
    }
    std::istringstream in(it->second);
    std::string item;
    for (size_t i = 0; i < N && std::getline(in, item, ','); ++i) a[i] = parse<T>(item);
  }
  void extensions() {}
  const std::string& missing() const { return missing_; }

 private:
  template <class T>
  static T parse(const std::string& s) {
    if constexpr (std::is_floating_point_v<T>)
      return static_cast<T>(std::strtod(s.c_str(), nullptr));
    else if constexpr (std::is_signed_v<T>)
      return static_cast<T>(std::strtoll(s.c_str(), nullptr, 10));
    else
      return static_cast<T>(std::strtoull(s.c_str(), nullptr, 10));
  }
  const std::map<std::string, std::string>& values_;
  std::string missing_;
};

/// Hex of a byte string.
inline std::string to_hex(const std::vector<uint8_t>& bytes) {
  static const char* digits = "0123456789abcdef";
  std::string s;
  for (uint8_t b : bytes) {
    s += digits[b >> 4];
    s += digits[b & 15];
  }
  return s;
}

/// Bytes of a hex string.
inline std::vector<uint8_t> from_hex(const std::string& hex) {
  std::vector<uint8_t> out;
  for (size_t i = 0; i + 1 < hex.size(); i += 2)
    out.push_back(static_cast<uint8_t>(std::strtoul(hex.substr(i, 2).c_str(), nullptr, 16)));
  return out;
}

}  // namespace wingman::mavlink::test
