// SPDX-License-Identifier: MIT
// check_encoded / decode_message: the wire-format walk matches LCM's encoder for every type, and messages that
// would make LCM's decoder allocate more than they carry (or exceed the limits) are rejected before decoding.
#include <gtest/gtest.h>
#include <wingman/common/message_limits.hpp>
#include <wingman/detections_t.hpp>
#include <wingman/track_windows_t.hpp>

#include <cstdint>
#include <limits>
#include <vector>

namespace {

using namespace wingman;
using common::check_encoded;
using common::MessageLimits;

template <class Msg>
std::vector<uint8_t> encode(const Msg& m) {
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(b.data(), 0, static_cast<int>(b.size())), static_cast<int>(b.size()));
  return b;
}

image_t gray(int w, int h) {
  image_t m{};
  m.utime = 1;
  m.width = w;
  m.height = h;
  m.stride = w;
  m.pixel_format = image_t::GRAY8;
  m.data.assign(static_cast<size_t>(w) * h, 3);
  m.size = static_cast<int32_t>(m.data.size());
  return m;
}

status_t status_with_channels(int n) {
  status_t s{};
  s.process = "p";
  s.detail = "";
  s.last_error = "boom";
  for (int i = 0; i < n; ++i) {
    channel_stats_t c{};
    c.channel = "CH" + std::to_string(i);
    s.channels.push_back(c);
  }
  s.num_channels = n;
  return s;
}

/// Overwrites the big-endian int32 at `offset`.
void put_i32(std::vector<uint8_t>& b, size_t offset, uint32_t v) {
  for (int i = 0; i < 4; ++i) b[offset + i] = static_cast<uint8_t>(v >> (24 - 8 * i));
}

// The walk must accept what LCM encodes, for every type with every kind of field, and reject it one byte short.
template <class Msg>
void expect_walk_matches_encoder(const Msg& m) {
  const std::vector<uint8_t> b = encode(m);
  EXPECT_EQ(check_encoded<Msg>(b.data(), b.size(), {}), "") << Msg::getTypeName();
  EXPECT_NE(check_encoded<Msg>(b.data(), b.size() - 1, {}), "") << Msg::getTypeName();
}

TEST(CheckEncoded, MatchesTheGeneratedEncoderOfEveryType) {
  expect_walk_matches_encoder(gray(8, 4));
  detections_t d{};
  d.detections.resize(3);
  d.num_detections = 3;
  expect_walk_matches_encoder(d);
  expect_walk_matches_encoder(own_pose_t{});
  targets_t t{};
  t.targets.resize(2);
  t.num_targets = 2;
  expect_walk_matches_encoder(t);
  expect_walk_matches_encoder(setpoint_t{});
  expect_walk_matches_encoder(status_with_channels(3));
  ground_truth_t g{};
  g.vehicles.resize(2);
  g.vehicles[0].name = "leader";
  g.vehicles[1].name = "follower";
  g.num_vehicles = 2;
  g.boxes.resize(1);
  g.num_boxes = 1;
  expect_walk_matches_encoder(g);
  track_windows_t w{};
  w.windows.resize(2);
  w.num_windows = 2;
  expect_walk_matches_encoder(w);
}

TEST(CheckEncoded, RejectsAnImageClaimingMoreBytesThanItCarriesBeforeDecoding) {
  // The case: 40 bytes of image_t whose size says 2^31 - 1 (LCM would resize data to 2 GB first).
  image_t m = gray(4, 4);
  m.data.clear();
  m.size = 0;
  std::vector<uint8_t> b = encode(m);
  ASSERT_EQ(b.size(), 8u + 8 + 8 + 4 * 4 + 1 + 4);
  put_i32(b, b.size() - 4, 0x7fffffff);
  MessageLimits big;
  big.max_image_bytes = int64_t{1} << 40;  // past the limit check: the length check alone must catch it
  const std::string why = check_encoded<image_t>(b.data(), b.size(), big);
  EXPECT_NE(why.find("image_t.size = 2147483647"), std::string::npos) << why;
  EXPECT_NE(why.find("0 left"), std::string::npos) << why;
  image_t out;
  EXPECT_EQ(common::decode_message<image_t>(b.data(), b.size(), big, out, nullptr), why);
  EXPECT_TRUE(out.data.empty());
}

TEST(CheckEncoded, RejectsNegativeLengthsAndBadStrings) {
  detections_t d{};
  std::vector<uint8_t> b = encode(d);
  put_i32(b, b.size() - 4, 0xffffffff);  // num_detections = -1
  EXPECT_NE(check_encoded<detections_t>(b.data(), b.size(), {}).find("detections_t.num_detections = -1"),
            std::string::npos);

  status_t s = status_with_channels(0);
  std::vector<uint8_t> sb = encode(s);
  put_i32(sb, 8 + 8, 0);  // process: length 0 (no room for the NUL; LCM would assign 2^64 - 1 chars)
  EXPECT_NE(check_encoded<status_t>(sb.data(), sb.size(), {}).find("status_t.process: string length 0"),
            std::string::npos);
  put_i32(sb, 8 + 8, 1000);
  EXPECT_NE(check_encoded<status_t>(sb.data(), sb.size(), {}).find("status_t.process: string length 1000"),
            std::string::npos);
}

