// SPDX-License-Identifier: MIT
// CRC-16/MCRF4XX (the "X.25" checksum of MAVLink frames) and the per-message CRC_EXTRA seed byte.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace wingman::mavlink {

/// Initial value of a frame checksum.
constexpr uint16_t kCrcInit = 0xFFFF;

/// Adds one byte to a CRC-16/MCRF4XX (polynomial 0x1021 reflected, init 0xFFFF, no final xor), as
/// MAVLink's crc_accumulate.
constexpr uint16_t crc_accumulate(uint8_t byte, uint16_t crc) {
  uint8_t tmp = static_cast<uint8_t>(byte ^ static_cast<uint8_t>(crc & 0xFF));
  tmp = static_cast<uint8_t>(tmp ^ static_cast<uint8_t>(tmp << 4));
  return static_cast<uint16_t>((crc >> 8) ^ (static_cast<uint16_t>(tmp) << 8) ^ (static_cast<uint16_t>(tmp) << 3) ^
                               (tmp >> 4));
}

/// Adds `size` bytes to `crc`.
uint16_t crc_accumulate(const uint8_t* data, size_t size, uint16_t crc);
/// Adds the characters of `text` to `crc`.
uint16_t crc_accumulate(std::string_view text, uint16_t crc);

}  // namespace wingman::mavlink
