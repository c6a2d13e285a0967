// SPDX-License-Identifier: MIT
// Recorder library: LCM logs that LCM reads back, size rotation, channel filters, drops counted, and real write
// errors (missing directory, a path under a regular file, a file-size limit) with recovery.
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <lcm/lcm-cpp.hpp>

#include <wingman/common/config.hpp>
#include <wingman/recorder/recorder.hpp>

#include <dirent.h>
#include <algorithm>
#include <csignal>
#include <fstream>
#include <thread>

namespace {

using wingman::recorder::ChannelFilter;
using wingman::recorder::Recorder;
using wingman::recorder::RecorderOptions;
using wingman::recorder::RecorderStats;
using wingman::testing::LogEvent;
using wingman::testing::read_log;
using wingman::testing::TempDir;

std::vector<std::string> segments(const std::string& dir) {
  std::vector<std::string> files;
  if (DIR* d = opendir(dir.c_str())) {
    while (dirent* e = readdir(d)) {
      const std::string name = e->d_name;
      if (name.size() > 7 && name.substr(name.size() - 7) == ".lcmlog") files.push_back(dir + "/" + name);
    }
    closedir(d);
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<LogEvent> read_all(const std::string& dir) {
  std::vector<LogEvent> all;
  for (const auto& f : segments(dir)) {
    const auto events = read_log(f);
    all.insert(all.end(), events.begin(), events.end());
  }
  return all;
}

std::vector<uint8_t> payload(int i, size_t size) {
  std::vector<uint8_t> p(size);
  for (size_t k = 0; k < size; ++k) p[k] = static_cast<uint8_t>(i * 31 + k);
  return p;
}

RecorderOptions options_in(const std::string& dir) {
  RecorderOptions o;
  o.directory = dir;
  o.retry_period_s = 0.2;
  return o;
}

/// Waits (bounded) until `pred(stats)` holds.
template <class Pred>
bool wait_for(Recorder& rec, Pred pred, double timeout_s = 10.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < end) {
    if (pred(rec.stats())) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return pred(rec.stats());
}

TEST(RecorderTest, SegmentsRotateBySizeAndLcmReadsEveryEventBackInOrder) {
  TempDir dir;
  RecorderOptions o = options_in(dir.path());
  o.max_segment_mib = 0.05;  // 51 KiB: 300 events of 1 KiB need several segments
  Recorder rec(o);
  for (int i = 0; i < 300; ++i) {
    const auto p = payload(i, 1000);
    ASSERT_TRUE(rec.record(i % 2 ? "POSE" : "DETECTIONS_CAM0", 1700000000000000 + i, p.data(), p.size()));
  }
  ASSERT_TRUE(rec.wait_idle(10.0));
  rec.close();
  const RecorderStats s = rec.stats();
  EXPECT_EQ(s.events_written, 300);
  EXPECT_EQ(s.dropped_queue_full + s.dropped_write_error, 0);
  const auto files = segments(dir.path());
  EXPECT_GE(files.size(), 5u);
  EXPECT_EQ(s.segments_opened, static_cast<int64_t>(files.size()));
  for (const auto& f : files) {
    struct stat st {};
    ASSERT_EQ(stat(f.c_str(), &st), 0);
    EXPECT_LE(st.st_size, static_cast<off_t>(0.05 * 1024 * 1024)) << f;
  }
  const auto events = read_all(dir.path());
  ASSERT_EQ(events.size(), 300u);
  for (int i = 0; i < 300; ++i) {
    EXPECT_EQ(events[i].channel, i % 2 ? "POSE" : "DETECTIONS_CAM0");
    EXPECT_EQ(events[i].timestamp, 1700000000000000 + i);
    EXPECT_EQ(events[i].data, payload(i, 1000));
  }
}

TEST(RecorderTest, LcmFileProviderReplaysASegment) {
  TempDir dir;
  {
    Recorder rec(options_in(dir.path()));
    for (int i = 0; i < 5; ++i) {
      const auto p = payload(i, 64);
      rec.record("CH_" + std::to_string(i), 1000 + i, p.data(), p.size());
    }
  }
  const auto files = segments(dir.path());
  ASSERT_EQ(files.size(), 1u);
  lcm::LCM in("file://" + files[0] + "?speed=0");
  ASSERT_TRUE(in.good());
  struct Sink {
    std::vector<std::string> channels;
    void on(const lcm::ReceiveBuffer* rbuf, const std::string& ch) {
      channels.push_back(ch);
      EXPECT_EQ(std::vector<uint8_t>(static_cast<uint8_t*>(rbuf->data), static_cast<uint8_t*>(rbuf->data) + 64),
                payload(static_cast<int>(channels.size() - 1), 64));
    }
  } sink;
  in.subscribe(".*", &Sink::on, &sink);
  for (int i = 0; i < 10 && in.handle() == 0; ++i) {
  }
  EXPECT_EQ(sink.channels, (std::vector<std::string>{"CH_0", "CH_1", "CH_2", "CH_3", "CH_4"}));
}

TEST(RecorderTest, FilterIncludesAndExcludesWholeChannelNames) {
  ChannelFilter defaults(RecorderOptions().include, RecorderOptions().exclude);
  EXPECT_TRUE(defaults.wants("DETECTIONS_CAM0"));
  EXPECT_TRUE(defaults.wants("STATUS_DETECTOR"));
  EXPECT_FALSE(defaults.wants("IMAGE"));
  EXPECT_FALSE(defaults.wants("IMAGE_CAM1"));
  EXPECT_TRUE(defaults.wants("SIM_IMAGE"));  // whole-name match: IMAGE.* does not match inside a name
  ChannelFilter only_status({"STATUS_.*", "TARGETS"}, {"STATUS_SIM"});
  EXPECT_TRUE(only_status.wants("STATUS_LOCALIZER"));
  EXPECT_TRUE(only_status.wants("TARGETS"));
  EXPECT_FALSE(only_status.wants("TARGETS_2"));
  EXPECT_FALSE(only_status.wants("STATUS_SIM"));
}

TEST(RecorderTest, OptionsRejectBadExpressionsAndSizesNamingTheKey) {
  RecorderOptions o;
  o.exclude = {"IMAGE[("};
  o.max_segment_mib = 0;
  const auto problems = o.validate();
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_NE(problems[0].find("output.max_segment_mib"), std::string::npos) << problems[0];
  EXPECT_NE(problems[1].find("channels.exclude"), std::string::npos) << problems[1];
  EXPECT_TRUE(RecorderOptions().validate().empty());
}

// Issue 33, finding 6: a pattern 20 k parentheses deep crashed the recorder at load (std::regex's recursive
// compiler), and a backtracking one hung it on a 60-character channel name.
TEST(ChannelPatternTest, HostilePatternsAreOneErrorAtLoadAndMatchingNeverBacktracks) {
  using wingman::recorder::ChannelPattern;
  std::string why;
  const std::string deep = std::string(20000, '(') + "a" + std::string(20000, ')');
  EXPECT_FALSE(ChannelPattern::compile(deep, &why));
  EXPECT_NE(why.find("characters: at most 256"), std::string::npos) << why;
  const std::string deep17 = std::string(17, '(') + "a" + std::string(17, ')');
  EXPECT_FALSE(ChannelPattern::compile(deep17, &why));
  EXPECT_EQ(why, "parentheses nested deeper than 16 at character 17");
  EXPECT_TRUE(ChannelPattern::compile(std::string(16, '(') + "a" + std::string(16, ')')));
  EXPECT_FALSE(ChannelPattern::compile("(A)\\1", &why));
  EXPECT_EQ(why, "a back-reference (\\1) at character 4: not supported");
  EXPECT_FALSE(ChannelPattern::compile("(A{1000}){1000}", &why));
  EXPECT_EQ(why, "counted repetition ('{') at character 3: not supported");
  EXPECT_FALSE(ChannelPattern::compile("IMAGE[(", &why));
  EXPECT_FALSE(why.empty());
  // An unbalanced ')' would escape the whole-name anchoring ("^(a)|(b)$").
  EXPECT_FALSE(ChannelPattern::compile("a)|(b", &why));
  EXPECT_EQ(why, "an unbalanced ')' at character 2");
  // Parentheses inside a bracket expression are literals, not nesting.
  const auto bracket = ChannelPattern::compile("[(((((((((((((((((((]X");
  ASSERT_TRUE(bracket);
  EXPECT_TRUE(bracket->matches("(X"));
  // Catastrophic for a backtracking matcher (2^60 paths): glibc's matcher answers at once.
  const std::string name(60, 'a');
  for (const std::string p : {"(a+)+b", "(a|a)*b", "(a*)*b", "(a|aa)+b"}) {
    const auto pattern = ChannelPattern::compile(p, &why);
    ASSERT_TRUE(pattern) << p << ": " << why;
    EXPECT_FALSE(pattern->matches(name)) << p;
    EXPECT_TRUE(pattern->matches(name + "b")) << p;
  }
  // Whole-name matching, alternation, classes.
  const auto status = ChannelPattern::compile("STATUS_[[:upper:]]+|TARGETS");
  ASSERT_TRUE(status);
  EXPECT_TRUE(status->matches("STATUS_LOCALIZER"));
  EXPECT_TRUE(status->matches("TARGETS"));
  EXPECT_FALSE(status->matches("TARGETS_2"));
  EXPECT_FALSE(status->matches("MY_STATUS_X"));
  EXPECT_FALSE(status->matches(std::string("TARGETS\0X", 9)));
  // Through the options: the key is named.
  RecorderOptions o;
  o.include = {deep17};
  const auto problems = o.validate();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("channels.include"), std::string::npos) << problems[0];
  EXPECT_NE(problems[0].find("parentheses nested deeper than 16"), std::string::npos) << problems[0];
}

TEST(RecorderTest, TheFilterCacheIsBoundedAndKeepsAnswering) {
  ChannelFilter f({"CH_.*"}, {"CH_1.*"});
  for (int i = 0; i < 3 * static_cast<int>(ChannelFilter::kMaxCached); ++i) {
    const std::string name = "CH_" + std::to_string(i);
    ASSERT_EQ(f.wants(name), name[3] != '1') << name;
  }
  EXPECT_TRUE(f.wants("CH_0"));
  EXPECT_FALSE(f.wants("CH_1"));
}

TEST(RecorderTest, EventsBeyondTheQueueBoundAreDroppedAndCountedPerChannel) {
  TempDir dir;
  RecorderOptions o = options_in(dir.path());
  o.max_queue_mib = 0.01;  // 10 KiB
  Recorder rec(o);
  const auto big = payload(0, 20000);
  EXPECT_FALSE(rec.record("BIG", 1, big.data(), big.size()));  // can never fit
  int accepted = 0;
  for (int i = 0; i < 2000; ++i) {
    const auto p = payload(i, 4000);
    accepted += rec.record("SMALL", 2 + i, p.data(), p.size()) ? 1 : 0;
  }
  ASSERT_TRUE(rec.wait_idle(10.0));
  const RecorderStats s = rec.stats();
  EXPECT_EQ(s.dropped_queue_full, 1 + (2000 - accepted));
  EXPECT_EQ(s.events_written, accepted);
  EXPECT_EQ(s.events_queued, accepted);
  const auto drops = rec.take_drops();
  EXPECT_EQ(drops.at("BIG"), 1);
  EXPECT_EQ(drops.count("SMALL") ? drops.at("SMALL") : 0, 2000 - accepted);
  EXPECT_TRUE(rec.take_drops().empty());
  rec.close();
  EXPECT_EQ(read_all(dir.path()).size(), static_cast<size_t>(accepted));
}

TEST(RecorderTest, MissingDirectoryAtStartIsOneClearErrorOrARetryThatRecoversWhenItAppears) {
  TempDir dir;
  RecorderOptions o = options_in(dir.file("later"));
  o.require_directory_at_start = true;
  try {
    Recorder rec(o);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(dir.file("later")), std::string::npos) << what;
    EXPECT_NE(what.find("No such file or directory"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  o.require_directory_at_start = false;
  Recorder rec(o);
  RecorderStats s = rec.stats();
  EXPECT_TRUE(s.failing);
  EXPECT_NE(s.last_error.find("No such file or directory"), std::string::npos) << s.last_error;
  const auto p = payload(1, 100);
  EXPECT_TRUE(rec.record("A", 1, p.data(), p.size()));
  ASSERT_TRUE(rec.wait_idle(5.0));
  EXPECT_EQ(rec.stats().dropped_write_error, 1);  // before the retry time: dropped and counted, never blocking
  ASSERT_EQ(mkdir(dir.file("later").c_str(), 0755), 0);
  ASSERT_TRUE(wait_for(rec, [&](const RecorderStats& st) {
    rec.record("A", 2, p.data(), p.size());
    return st.events_written > 0;
  }));
  s = rec.stats();
  EXPECT_FALSE(s.failing);
  EXPECT_EQ(s.segment.rfind(dir.file("later") + "/wingman-", 0), 0u) << s.segment;
}

TEST(RecorderTest, DirectoryUnderARegularFileNamesPathAndReason) {
  // Permissions do not stop root; a path under a regular file fails for everyone (ENOTDIR).
  TempDir dir;
  std::ofstream(dir.file("plain")) << "x";
  RecorderOptions o = options_in(dir.file("plain") + "/logs");
  o.require_directory_at_start = true;
  try {
    Recorder rec(o);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(dir.file("plain") + "/logs"), std::string::npos) << what;
    EXPECT_NE(what.find("Not a directory"), std::string::npos) << what;
  }
}

/// RLIMIT_FSIZE makes write() fail for real (EFBIG) once a file would grow past it, for root too.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &saved_);
    std::signal(SIGXFSZ, SIG_IGN);
    set(bytes);
  }
  ~FileSizeLimit() { setrlimit(RLIMIT_FSIZE, &saved_); }
  void set(rlim_t bytes) {
    rlimit r = saved_;
    r.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &r);
  }
  void lift() { setrlimit(RLIMIT_FSIZE, &saved_); }

