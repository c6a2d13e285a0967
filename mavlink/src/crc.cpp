// SPDX-License-Identifier: MIT
// CRC-16/MCRF4XX over byte ranges and strings.
#include "wingman/mavlink/crc.hpp"

namespace wingman::mavlink {

uint16_t crc_accumulate(const uint8_t* data, size_t size, uint16_t crc) {
  for (size_t i = 0; i < size; ++i) crc = crc_accumulate(data[i], crc);
  return crc;
}

uint16_t crc_accumulate(std::string_view text, uint16_t crc) {
  for (char c : text) crc = crc_accumulate(static_cast<uint8_t>(c), crc);
  return crc;
}

}  // namespace wingman::mavlink
