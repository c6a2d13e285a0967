// SPDX-License-Identifier: MIT
// The type fingerprint at the start of an encoded LCM message (internal to the tools).
#pragma once

#include <cstdint>

namespace wingman::tools {

/// The 8-byte big-endian type hash an LCM encoding starts with (compare with Msg::getHash()); 0 when shorter.
inline uint64_t lcm_fingerprint(const void* data, int size) {
  if (size < 8) return 0;
  const auto* p = static_cast<const uint8_t*>(data);
  uint64_t h = 0;
  for (int i = 0; i < 8; ++i) h = (h << 8) | p[i];
  return h;
}

}  // namespace wingman::tools