 private:
  rlimit saved_{};
};

TEST(RecorderTest, AFailingWriteKeepsTheSegmentReadableDropsAndCountsAndRecoversInANewSegment) {
  TempDir dir;
  RecorderOptions o = options_in(dir.path());
  // The 20 sends below must all fall before the retry; at 0.2 s a clean-clone ASan run under load retried in
  // between (a second segment, 11 written). 3 s leaves room for any slowdown; the recovery below waits for it.
  o.retry_period_s = 3.0;
  Recorder rec(o);
  FileSizeLimit limit(10000);  // 1000-byte payloads: event 10 crosses the limit part-way
  int sent = 0;
  auto send = [&](int n) {
    for (int i = 0; i < n; ++i, ++sent) {
      const auto p = payload(sent, 1000);
      rec.record("POSE", sent, p.data(), p.size());
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  };
  send(20);
  ASSERT_TRUE(rec.wait_idle(5.0));
  RecorderStats s = rec.stats();
  EXPECT_TRUE(s.failing);
  EXPECT_EQ(s.write_errors, 1);  // one failure, not one per message: the others wait for the retry
  EXPECT_NE(s.last_error.find("File too large"), std::string::npos) << s.last_error;
  EXPECT_NE(s.last_error.find(dir.path() + "/wingman-"), std::string::npos) << s.last_error;
  EXPECT_EQ(s.events_written + s.dropped_write_error, 20);
  const int64_t written_before = s.events_written;
  EXPECT_GE(written_before, 8);
  EXPECT_LE(written_before, 10);
  // The first segment ends with its last complete event.
  auto files = segments(dir.path());
  ASSERT_EQ(files.size(), 1u);
  EXPECT_EQ(read_log(files[0]).size(), static_cast<size_t>(written_before));

  limit.lift();
  ASSERT_TRUE(wait_for(rec, [&](const RecorderStats& st) {
    send(1);
    return st.events_written > written_before && !st.failing;
  }));
  ASSERT_TRUE(rec.wait_idle(5.0));
  rec.close();
  s = rec.stats();
  EXPECT_EQ(s.events_written + s.dropped_write_error, sent);
  files = segments(dir.path());
  EXPECT_EQ(files.size(), 2u);  // failed retries leave no empty segments behind
  const auto events = read_all(dir.path());
  ASSERT_EQ(events.size(), static_cast<size_t>(s.events_written));
  for (size_t i = 1; i < events.size(); ++i) EXPECT_LT(events[i - 1].timestamp, events[i].timestamp);
  EXPECT_EQ(events.back().data, payload(sent - 1, 1000));
}

}  // namespace
