// SPDX-License-Identifier: MIT
// The streaming parser under bad input: garbage, bad checksums, cut-off frames, signed and incompatible frames,
// unknown messages, byte-by-byte feeding and a flood. Every byte is accounted for in the counters.
#include "mavlink_test_helpers.hpp"

#include <wingman/mavlink/enums.hpp>
#include <wingman/mavlink/parser.hpp>

#include <gtest/gtest.h>

using namespace wingman::mavlink;
using namespace wingman::mavlink::test;

namespace {

std::vector<uint8_t> heartbeat_frame(uint8_t seq) {
  Heartbeat hb;
  hb.custom_mode = 0x12345678;
  hb.type = kMavTypeQuadrotor;
  return encode(hb, Sender{1, 1, seq});
}

std::vector<uint8_t> timesync_frame(int64_t ts1) {
  Timesync t;
  t.ts1 = ts1;
  return encode(t, Sender{1, 1, 0});
}

/// Feeds `bytes` in one call; returns the sequence numbers of the frames found.
std::vector<int> feed(Parser& p, const std::vector<uint8_t>& bytes) {
  std::vector<int> seqs;
  p.feed(bytes.data(), bytes.size(), [&](const Frame& f) { seqs.push_back(f.seq); });
  return seqs;
}

void append(std::vector<uint8_t>& a, const std::vector<uint8_t>& b) { a.insert(a.end(), b.begin(), b.end()); }

/// Appends the checksum of `frame` (header and payload, without one) for a message with `crc_extra`.
std::vector<uint8_t> with_crc(std::vector<uint8_t> frame, uint8_t crc_extra) {
  uint16_t crc = crc_accumulate(frame.data() + 1, frame.size() - 1, kCrcInit);
  crc = crc_accumulate(crc_extra, crc);
  frame.push_back(static_cast<uint8_t>(crc & 0xFF));
  frame.push_back(static_cast<uint8_t>(crc >> 8));
  return frame;
}

/// A heartbeat frame whose header's incompatibility flags are `flags` (checksum recomputed).
std::vector<uint8_t> heartbeat_with_flags(uint8_t flags) {
  auto f = heartbeat_frame(1);
  f.resize(f.size() - kChecksumSize);
  f[2] = flags;
  return with_crc(f, 50);
}

}  // namespace

TEST(MavlinkParser, FindsFramesBetweenGarbageIncludingStartBytes) {
  std::vector<uint8_t> s = {0x00, 0xFD, 0x01, 0xFE, 0x55};  // garbage with both start bytes
  append(s, heartbeat_frame(1));
  append(s, {0xFD, 0xFD, 0x13});
  append(s, heartbeat_frame(2));
  Parser p;
  EXPECT_EQ(feed(p, s), (std::vector<int>{1, 2}));
  // The garbage's start bytes began candidate frames that failed their checksum or were skipped as unknown
  // messages; either way the real frames were found.
  EXPECT_EQ(p.stats().frames, 2);
  EXPECT_GE(p.stats().garbage_bytes, 3);
}

TEST(MavlinkParser, ABadChecksumCostsOnlyTheStartByte) {
  auto bad = heartbeat_frame(1);
  bad[12] ^= 0x40;  // a payload bit flipped
  std::vector<uint8_t> s = bad;
  append(s, heartbeat_frame(2));
  Parser p;
  EXPECT_EQ(feed(p, s), (std::vector<int>{2}));
  EXPECT_EQ(p.stats().bad_crc, 1);
  EXPECT_EQ(p.stats().garbage_bytes, static_cast<int64_t>(bad.size()));
}

TEST(MavlinkParser, AFrameCutOffByTheNextIsDroppedAndTheNextFound) {
  auto cut = heartbeat_frame(1);
  cut.resize(cut.size() - 5);
  std::vector<uint8_t> s = cut;
  append(s, heartbeat_frame(2));
  append(s, heartbeat_frame(3));
  Parser p;
  EXPECT_EQ(feed(p, s), (std::vector<int>{2, 3}));
  EXPECT_EQ(p.stats().bad_crc, 1);
}

TEST(MavlinkParser, APartialFrameAtTheEndOfADatagramIsCountedAsTruncated) {
  auto f = heartbeat_frame(1);
  Parser p;
  p.feed(f.data(), 8, [](const Frame&) { FAIL(); });
  p.end_of_datagram([](const Frame&) { FAIL(); });
  EXPECT_EQ(p.stats().truncated, 1);
  EXPECT_EQ(feed(p, f), (std::vector<int>{1}));
}

TEST(MavlinkParser, AFrameBehindAFalseStartIsFoundAtTheEndOfTheDatagram) {
  // A v2 start byte whose "length" runs past the datagram's end: at the datagram's end the frame behind it is found.
  std::vector<uint8_t> s = {0xFD, 200, 0, 0, 0, 0, 0, 0, 0, 0};
  append(s, heartbeat_frame(4));
  Parser p;
  EXPECT_TRUE(feed(p, s).empty());
  std::vector<int> seqs;
  p.end_of_datagram([&](const Frame& f) { seqs.push_back(f.seq); });
  EXPECT_EQ(seqs, (std::vector<int>{4}));
  EXPECT_EQ(p.stats().truncated, 1);
}

