// SPDX-License-Identifier: MIT
// The streaming parser: find a start byte, wait for the header and the frame, check it, hand it on or drop it.
#include "wingman/mavlink/parser.hpp"

#include <algorithm>
#include <cstring>

namespace wingman::mavlink {

std::string ParserStats::summary() const {
  return "frames " + std::to_string(frames) + ", garbage " + std::to_string(garbage_bytes) + " B, bad crc " +
         std::to_string(bad_crc) + ", bad length " + std::to_string(bad_length) + ", unknown " +
         std::to_string(unknown_messages) + ", signed refused " + std::to_string(signed_refused) + ", incompatible " +
         std::to_string(incompatible_flags) + ", truncated " + std::to_string(truncated);
}

void Parser::feed(const uint8_t* data, size_t size, const FrameHandler& on_frame) {
  stats_.bytes += static_cast<int64_t>(size);
  buffer_.reserve(kMaxFrameSize);
  while (size > 0) {
    const size_t n = std::min(size, kMaxFrameSize - buffer_.size());
    buffer_.insert(buffer_.end(), data, data + n);
    data += n;
    size -= n;
    process(on_frame);
  }
}

void Parser::end_of_datagram(const FrameHandler& on_frame) {
  if (buffer_.empty()) return;
  // No more bytes will come for the candidate frame at the front: it was cut off, or its start byte was garbage
  // and a real frame follows inside the buffer. Drop start bytes until the rest parses or nothing is left.
  ++stats_.truncated;
  while (!buffer_.empty()) {
    ++stats_.garbage_bytes;
    consume(1);
    process(on_frame);
  }
}

void Parser::consume(size_t n) { buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(n)); }

void Parser::process(const FrameHandler& on_frame) {
  for (;;) {
    // Skip to a start byte.
    auto stx = std::find_if(buffer_.begin(), buffer_.end(), [](uint8_t b) { return b == kStxV1 || b == kStxV2; });
    const size_t skipped = static_cast<size_t>(stx - buffer_.begin());
    if (skipped > 0) {
      stats_.garbage_bytes += static_cast<int64_t>(skipped);
      consume(skipped);
    }
    if (buffer_.empty()) return;
    const bool v2 = buffer_[0] == kStxV2;
    const size_t header = v2 ? kHeaderSizeV2 : kHeaderSizeV1;
    if (buffer_.size() < header) return;
    const uint8_t length = buffer_[1];
    const uint8_t incompat = v2 ? buffer_[2] : 0;
    const uint32_t msgid = v2 ? static_cast<uint32_t>(buffer_[7]) | (static_cast<uint32_t>(buffer_[8]) << 8) |
                                    (static_cast<uint32_t>(buffer_[9]) << 16)
                              : buffer_[5];
    const MessageInfo* info = find_message(msgid);
    // Start bytes inside garbage are told apart from real frames by their header where it can be, at once, without
    // waiting for bytes that may never come: no CRC_EXTRA can check a frame of an unknown message, so only a v2
    // header with known incompatibility flags is taken as one (and skipped whole); a v1 header of an unknown
    // message (v1 has no flags to check) or of a known one with a payload longer than its fields (some senders add
    // the extensions, none more) is garbage. Such a start byte is dropped and the search goes on behind it.
    const bool plausible =
        info != nullptr ? (v2 || length <= info->max_length) : (v2 && (incompat & ~kIncompatFlagSigned) == 0);
    if (!plausible) {
      ++stats_.garbage_bytes;
      consume(1);
      continue;
    }
    const size_t frame_size = header + length + kChecksumSize + ((incompat & kIncompatFlagSigned) ? kSignatureSize : 0);
    if (buffer_.size() < frame_size) return;
    if (info == nullptr) {
      ++stats_.unknown_messages;
      consume(frame_size);
      continue;
    }
    uint16_t crc = crc_accumulate(buffer_.data() + 1, header - 1 + length, kCrcInit);
    crc = crc_accumulate(info->crc_extra, crc);
    const size_t crc_at = header + length;
    const uint16_t wire_crc = static_cast<uint16_t>(buffer_[crc_at] | (buffer_[crc_at + 1] << 8));
    if (crc != wire_crc) {  // not a frame (or a damaged one): drop its start byte and look again
      ++stats_.bad_crc;
      ++stats_.garbage_bytes;
      consume(1);
      continue;
    }
    if (incompat & kIncompatFlagSigned) {
      ++stats_.signed_refused;
      consume(frame_size);
      continue;
    }
    if (incompat != 0) {
      ++stats_.incompatible_flags;
      consume(frame_size);
      continue;
    }
    if (!v2 && length < info->base_length) {
      ++stats_.bad_length;
      consume(frame_size);
      continue;
    }
    frame_.version = v2 ? Version::kV2 : Version::kV1;
    frame_.incompat_flags = incompat;
    frame_.compat_flags = v2 ? buffer_[3] : 0;
    frame_.seq = buffer_[v2 ? 4 : 2];
    frame_.sysid = buffer_[v2 ? 5 : 3];
    frame_.compid = buffer_[v2 ? 6 : 4];
    frame_.msgid = msgid;
    // Bytes past the fields this codec knows (a newer sender's extensions) are ignored.
    frame_.payload_length = std::min(length, info->max_length);
    frame_.payload.fill(0);
    std::memcpy(frame_.payload.data(), buffer_.data() + header, frame_.payload_length);
    ++stats_.frames;
    consume(frame_size);
    on_frame(frame_);
  }
}

}  // namespace wingman::mavlink
