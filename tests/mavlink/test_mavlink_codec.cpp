// SPDX-License-Identifier: MIT
// The codec's checksum, message table, framing and round trips.
#include "mavlink_test_helpers.hpp"

#include <wingman/mavlink/enums.hpp>
#include <wingman/mavlink/parser.hpp>

#include <gtest/gtest.h>

#include <cstring>

using namespace wingman::mavlink;
using namespace wingman::mavlink::test;

TEST(MavlinkCrc, MatchesTheMcrf4xxCheckValue) {
  // CRC-16/MCRF4XX of "123456789" is 0x6F91 (the catalogue's check value).
  EXPECT_EQ(crc_accumulate(std::string_view("123456789"), kCrcInit), 0x6F91);
}

TEST(MavlinkMessageTable, CrcExtraAndLengthsComputedFromTheFieldListsMatchThePublishedValues) {
  // Published values: CRC_EXTRA and payload lengths of MAVLink's generated C headers (and mavlink-mappings'
  // MAGIC_NUMBER / PAYLOAD_LENGTH) for these messages.
  struct Known {
    uint32_t id;
    uint8_t crc_extra, base_length, max_length;
  };
  const Known known[] = {{0, 50, 9, 9},     {2, 137, 12, 12},   {31, 246, 32, 48}, {32, 185, 28, 28},
                         {76, 152, 33, 33}, {77, 143, 3, 10},   {84, 143, 53, 53}, {85, 140, 51, 51},
                         {111, 34, 16, 18}, {331, 91, 230, 233}};
  ASSERT_EQ(known_messages().size(), std::size(known));
  for (const Known& k : known) {
    const MessageInfo* info = find_message(k.id);
    ASSERT_NE(info, nullptr) << "id " << k.id;
    EXPECT_EQ(info->crc_extra, k.crc_extra) << info->name;
    EXPECT_EQ(info->base_length, k.base_length) << info->name;
    EXPECT_EQ(info->max_length, k.max_length) << info->name;
  }
  EXPECT_EQ(find_message(1), nullptr);
}

TEST(MavlinkFrame, HeartbeatV2HasTheLayoutOfTheSpecification) {
  Heartbeat hb;
  hb.custom_mode = px4_custom_mode(kPx4MainModeOffboard);
  hb.type = kMavTypeQuadrotor;
  hb.autopilot = kMavAutopilotPx4;
  hb.base_mode = kMavModeFlagSafetyArmed | kMavModeFlagCustomModeEnabled;
  hb.system_status = kMavStateActive;
  const auto f = encode(hb, Sender{1, 1, 7});
  ASSERT_EQ(f.size(), kHeaderSizeV2 + 9 + kChecksumSize);
  const std::vector<uint8_t> head = {0xFD, 9, 0, 0, 7, 1, 1, 0, 0, 0, 0x00, 0x00, 0x06, 0x00, 2, 12, 129, 4, 3};
  EXPECT_EQ(std::vector<uint8_t>(f.begin(), f.begin() + 19), head);
  uint16_t crc = crc_accumulate(f.data() + 1, f.size() - 3, kCrcInit);
  crc = crc_accumulate(uint8_t{50}, crc);
  EXPECT_EQ(f[f.size() - 2], crc & 0xFF);
  EXPECT_EQ(f[f.size() - 1], crc >> 8);
}

TEST(MavlinkFrame, V2DropsTrailingZerosButKeepsTheFirstPayloadByte) {
  CommandAck ack;  // all zero
  auto f = encode(ack, Sender{});
  EXPECT_EQ(f[1], 1) << "an all-zero payload keeps one byte";
  ack.command = kMavCmdSetMessageInterval;
  ack.result = kMavResultAccepted;
  f = encode(ack, Sender{});
  EXPECT_EQ(f[1], 2) << "command (2 bytes), result 0 and the zero extensions dropped";
  ack.target_component = 191;
  f = encode(ack, Sender{});
  EXPECT_EQ(f[1], 10) << "an extension at the end keeps everything before it";
}

TEST(MavlinkFrame, V1SendsTheBaseFieldsOnlyAndRefusesLargeIds) {
  AttitudeQuaternion q;
  q.repr_offset_q = {1, 0, 0, 0};
  const auto f = encode(q, Sender{}, Version::kV1);
  EXPECT_EQ(f[0], kStxV1);
  EXPECT_EQ(f[1], 32);
  EXPECT_EQ(f.size(), kHeaderSizeV1 + 32 + kChecksumSize);
  EXPECT_THROW(encode(Odometry{}, Sender{}, Version::kV1), std::invalid_argument);
}

template <class Msg>
void expect_round_trip(Version version, std::mt19937& rng) {
  for (int i = 0; i < 50; ++i) {
    Msg msg;
    Randomizer random(rng, i % 3 == 0 ? 0.0 : 0.5);
    msg.visit(random);
    const auto bytes = encode(msg, Sender{3, 4, static_cast<uint8_t>(i)}, version);
    Parser parser;
    int frames = 0;
    parser.feed(bytes.data(), bytes.size(), [&](const Frame& f) {
      ++frames;
      Msg back;
      ASSERT_TRUE(decode(f, back));
      auto expected = payload_bytes(msg);
      if (version == Version::kV1) {  // extensions are not sent in v1: they read as zero
        const MessageInfo* info = find_message(Msg::kId);
        std::fill(expected.begin() + info->base_length, expected.end(), 0);
      }
      EXPECT_EQ(payload_bytes(back), expected) << Msg::kName;
      EXPECT_EQ(f.sysid, 3);
      EXPECT_EQ(f.compid, 4);
      EXPECT_EQ(f.seq, i);
    });
    EXPECT_EQ(frames, 1) << Msg::kName << ": " << parser.stats().summary();
  }
}

TEST(MavlinkFrame, EveryMessageRoundTripsThroughTheParserAsV2AndV1) {
  std::mt19937 rng(7);
  for_each_message_type([&](auto msg) {
    using Msg = decltype(msg);
    expect_round_trip<Msg>(Version::kV2, rng);
    if (Msg::kId <= 255) expect_round_trip<Msg>(Version::kV1, rng);
  });
}

TEST(MavlinkFrame, DecodeRefusesAnotherMessageId) {
  Frame f;
  f.msgid = Heartbeat::kId;
  Timesync t;
  EXPECT_FALSE(decode(f, t));
}