TEST(MavlinkParser, ByteByByteFeedingFindsTheSameFrames) {
  std::vector<uint8_t> s;
  for (int i = 0; i < 20; ++i) {
    append(s, heartbeat_frame(static_cast<uint8_t>(i)));
    append(s, timesync_frame(i));
    s.push_back(static_cast<uint8_t>(i * 37));
  }
  Parser p;
  std::vector<int> seqs;
  for (uint8_t b : s) p.feed(&b, 1, [&](const Frame& f) { seqs.push_back(f.msgid == Heartbeat::kId ? f.seq : -1); });
  EXPECT_EQ(p.stats().frames, 40);
  EXPECT_EQ(p.stats().bytes, static_cast<int64_t>(s.size()));
}

TEST(MavlinkParser, SignedFramesAreRefusedAndSkippedWhole) {
  const auto f = heartbeat_with_flags(kIncompatFlagSigned);
  std::vector<uint8_t> s = f;
  s.insert(s.end(), kSignatureSize, 0xFD);  // a signature full of start bytes is not rescanned
  append(s, heartbeat_frame(2));
  Parser p;
  EXPECT_EQ(feed(p, s), (std::vector<int>{2}));
  EXPECT_EQ(p.stats().signed_refused, 1);
  EXPECT_EQ(p.stats().garbage_bytes, 0);
}

TEST(MavlinkParser, UnknownIncompatibilityFlagsAreRefused) {
  const auto f = heartbeat_with_flags(0x02);
  Parser p;
  EXPECT_TRUE(feed(p, f).empty());
  EXPECT_EQ(p.stats().incompatible_flags, 1);
}

TEST(MavlinkParser, UnknownMessagesAreSkippedWhole) {
  // A v2 frame of message 253 (STATUSTEXT), which the codec does not handle, then a heartbeat.
  std::vector<uint8_t> s = {0xFD, 4, 0, 0, 9, 1, 1, 253, 0, 0, 'a', 'b', 'c', 'd', 0x12, 0x34};
  append(s, heartbeat_frame(2));
  Parser p;
  EXPECT_EQ(feed(p, s), (std::vector<int>{2}));
  EXPECT_EQ(p.stats().unknown_messages, 1);
}

TEST(MavlinkParser, AShortV1FrameIsRefusedAndAnEmptyV2PayloadReadsAsZeros) {
  // v1 HEARTBEAT with 3 payload bytes (needs 9).
  const auto v1 = with_crc({0xFE, 3, 0, 1, 1, 0, 1, 2, 3}, 50);
  // v2 COMMAND_ACK with no payload bytes (node-mavlink sends an all-zero payload so).
  const auto v2 = with_crc({0xFD, 0, 0, 0, 5, 1, 1, 77, 0, 0}, 143);
  std::vector<uint8_t> s = v1;
  append(s, v2);
  Parser p;
  int acks = 0;
  p.feed(s.data(), s.size(), [&](const Frame& f) {
    CommandAck ack;
    ASSERT_TRUE(decode(f, ack));
    EXPECT_EQ(ack.command, 0);
    ++acks;
  });
  EXPECT_EQ(acks, 1);
  EXPECT_EQ(p.stats().bad_length, 1);
}

TEST(MavlinkParser, ALongerV2PayloadFromANewerSenderIsRead) {
  // TIMESYNC with two more bytes than this codec knows (a future extension): the known fields are read.
  Timesync t;
  t.ts1 = 42;
  t.target_component = 7;
  auto f = encode(t, Sender{});
  std::vector<uint8_t> longer(f.begin(), f.end() - 2);
  longer[1] = static_cast<uint8_t>(longer[1] + 2);
  longer.push_back(0xAA);
  longer.push_back(0xBB);
  longer = with_crc(longer, 34);
  Parser p;
  int n = 0;
  p.feed(longer.data(), longer.size(), [&](const Frame& fr) {
    Timesync back;
    ASSERT_TRUE(decode(fr, back));
    EXPECT_EQ(back.ts1, 42);
    EXPECT_EQ(back.target_component, 7);
    ++n;
  });
  EXPECT_EQ(n, 1);
}

TEST(MavlinkParser, AFloodOfFramesAndNoiseIsHandledInBoundedMemory) {
  // 100000 frames mixed with random noise, fed in odd-sized chunks: every frame not hit by noise is found, and
  // the counters account for every byte.
  std::mt19937 rng(3);
  std::vector<uint8_t> s;
  int clean = 0;
  for (int i = 0; i < 100000; ++i) {
    append(s, heartbeat_frame(static_cast<uint8_t>(i)));
    ++clean;
    if (i % 10 == 0) {
      // noise without start bytes, so it cannot swallow the next frame as an unknown message
      for (int k = 0; k < 7; ++k) s.push_back(static_cast<uint8_t>(rng() % 0xF0));
    }
  }
  Parser p;
  int64_t found = 0;
  for (size_t at = 0; at < s.size();) {
    const size_t n = std::min<size_t>(s.size() - at, 1 + rng() % 1500);
    p.feed(s.data() + at, n, [&](const Frame&) { ++found; });
    at += n;
  }
  EXPECT_EQ(found, clean);
  EXPECT_EQ(p.stats().garbage_bytes, 10000 * 7);
  EXPECT_EQ(p.stats().bytes, static_cast<int64_t>(s.size()));
}
