// SPDX-License-Identifier: MIT
// LcmLogReader (issue 33, finding 4): headers checked before allocating, corrupt events named by their offset or
// skipped and counted, the file:// URL parsed.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <wingman/common/lcm_log_reader.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace wingman::common {
namespace {

void put32(std::vector<uint8_t>& out, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<uint8_t>(v >> s));
}
void put64(std::vector<uint8_t>& out, uint64_t v) {
  put32(out, static_cast<uint32_t>(v >> 32));
  put32(out, static_cast<uint32_t>(v));
}

/// Appends one event; `channel_len` / `data_len` override the true lengths in the header (a corrupt event).
void event(std::vector<uint8_t>& log, const std::string& channel, const std::vector<uint8_t>& data, int64_t timestamp,
           int64_t channel_len = -1, int64_t data_len = -1) {
  put32(log, 0xEDA1DA01);
  put64(log, 0);
  put64(log, static_cast<uint64_t>(timestamp));
  put32(log, static_cast<uint32_t>(channel_len >= 0 ? channel_len : static_cast<int64_t>(channel.size())));
  put32(log, static_cast<uint32_t>(data_len >= 0 ? data_len : static_cast<int64_t>(data.size())));
  log.insert(log.end(), channel.begin(), channel.end());
  log.insert(log.end(), data.begin(), data.end());
}

std::vector<std::string> channels(LcmLogReader& r) {
  std::vector<std::string> out;
  while (const LcmLogEvent* e = r.read_next()) out.push_back(e->channel);
  return out;
}

std::string error_of(LcmLogReader& r) {
  try {
    while (r.read_next()) {
    }
  } catch (const LcmLogError& e) {
    return e.what();
  }
  return "";
}

TEST(LcmLogReader, ReadsWhatLcmWritesEventForEvent) {
  const std::string path = ::testing::TempDir() + "wingman_log_reader.lcmlog";
  {
    lcm::LogFile log(path, "w");
    ASSERT_TRUE(log.good());
    for (int i = 0; i < 3; ++i) {
      std::vector<uint8_t> data(static_cast<size_t>(i * 10), static_cast<uint8_t>(i));
      lcm::LogEvent ev;
      ev.eventnum = i;
      ev.timestamp = 1000 + i;
      ev.channel = "CH" + std::to_string(i);
      ev.datalen = static_cast<int32_t>(data.size());
      ev.data = data.data();
      ASSERT_EQ(log.writeEvent(&ev), 0);
    }
  }
  LcmLogReader r(path);
  for (int i = 0; i < 3; ++i) {
    const LcmLogEvent* e = r.read_next();
    ASSERT_NE(e, nullptr);
    EXPECT_EQ(e->channel, "CH" + std::to_string(i));
    EXPECT_EQ(e->timestamp, 1000 + i);
    EXPECT_EQ(e->datalen, i * 10);
    if (i > 0) {
      EXPECT_EQ(static_cast<const uint8_t*>(e->data)[0], i);
    }
  }
  EXPECT_EQ(r.read_next(), nullptr);
  EXPECT_EQ(r.read_next(), nullptr);
  std::remove(path.c_str());
}

// LCM 1.3.1's reader calls calloc(datalen + 1): 2^31 - 1 overflows it and every process reading the log crashed.
TEST(LcmLogReader, AHugeDataLengthIsACorruptEventNamedByItsOffsetNotAnAllocation) {
  std::vector<uint8_t> log;
  event(log, "GOOD", {1, 2, 3}, 10);
  const size_t bad_at = log.size();
  event(log, "BAD", {4, 5}, 11, -1, 0x7FFFFFFF);
  LcmLogReader r = LcmLogReader::from_memory(log.data(), log.size(), "in.lcmlog");
  ASSERT_NE(r.read_next(), nullptr);
  try {
    r.read_next();
    ADD_FAILURE() << "a corrupt event was read";
  } catch (const LcmLogError& e) {
    EXPECT_EQ(e.offset(), static_cast<int64_t>(bad_at));
    EXPECT_EQ(std::string(e.what()),
              "in.lcmlog: corrupt event at byte 35: data length 2147483647: must be "
              "0..1073741824");
  }
}

