// SPDX-License-Identifier: MIT
// Frame encoding and the message table computed from messages.hpp.
#include "wingman/mavlink/frame.hpp"

#include <algorithm>

namespace wingman::mavlink {

void MessageLayout::add(std::string_view type, std::string_view name, size_t bytes, uint8_t array_length) {
  if (in_extensions_) {  // extensions are not part of CRC_EXTRA (old and new senders must agree)
    ext_ += bytes;
    return;
  }
  base_ += bytes;
  crc_ = crc_accumulate(type, crc_);
  crc_ = crc_accumulate(" ", crc_);
  crc_ = crc_accumulate(name, crc_);
  crc_ = crc_accumulate(" ", crc_);
  if (array_length > 0) crc_ = crc_accumulate(array_length, crc_);
}

namespace {

std::vector<MessageInfo> build_table() {
  std::vector<MessageInfo> table;
  for_each_message_type([&](auto msg) {
    using Msg = decltype(msg);
    MessageLayout layout(Msg::kName);
    msg.visit(layout);
    MessageInfo info;
    info.id = Msg::kId;
    info.name = Msg::kName;
    info.crc_extra = layout.crc_extra();
    info.base_length = static_cast<uint8_t>(layout.base_length());
    info.max_length = static_cast<uint8_t>(layout.max_length());
    table.push_back(info);
  });
  std::sort(table.begin(), table.end(), [](const MessageInfo& a, const MessageInfo& b) { return a.id < b.id; });
  return table;
}

}  // namespace

const std::vector<MessageInfo>& known_messages() {
  static const std::vector<MessageInfo> table = build_table();
  return table;
}

const MessageInfo* find_message(uint32_t msgid) {
  const auto& table = known_messages();
  auto it =
      std::lower_bound(table.begin(), table.end(), msgid, [](const MessageInfo& m, uint32_t id) { return m.id < id; });
  return it != table.end() && it->id == msgid ? &*it : nullptr;
}

std::vector<uint8_t> encode_frame(const MessageInfo& info, const uint8_t* payload, const Sender& sender,
                                  Version version) {
  std::vector<uint8_t> out;
  size_t length = 0;
  if (version == Version::kV1) {
    if (info.id > 255)
      throw std::invalid_argument(std::string("mavlink: ") + info.name + " (id " + std::to_string(info.id) +
                                  ") cannot be sent as MAVLink 1");
    length = info.base_length;  // MAVLink 1 has no extensions
    out.reserve(kHeaderSizeV1 + length + kChecksumSize);
    out = {kStxV1,        static_cast<uint8_t>(length), sender.seq, sender.sysid,
           sender.compid, static_cast<uint8_t>(info.id)};
  } else {
    length = info.max_length;
    while (length > 1 && payload[length - 1] == 0) --length;  // v2: trailing zeros dropped, the first byte kept
    out.reserve(kHeaderSizeV2 + length + kChecksumSize);
    out = {kStxV2,
           static_cast<uint8_t>(length),
           0,
           0,
           sender.seq,
           sender.sysid,
           sender.compid,
           static_cast<uint8_t>(info.id & 0xFF),
           static_cast<uint8_t>((info.id >> 8) & 0xFF),
           static_cast<uint8_t>((info.id >> 16) & 0xFF)};
  }
  out.insert(out.end(), payload, payload + length);
  uint16_t crc = crc_accumulate(out.data() + 1, out.size() - 1, kCrcInit);
  crc = crc_accumulate(info.crc_extra, crc);
  out.push_back(static_cast<uint8_t>(crc & 0xFF));
  out.push_back(static_cast<uint8_t>(crc >> 8));
  return out;
}

}  // namespace wingman::mavlink
