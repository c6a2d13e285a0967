// SPDX-License-Identifier: MIT
// Tests of `wingman spy`: its java command line, and that lcm-spy's classpath decodes every pipeline channel.
#include "wingman/tools/spy.hpp"

#include "test_support.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using ::testing::Contains;
using ::testing::HasSubstr;
using ::testing::Not;
using wingman::testing::TempDir;
using wingman::tools::spy_command;
using wingman::tools::SpyOptions;

/// The eight channels wingman-publish-samples writes: one per message type, and the camera's preview.
const std::vector<std::string> kPipelineChannels = {"IMAGE_CAM0", "PREVIEW_CAM0", "DETECTIONS_CAM0", "OWN_POSE",
                                                    "TARGETS",    "SETPOINT",     "STATUS_SAMPLE",   "GROUND_TRUTH"};

/// Exit code and combined stdout+stderr of a shell command.
struct CommandResult {
  int exit_code = -1;
  std::string output;
};

/// Runs one simple `command` (no pipes or lists) with /bin/sh, bounded by `timeout_s` seconds (coreutils timeout; 124
/// when it ran out).
CommandResult run_command(const std::string& command, int timeout_s = 60) {
  const std::string bounded = "timeout -k 5 " + std::to_string(timeout_s) + " " + command + " 2>&1";
  CommandResult result;
  FILE* pipe = ::popen(bounded.c_str(), "r");
  if (pipe == nullptr) throw std::runtime_error("popen failed: " + command);
  std::array<char, 4096> buf{};
  size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) result.output.append(buf.data(), n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

std::string bin_dir() {
  const char* env = std::getenv("WINGMAN_BIN_DIR");
  return env != nullptr && *env != '\0' ? env : WINGMAN_DEFAULT_BIN_DIR;
}

std::vector<std::string> split_words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

/// The java runtime and classpath of `wingman spy`, from `wingman spy --dry-run`.
struct SpyJava {
  std::string java;
  std::string classpath;
};

SpyJava spy_java_from_dry_run() {
  const CommandResult dry =
      run_command(bin_dir() + "/wingman spy --dry-run --lcm-url='udpm://239.255.76.67:7667?ttl=0'", 30);
  if (dry.exit_code != 0) throw std::runtime_error("wingman spy --dry-run failed: " + dry.output);
  const std::vector<std::string> words = split_words(dry.output);
  SpyJava spy;
  for (size_t i = 0; i + 1 < words.size(); ++i) {
    if (words[i] == "-cp") spy.classpath = words[i + 1];
  }
  if (words.empty() || spy.classpath.empty()) throw std::runtime_error("no -cp in: " + dry.output);
  spy.java = words[0];
  return spy;
}

/// Runs DecodeCheck on `log` with `classpath` (plus DecodeCheck's own directory).
CommandResult run_decode_check(const SpyJava& spy, const std::string& log, const std::vector<std::string>& channels) {
  std::string cmd = spy.java + " -cp " + spy.classpath + ":" + WINGMAN_DECODE_CHECK_DIR + " DecodeCheck " + log;
  for (const auto& c : channels) cmd += " " + c;
  return run_command(cmd, 60);
}

/// The DecodeCheck line of `channel` ("" when none).
std::string line_of(const std::string& output, const std::string& channel) {
  std::istringstream in(output);
  for (std::string line; std::getline(in, line);) {
    const auto words = split_words(line);
    if (!words.empty() && words[0] == channel) return line;
  }
  return "";
}

TEST(SpyCommand, StartsLcmSpyWithLcmJchart2dAndTypesJarsAndTheUrl) {
  SpyOptions options;
  options.lcm_url = "udpm://239.255.76.67:7667?ttl=0";
  const std::vector<std::string> cmd = spy_command(options);

  ASSERT_FALSE(cmd.empty());
  EXPECT_EQ(cmd.front(), "java");
  EXPECT_THAT(cmd, Contains("lcm.spy.Spy"));
  EXPECT_THAT(cmd, Contains("-Djava.net.preferIPv4Stack=true"));
  EXPECT_THAT(cmd, Contains("--lcm-url=udpm://239.255.76.67:7667?ttl=0"));
  EXPECT_THAT(cmd, Not(Contains("-Xincgc")));  // Java 17 refuses to start with it
  std::string classpath;
  for (size_t i = 0; i + 1 < cmd.size(); ++i) {
    if (cmd[i] == "-cp") classpath = cmd[i + 1];
  }
  EXPECT_THAT(classpath, HasSubstr(WINGMAN_LCM_JAR));
  EXPECT_THAT(classpath, HasSubstr("/usr/share/java/jchart2d.jar"));
  EXPECT_THAT(classpath, HasSubstr(WINGMAN_LCMTYPES_JAR));
}

TEST(SpyCommand, UrlComesAfterTheMainClass) {
  SpyOptions options;
  options.lcm_url = "udpm://239.255.76.67:7667?ttl=0";
  const std::vector<std::string> cmd = spy_command(options);
  EXPECT_EQ(cmd.back(), "--lcm-url=udpm://239.255.76.67:7667?ttl=0");
  EXPECT_EQ(cmd[cmd.size() - 2], "lcm.spy.Spy");
}

TEST(SpyCommand, EmptyUrlTakesLcmDefaultUrlFromTheEnvironment) {
  const char* old = std::getenv("LCM_DEFAULT_URL");
  const std::string saved = old != nullptr ? old : "";
  ::setenv("LCM_DEFAULT_URL", "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304", 1);
  const std::vector<std::string> with_env = spy_command(SpyOptions{});
  ::unsetenv("LCM_DEFAULT_URL");
  const std::vector<std::string> without_env = spy_command(SpyOptions{});
  if (old != nullptr) ::setenv("LCM_DEFAULT_URL", saved.c_str(), 1);

  EXPECT_EQ(with_env.back(), "--lcm-url=udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304");
  EXPECT_EQ(without_env.back(), "lcm.spy.Spy");  // lcm-spy then uses LCM's default
}

TEST(SpyCommand, MissingTypesJarThrowsNamingIt) {
  SpyOptions options;
  options.types_jar = "/nonexistent/wingman_lcmtypes.jar";
  try {
    spy_command(options);
    FAIL() << "spy_command accepted a missing types jar";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/wingman_lcmtypes.jar"));
    EXPECT_THAT(e.what(), HasSubstr("types jar"));
  }
}

TEST(SpyCommand, MissingTypesJarFailsTheDryRunNamingIt) {
  const CommandResult r = run_command(bin_dir() + "/wingman spy --dry-run --types-jar /nonexistent/types.jar", 30);
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("/nonexistent/types.jar"));
}

