// SPDX-License-Identifier: MIT
// Checks of an encoded LCM message before it is decoded, and the one decode path every subscription uses.
//
// LCM's generated C++ decoders (lcm-gen 1.3.1) resize a variable-length array to its declared length before they
// look at the buffer: a 40-byte image_t that claims 2^31 data bytes would allocate 2 GB, a negative length throws
// from std::vector. check_encoded() walks the wire format first and rejects such messages, naming the field.
#pragma once

#include "wingman/common/message_validation.hpp"

#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <string>

namespace wingman::common {

/// Limits applied to every incoming message before it is decoded (Runtime::set_message_limits()).
struct MessageLimits {
  /// Largest encoded message accepted on any channel, bytes. 64 MiB holds a 4096 x 4096 BGR8 image (48 MiB).
  std::size_t max_message_bytes = 64u << 20;
  /// image_t: width and height above these are rejected before the pixels are decoded (pixels).
  ImageLimits image;
  /// image_t: largest `size` (data bytes) accepted; 0 = width x height x 4 of `image`.
  std::int64_t max_image_bytes = 0;
  /// Longest variable-length array of structs or strings accepted (boxes per detections_t, targets per targets_t,
  /// channels per status_t), elements, >= 1: a longer one is rejected before decoding. One detections_t of 10^6
  /// boxes cost the localizer 1.5 GB and 15 s (issue 33).
  std::int64_t max_array_elements = 4096;

  /// "" or one line naming the bad limit.
  std::string validate() const;
  /// The effective image_t data limit, bytes.
  std::int64_t image_bytes_limit() const;
};

/// "" when the `size` bytes at `data` are a well-formed encoding of LCM type `type_name` (e.g. "image_t", whose
/// fingerprint is `fingerprint`) within `limits`: the fingerprint matches, every field lies inside the buffer, every
/// string and variable-length array length is non-negative and fits in the bytes that remain (bytes after the end
/// of the message are allowed, as in LCM). Otherwise one line naming the type, the field and the rule, e.g.
/// "image_t.size = 2147483647: more than the 0 bytes left in the message". Checks only the wire format and the
/// limits; the values are validate_message()'s job. Throws std::invalid_argument for a type it does not know.
std::string check_encoded(const std::string& type_name, std::int64_t fingerprint, const void* data, std::size_t size,
                          const MessageLimits& limits);

/// check_encoded() for message type Msg.
template <class Msg>
std::string check_encoded(const void* data, std::size_t size, const MessageLimits& limits) {
  return check_encoded(Msg::getTypeName(), Msg::getHash(), data, size, limits);
}

/// True when check_encoded() knows `type_name` (every type in lcmtypes/).
bool knows_encoding(const std::string& type_name);

/// Decodes `size` bytes at `data` into `msg` and checks it: check_encoded(), then Msg::decode(), then `validate`
/// (may be empty). Returns "" when `msg` may be handled, else the reason the message is dropped (without channel).
/// This is the whole path from a received LCM payload to a handler (Runtime's subscriptions, the fuzz targets).
template <class Msg>
std::string decode_message(const void* data, std::size_t size, const MessageLimits& limits, Msg& msg,
                           const std::function<std::string(const Msg&)>& validate) {
  std::string problem = check_encoded<Msg>(data, size, limits);
  if (!problem.empty()) return problem;
  int decoded = -1;
  try {
    decoded = msg.decode(data, 0, static_cast<int>(size));
  } catch (const std::exception&) {  // not expected after check_encoded(); kept as the last line of defence
    decoded = -1;
  }
  if (decoded < 0)
    return std::to_string(size) + " bytes do not decode as " + Msg::getTypeName() + " (wrong type or truncated)";
  return validate ? validate(msg) : std::string();
}

}  // namespace wingman::common