TEST(LcmLogReader, EveryKindOfCorruptHeaderIsNamed) {
  struct Case {
    int64_t channel_len, data_len;
    const char* says;
  };
  for (const Case& c :
       {Case{0, -1, "channel length 0: must be 1..1023"}, Case{5000, -1, "channel length 5000: must be 1..1023"},
        Case{-1, 0x80000000LL, "data length -2147483648: must be 0..1073741824"},
        Case{-1, 1000, "channel length 3 and data length 1000 need 1003 bytes, only"}}) {
    std::vector<uint8_t> log;
    event(log, "ONE", {9}, 1);
    event(log, "TWO", {9, 9}, 2, c.channel_len, c.data_len);
    event(log, "SIX", {9, 9, 9}, 3);
    LcmLogReader r = LcmLogReader::from_memory(log.data(), log.size(), "x.lcmlog");
    const std::string e = error_of(r);
    EXPECT_NE(e.find("x.lcmlog: corrupt event at byte 32: "), std::string::npos) << e;
    EXPECT_NE(e.find(c.says), std::string::npos) << e;
  }
  std::vector<uint8_t> log;
  event(log, "ONE", {9}, 1);
  log.insert(log.end(),
             {0xDE, 0xAD, 0xBE, 0xEF, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1});
  LcmLogReader no_sync = LcmLogReader::from_memory(log.data(), log.size(), "x.lcmlog");
  EXPECT_NE(error_of(no_sync).find("at byte 32: no sync word (0xDEADBEEF instead of 0xEDA1DA01)"), std::string::npos);
  std::vector<uint8_t> cut;
  event(cut, "ONE", {9}, 1);
  event(cut, "TWO", {1, 2, 3, 4}, 2);
  cut.resize(cut.size() - 10);  // the writer was killed in the middle of the last event
  LcmLogReader truncated = LcmLogReader::from_memory(cut.data(), cut.size(), "x.lcmlog");
  EXPECT_NE(error_of(truncated).find("at byte 32: header cut short by the end of the file (25 of 28 bytes)"),
            std::string::npos);
}

TEST(LcmLogReader, OnRequestCorruptStretchesAreSkippedToTheNextValidEventAndCounted) {
  std::vector<uint8_t> log;
  event(log, "A", {1}, 1);
  event(log, "B", {2}, 2, -1, 0x7FFFFFFF);                // its sync word is found again, but its header is not valid
  log.insert(log.end(), {0xED, 0xA1, 0xDA, 0x01, 7, 7});  // a stray sync word with no valid header after it
  event(log, "C", {3}, 3);
  event(log, "D", {4}, 4, 5000);
  event(log, "E", {5}, 5);
  LcmLogReadOptions skip;
  skip.skip_corrupt = true;
  LcmLogReader r = LcmLogReader::from_memory(log.data(), log.size(), "s.lcmlog", skip);
  EXPECT_EQ(channels(r), (std::vector<std::string>{"A", "C", "E"}));
  EXPECT_EQ(r.corrupt_events(), 2);
  EXPECT_EQ(r.skipped_bytes(), 30 + 6 + 30);
  EXPECT_NE(r.first_corruption().find("s.lcmlog: corrupt event at byte 30: data length 2147483647"), std::string::npos)
      << r.first_corruption();
  const std::vector<uint8_t> none;
  LcmLogReader empty = LcmLogReader::from_memory(none.data(), 0, "e.lcmlog");
  EXPECT_EQ(empty.read_next(), nullptr);
  const std::vector<uint8_t> junk(100, 0xED);
  LcmLogReader all_junk = LcmLogReader::from_memory(junk.data(), junk.size(), "j.lcmlog", skip);
  EXPECT_EQ(all_junk.read_next(), nullptr);
  EXPECT_EQ(all_junk.corrupt_events(), 1);
  EXPECT_EQ(all_junk.skipped_bytes(), 100);
}

TEST(LcmFileUrl, PathAndSpeedAreParsedAndAnythingElseIsNamed) {
  const LcmFileUrl a = parse_lcm_file_url("file:///tmp/in.lcmlog?speed=0");
  EXPECT_EQ(a.path, "/tmp/in.lcmlog");
  EXPECT_EQ(a.speed, 0.0);
  EXPECT_EQ(parse_lcm_file_url("file://rel.lcmlog").speed, 1.0);
  EXPECT_EQ(parse_lcm_file_url("file:///x?mode=r&speed=2.5").speed, 2.5);
  EXPECT_THROW(parse_lcm_file_url("file://?speed=0"), std::invalid_argument);
  EXPECT_THROW(parse_lcm_file_url("file:///x?speed=-1"), std::invalid_argument);
  EXPECT_THROW(parse_lcm_file_url("file:///x?speed=inf"), std::invalid_argument);
  EXPECT_THROW(parse_lcm_file_url("file:///x?mode=w"), std::invalid_argument);
  EXPECT_THROW(parse_lcm_file_url("udpm://239.255.76.67:7667"), std::invalid_argument);
  try {
    parse_lcm_file_url("file:///x?start_timestamp=5");
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown option 'start_timestamp'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace wingman::common