TEST(SpyDecode, EveryPipelineChannelDecodesWithTheClasspathOfWingmanSpy) {
  const TempDir tmp;  // removed with its files at the end of the test
  const std::string& dir = tmp.path();
  const std::string log = dir + "/samples.lcmlog";
  const CommandResult pub = run_command(std::string(WINGMAN_PUBLISH_SAMPLES_EXE) + " --log " + log + " --repeat 3", 30);
  ASSERT_EQ(pub.exit_code, 0) << pub.output;

  const SpyJava spy = spy_java_from_dry_run();
  const CommandResult check = run_decode_check(spy, log, kPipelineChannels);
  EXPECT_EQ(check.exit_code, 0) << "classpath " << spy.classpath << "\n" << check.output;
  const std::vector<std::pair<std::string, std::string>> expected_types = {{"IMAGE_CAM0", "wingman.image_t"},
                                                                           {"PREVIEW_CAM0", "wingman.image_t"},
                                                                           {"DETECTIONS_CAM0", "wingman.detections_t"},
                                                                           {"OWN_POSE", "wingman.own_pose_t"},
                                                                           {"TARGETS", "wingman.targets_t"},
                                                                           {"SETPOINT", "wingman.setpoint_t"},
                                                                           {"STATUS_SAMPLE", "wingman.status_t"},
                                                                           {"GROUND_TRUTH", "wingman.ground_truth_t"}};
  for (const auto& [channel, type] : expected_types) {
    const std::vector<std::string> words = split_words(line_of(check.output, channel));
    ASSERT_EQ(words.size(), 4u) << channel << " in:\n" << check.output;
    EXPECT_EQ(words[1], type) << channel;
    EXPECT_EQ(words[2], "3") << channel;
    EXPECT_EQ(words[3], "OK") << channel;
  }
}

TEST(SpyDecode, DecodeCheckFailsOnAChannelNoClassOnTheClasspathDecodes) {
  const TempDir tmp;  // removed with its files at the end of the test
  const std::string& dir = tmp.path();
  const std::string log = dir + "/garbage.lcmlog";
  {
    lcm::LogFile file(log, "w");
    ASSERT_TRUE(file.good());
    std::vector<uint8_t> garbage = {0xde, 0xad, 0xbe, 0xef, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06};
    lcm::LogEvent ev;
    ev.eventnum = 0;
    ev.timestamp = 1;
    ev.channel = "GARBAGE";
    ev.datalen = static_cast<int32_t>(garbage.size());
    ev.data = garbage.data();
    ASSERT_EQ(file.writeEvent(&ev), 0);
  }
  const CommandResult check = run_decode_check(spy_java_from_dry_run(), log, {"GARBAGE", "IMAGE_CAM0"});
  EXPECT_EQ(check.exit_code, 1) << check.output;
  EXPECT_THAT(line_of(check.output, "GARBAGE"), HasSubstr("UNDECODABLE"));
  EXPECT_THAT(line_of(check.output, "IMAGE_CAM0"), HasSubstr("MISSING"));
}

TEST(SpyDecode, WithoutTheTypesJarNoPipelineChannelDecodes) {
  const TempDir tmp;  // removed with its files at the end of the test
  const std::string& dir = tmp.path();
  const std::string log = dir + "/samples.lcmlog";
  const CommandResult pub = run_command(std::string(WINGMAN_PUBLISH_SAMPLES_EXE) + " --log " + log, 30);
  ASSERT_EQ(pub.exit_code, 0) << pub.output;
  // Debian's lcm-spy classpath: what the types jar adds is what makes our channels decode.
  const SpyJava bare{spy_java_from_dry_run().java, std::string(WINGMAN_LCM_JAR) + ":/usr/share/java/jchart2d.jar"};
  const CommandResult check = run_decode_check(bare, log, kPipelineChannels);
  EXPECT_EQ(check.exit_code, 1) << check.output;
  for (const auto& channel : kPipelineChannels) {
    EXPECT_THAT(line_of(check.output, channel), HasSubstr("UNDECODABLE")) << channel;
  }
}

}  // namespace