TEST(CheckEncoded, RejectsNestedArraysLongerThanTheBytesLeft) {
  status_t s = status_with_channels(1);
  std::vector<uint8_t> b = encode(s);
  // num_channels sits just before the one channel_stats_t (4 + 3 + 1 + 8 + 8 + 4 + 8 bytes).
  const size_t at = b.size() - (4 + 4 + 1 + 8 + 8 + 4 + 8) - 4;
  put_i32(b, at, 1000000);
  const std::string why = check_encoded<status_t>(b.data(), b.size(), {});
  EXPECT_NE(why.find("status_t.num_channels = 1000000"), std::string::npos) << why;
}

// Issue 33, finding 6: 2^31 - 1 x 2^31 - 1 x 4 overflowed into a negative byte limit, and every frame was dropped.
TEST(MessageLimits, ImageByteLimitSaturatesInsteadOfOverflowing) {
  MessageLimits l;
  l.image.max_width = 2147483647;
  l.image.max_height = 2147483647;
  EXPECT_EQ(l.image_bytes_limit(), std::numeric_limits<int64_t>::max());
  l.image.max_height = 8192;
  EXPECT_EQ(l.image_bytes_limit(), int64_t{2147483647} * 8192 * 4);
}

// Issue 33, finding 5: one detections_t of 10^6 boxes cost the localizer 1.5 GB and 15 s; arrays of structs are
// bounded by count before anything is decoded.
TEST(CheckEncoded, RejectsMoreBoxesThanMaxArrayElementsBeforeDecoding) {
  const MessageLimits limits;
  wingman::detections_t d{};
  d.image_width = 640;
  d.image_height = 480;
  d.detections.resize(static_cast<size_t>(limits.max_array_elements));
  d.num_detections = static_cast<int32_t>(d.detections.size());
  const std::vector<uint8_t> ok = encode(d);
  EXPECT_EQ(check_encoded<wingman::detections_t>(ok.data(), ok.size(), limits), "");
  d.detections.resize(1000000);
  d.num_detections = 1000000;
  const std::vector<uint8_t> huge = encode(d);
  EXPECT_EQ(check_encoded<wingman::detections_t>(huge.data(), huge.size(), limits),
            "detections_t.num_detections = 1000000: more than the 4096 elements accepted (max_array_elements)");
  MessageLimits bad;
  bad.max_array_elements = 0;
  EXPECT_NE(bad.validate().find("max_array_elements = 0"), std::string::npos);
}

TEST(CheckEncoded, RejectsImagesAndMessagesOverTheLimits) {
  MessageLimits limits;
  limits.image = {16, 16};
  const std::vector<uint8_t> b = encode(gray(32, 4));
  EXPECT_NE(check_encoded<image_t>(b.data(), b.size(), limits).find("image_t.width x height = 32 x 4"),
            std::string::npos);
  limits.image = {64, 64};
  limits.max_image_bytes = 100;
  EXPECT_NE(check_encoded<image_t>(b.data(), b.size(), limits).find("image_t.size = 128"), std::string::npos);
  limits = MessageLimits{};
  limits.max_message_bytes = 100;
  EXPECT_NE(check_encoded<image_t>(b.data(), b.size(), limits).find("max_message_bytes"), std::string::npos);
}

TEST(CheckEncoded, RejectsTheWrongTypeAndShortInput) {
  const std::vector<uint8_t> b = encode(own_pose_t{});
  EXPECT_NE(check_encoded<image_t>(b.data(), b.size(), {}).find("fingerprint is not image_t's"), std::string::npos);
  EXPECT_NE(check_encoded<image_t>(b.data(), 3, {}).find("too short"), std::string::npos);
}

TEST(DecodeMessage, DecodesAndValidates) {
  const std::vector<uint8_t> b = encode(gray(8, 4));
  image_t m;
  EXPECT_EQ(common::decode_message<image_t>(b.data(), b.size(), {}, m, nullptr), "");
  EXPECT_EQ(m.width, 8);
  const std::string why = common::decode_message<image_t>(
      b.data(), b.size(), {}, m, [](const image_t&) { return std::string("image_t.width: rejected"); });
  EXPECT_EQ(why, "image_t.width: rejected");
}

TEST(MessageLimits, ValidateNamesTheLimit) {
  MessageLimits l;
  EXPECT_EQ(l.validate(), "");
  l.max_message_bytes = 1;
  EXPECT_NE(l.validate().find("max_message_bytes"), std::string::npos);
  EXPECT_TRUE(common::knows_encoding("image_t"));
  EXPECT_FALSE(common::knows_encoding("foo_t"));
}

}  // namespace
