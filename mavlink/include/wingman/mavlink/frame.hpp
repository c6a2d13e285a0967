// SPDX-License-Identifier: MIT
// MAVLink frames: v2 (v1 on receive and on request), header fields, checksum, the table of known messages, and
// encoding and decoding of the messages of messages.hpp.
#pragma once

#include "wingman/mavlink/crc.hpp"
#include "wingman/mavlink/messages.hpp"
#include "wingman/mavlink/wire.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace wingman::mavlink {

constexpr uint8_t kStxV1 = 0xFE;               ///< start byte of a MAVLink 1 frame
constexpr uint8_t kStxV2 = 0xFD;               ///< start byte of a MAVLink 2 frame
constexpr size_t kHeaderSizeV1 = 6;            ///< STX, len, seq, sysid, compid, msgid
constexpr size_t kHeaderSizeV2 = 10;           ///< STX, len, incompat, compat, seq, sysid, compid, msgid (3 bytes)
constexpr size_t kChecksumSize = 2;            ///< CRC-16/MCRF4XX, little-endian
constexpr size_t kSignatureSize = 13;          ///< link id, 6-byte timestamp, 6-byte signature
constexpr uint8_t kIncompatFlagSigned = 0x01;  ///< MAVLINK_IFLAG_SIGNED: the frame carries a signature
/// Largest frame on the wire, bytes (v2, full payload, signed).
constexpr size_t kMaxFrameSize = kHeaderSizeV2 + kMaxPayload + kChecksumSize + kSignatureSize;

enum class Version : uint8_t { kV1 = 1, kV2 = 2 };

/// One received frame, checked (checksum, known message, length) and unsigned.
struct Frame {
  Version version = Version::kV2;
  uint8_t incompat_flags = 0;                  ///< v2 only
  uint8_t compat_flags = 0;                    ///< v2 only
  uint8_t seq = 0;                             ///< sender's packet sequence (gaps: lost frames)
  uint8_t sysid = 0;                           ///< sender's system id
  uint8_t compid = 0;                          ///< sender's component id
  uint32_t msgid = 0;                          ///< message id (24 bits in v2, 8 in v1)
  uint8_t payload_length = 0;                  ///< bytes received (a v2 sender drops trailing zeros)
  std::array<uint8_t, kMaxPayload> payload{};  ///< the payload, zero past payload_length
};

/// Who sends a frame, and its sequence number.
struct Sender {
  uint8_t sysid = 1;   ///< system id
  uint8_t compid = 1;  ///< component id
  uint8_t seq = 0;     ///< packet sequence
};

/// What the codec knows of a message, computed from its field list (messages.hpp).
struct MessageInfo {
  uint32_t id = 0;
  const char* name = "";
  uint8_t crc_extra = 0;    ///< seed byte added to the checksum: from the name, types and names of the base fields
  uint8_t base_length = 0;  ///< payload bytes of the fields before the extensions (a v1 payload)
  uint8_t max_length = 0;   ///< payload bytes with the extensions
};

/// The message with id `msgid`, or nullptr when the codec does not handle it.
const MessageInfo* find_message(uint32_t msgid);
/// Every message the codec handles, in id order.
const std::vector<MessageInfo>& known_messages();

/// Computes MessageInfo from a message's field list: CRC_EXTRA is CRC-16/MCRF4XX over "NAME " and, per base field
/// in wire order, "type name " (and the array length as one byte), folded to one byte (low ^ high), as MAVLink's
/// generators compute it.
class MessageLayout {
 public:
  explicit MessageLayout(const char* name) : crc_(crc_accumulate(std::string(name) + " ", kCrcInit)) {}
  template <class T>
  void field(std::string_view name, const T&) {
    add(type_name<T>(), name, sizeof(T), 0);
  }
  template <class T, size_t N>
  void field(std::string_view name, const std::array<T, N>&) {
    add(type_name<T>(), name, sizeof(T) * N, static_cast<uint8_t>(N));
  }
  void extensions() { in_extensions_ = true; }
  uint8_t crc_extra() const { return static_cast<uint8_t>((crc_ & 0xFF) ^ (crc_ >> 8)); }
  size_t base_length() const { return base_; }
  size_t max_length() const { return base_ + ext_; }

 private:
  void add(std::string_view type, std::string_view name, size_t bytes, uint8_t array_length);
  uint16_t crc_;
  size_t base_ = 0, ext_ = 0;
  bool in_extensions_ = false;
};

/// Builds a frame around an already serialized payload (`payload_length` bytes; v2 truncates trailing zeros, keeping
/// at least one byte; v1 sends the info's base_length bytes). Throws std::invalid_argument for a v1 frame of a
/// message id above 255.
std::vector<uint8_t> encode_frame(const MessageInfo& info, const uint8_t* payload, const Sender& sender,
                                  Version version);

/// One message as a complete frame, ready to write. Throws std::invalid_argument when the message is not in the
/// table or cannot be sent as `version`.
template <class Msg>
std::vector<uint8_t> encode(const Msg& msg, const Sender& sender, Version version = Version::kV2) {
  const MessageInfo* info = find_message(Msg::kId);
  if (info == nullptr) throw std::invalid_argument(std::string("mavlink: no table entry for ") + Msg::kName);
  std::array<uint8_t, kMaxPayload> payload{};
  PayloadWriter writer(payload.data());
  const_cast<Msg&>(msg).visit(writer);  // visit() only reads through a writer
  return encode_frame(*info, payload.data(), sender, version);
}

/// The message in `frame`, or false when the frame holds another message id.
template <class Msg>
bool decode(const Frame& frame, Msg& out) {
  if (frame.msgid != Msg::kId) return false;
  out = Msg{};
  PayloadReader reader(frame.payload.data());
  out.visit(reader);
  return true;
}

}  // namespace wingman::mavlink
