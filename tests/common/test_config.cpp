// SPDX-License-Identifier: MIT
// ConfigLoader / ConfigPrinter: defaults, every bad key reported at once, round trip.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <wingman/common/config.hpp>
#include <wingman/common/time_sanity.hpp>

#include <chrono>
#include <cstdio>

namespace {

using wingman::common::ConfigError;
using wingman::common::load_options_from_string;
using wingman::common::print_options;

struct Demo {
  int width = 640;
  double fps = 30.0;
  std::string device = "/dev/video0";
  bool loop = false;
  std::vector<double> k = {1.0, 2.5};
  int64_t start = 0;

  template <class V>
  void visit(V& v) {
    v("camera.width", width, "pixels");
    v("camera.fps", fps, "frames per second");
    v("camera.device", device, "path");
    v("file.loop", loop, "restart at the end");
    v("file.k", k, "coefficients");
    v("file.start", start, "utime");
  }
  std::vector<std::string> validate() const {
    std::vector<std::string> p;
    if (width <= 0) p.push_back(wingman::common::problem("camera.width", width, "must be > 0"));
    return p;
  }
};

TEST(ConfigLoader, EmptyFileGivesDefaults) {
  const Demo d = load_options_from_string<Demo>("", "empty.yaml");
  EXPECT_EQ(d.width, 640);
  EXPECT_EQ(d.device, "/dev/video0");
}

TEST(ConfigLoader, ReadsNestedKeysOfEveryType) {
  const Demo d = load_options_from_string<Demo>(
      "camera: {width: 1280, fps: 15.5, device: /dev/video2}\nfile: {loop: true, k: [3, 4], start: 1700000000000000}\n",
      "x.yaml");
  EXPECT_EQ(d.width, 1280);
  EXPECT_DOUBLE_EQ(d.fps, 15.5);
  EXPECT_EQ(d.device, "/dev/video2");
  EXPECT_TRUE(d.loop);
  EXPECT_EQ(d.k, (std::vector<double>{3, 4}));
  EXPECT_EQ(d.start, 1700000000000000);
}

TEST(ConfigLoader, ReportsEveryBadKeyAtOnceWithFileAndLine) {
  try {
    load_options_from_string<Demo>("camera:\n  width: -3\n  fps: fast\n  colour: red\nfile:\n  loop: maybe\n",
                                   "cam.yaml");
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("4 problems"), std::string::npos) << m;
    EXPECT_NE(m.find("cam.yaml:3: camera.fps: expected a number, got 'fast'"), std::string::npos) << m;
    EXPECT_NE(m.find("cam.yaml:4: camera.colour: unknown key"), std::string::npos) << m;
    EXPECT_NE(m.find("cam.yaml:6: file.loop: expected true or false, got 'maybe'"), std::string::npos) << m;
    EXPECT_NE(m.find("camera.width = -3: must be > 0"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << "one line: " << m;
  }
}

TEST(ConfigLoader, NonScalarKeyIsANamedProblemNotACrash) {
  // Found by fuzz.config: YAML's complex keys ("? ...") made the loader throw yaml-cpp's bad conversion.
  try {
    load_options_from_string<Demo>("camera:\n  ? fps: 3\n  : 1\n  width: 0\n", "k.yaml");
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("k.yaml:2: camera: a key must be a plain name, got a mapping"), std::string::npos) << m;
    EXPECT_NE(m.find("camera.width = 0: must be > 0"), std::string::npos) << "other problems still reported: " << m;
  }
}

TEST(ConfigLoader, UnknownKeyInWrongSectionSuggestsTheKnownOne) {
  try {
    load_options_from_string<Demo>("file:\n  fps: 10\n", "s.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean 'camera.fps'?"), std::string::npos) << e.what();
  }
}

TEST(ConfigLoader, SyntaxErrorNamesFileAndLine) {
  try {
    load_options_from_string<Demo>("camera:\n  width: [1, 2\n", "bad.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not valid YAML"), std::string::npos) << e.what();
  }
}

TEST(ConfigLoader, MissingFileIsNamed) {
  try {
    wingman::common::load_options<Demo>("/nonexistent/wingman.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/wingman.yaml: cannot open"), std::string::npos);
  }
}

TEST(ConfigPrinter, PrintedConfigReadsBackToTheSameValues) {
  Demo d;
  d.width = 999;
  d.device = "we\"ird";
  d.k = {0.1, 1e-9};
  const std::string text = print_options(d, "header line");
  EXPECT_EQ(text.rfind("# header line\n", 0), 0u) << text;
  EXPECT_NE(text.find("  # pixels\n  width: 999\n"), std::string::npos) << text;
  const Demo back = load_options_from_string<Demo>(text, "printed");
  EXPECT_EQ(back.width, 999);
  EXPECT_EQ(back.device, "we\"ird");
  EXPECT_EQ(back.k, d.k);
  EXPECT_EQ(print_options(back), print_options(d));
}

// Issue 33, finding 6: a directory given as --config read as an empty file (all defaults, exit 0).
TEST(ConfigLoader, ADirectoryIsAnErrorNotAnEmptyConfig) {
  const std::string dir = ::testing::TempDir();
  try {
    wingman::common::ConfigLoader::from_file(dir);
    ADD_FAILURE() << "a directory was read as a config file";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), dir + ": is a directory, not a config file");
  }
}

// Issue 33, finding 5: a 663-byte alias bomb in a mapping took 4.2 GB, 31 s and wrote a 630 MB error line.
TEST(ConfigLoader, AnAliasBombIsANamedProblemNotGigabytes) {
  // Mappings of mappings: the loader walks every key of every expansion.
  std::string bomb = "a: &a {k: 1, l: 1, m: 1, n: 1, o: 1, p: 1, q: 1, r: 1, s: 1}\n";
  for (char c = 'b'; c <= 'i'; ++c) {
    const char p = static_cast<char>(c - 1);
    bomb += fmt::format(
        "{0}: &{0} {{k: *{1}, l: *{1}, m: *{1}, n: *{1}, o: *{1}, p: *{1}, q: *{1}, r: *{1}, s: *{1}}}\n", c, p);
  }
  ASSERT_LT(bomb.size(), 700u);  // 9^9 = 387 million keys once expanded
  const auto t0 = std::chrono::steady_clock::now();
  try {
    load_options_from_string<wingman::common::TimeSanityOptions>(bomb, "bomb.yaml");
    ADD_FAILURE() << "an alias bomb was loaded";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "bomb.yaml: YAML aliases expand to more than 100000 nodes (an alias bomb?)");
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  // A few aliases, as a person might write, still load.
  EXPECT_NO_THROW(load_options_from_string<wingman::common::TimeSanityOptions>(
      "time: {max_ahead_s: &t 0.5, resync_after_s: *t}\n", "ok.yaml"));
  // And a document larger than 1 MiB is refused by its size.
  EXPECT_THROW(load_options_from_string<wingman::common::TimeSanityOptions>(std::string(2 << 20, '#'), "big.yaml"),
               ConfigError);
}

}  // namespace

// Layered configuration (issue 32): --config A --config B (later wins) and --set KEY=VALUE over both.
namespace layered {

using wingman::common::ConfigSources;
using wingman::common::load_options;

std::string write_file(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/wingman_layered_" + name;
  std::FILE* f = std::fopen(path.c_str(), "w");
  EXPECT_NE(f, nullptr) << path;
  std::fputs(text.c_str(), f);
  std::fclose(f);
  return path;
}

std::string error_of(const ConfigSources& sources) {
  try {
    load_options<Demo>(sources);
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected ConfigError from " << sources.describe();
  return "";
}

TEST(ConfigLayers, LaterFilesWinKeyByKeyAndKeepTheRest) {
  const std::string a = write_file("a.yaml", "camera: {width: 1280, fps: 15}\nfile: {k: [1, 2, 3]}\n");
  const std::string b = write_file("b.yaml", "camera:\n  fps: 60\n");
  const Demo ab = load_options<Demo>(ConfigSources{{a, b}, {}});
  EXPECT_EQ(ab.width, 1280);     // only in a
  EXPECT_DOUBLE_EQ(ab.fps, 60);  // b over a
  EXPECT_EQ(ab.k, (std::vector<double>{1, 2, 3}));
  const Demo ba = load_options<Demo>(ConfigSources{{b, a}, {}});
  EXPECT_DOUBLE_EQ(ba.fps, 15);  // the order is the command line's
}

TEST(ConfigLayers, SetTakesScalarsAndSequencesOverEveryFile) {
  const std::string a = write_file("s.yaml", "camera: {width: 1280, device: /dev/video2}\nfile: {k: [1, 2]}\n");
  const Demo d = load_options<Demo>(ConfigSources{
      {a}, {"camera.width=320", "file.k=[-6,2,0]", "file.loop=true", "camera.device=", "camera.width=800"}});
  EXPECT_EQ(d.width, 800);  // the later --set wins
  EXPECT_EQ(d.k, (std::vector<double>{-6, 2, 0}));
  EXPECT_TRUE(d.loop);
  EXPECT_EQ(d.device, "");  // an empty value is YAML's null: an empty string
  // A mapping value sets each of its keys; no file at all is fine.
  const Demo m = load_options<Demo>(ConfigSources{{}, {"camera={fps: 5, width: 2}"}});
  EXPECT_DOUBLE_EQ(m.fps, 5);
  EXPECT_EQ(m.width, 2);
}

TEST(ConfigLayers, EveryBadSetIsNamedWithTheFilesProblemsInOneLine) {
  const std::string a = write_file("bad_a.yaml", "camera:\n  fps: fast\n");
  const std::string m = error_of(
      ConfigSources{{a}, {"camera.width=-3", "file.k=[1, x]", "camera.colour=red", "nonsense", "file.loop=maybe"}});
  EXPECT_NE(m.find("6 problems"), std::string::npos) << m;
  EXPECT_NE(m.find(a + ":2: camera.fps: expected a number, got 'fast'"), std::string::npos) << m;
  EXPECT_NE(m.find("--set file.k[1]: expected a number, got 'x'"), std::string::npos) << m;
  EXPECT_NE(m.find("--set camera.colour: unknown key"), std::string::npos) << m;
  EXPECT_NE(m.find("--set 'nonsense': expected KEY=VALUE"), std::string::npos) << m;
  EXPECT_NE(m.find("--set file.loop: expected true or false, got 'maybe'"), std::string::npos) << m;
  EXPECT_NE(m.find("--set camera.width = -3: must be > 0"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << "one line: " << m;
}

TEST(ConfigLayers, AnUnknownKeyInTheSecondFileNamesThatFile) {
  const std::string a = write_file("first.yaml", "camera: {width: 100}\n");
  const std::string b = write_file("second.yaml", "camera:\n  width: 0\n  colour: red\n");
  const std::string m = error_of(ConfigSources{{a, b}, {}});
  EXPECT_NE(m.find("2 problems"), std::string::npos) << m;
  EXPECT_NE(m.find(b + ":3: camera.colour: unknown key"), std::string::npos) << m;
  EXPECT_NE(m.find(b + ": camera.width = 0: must be > 0"), std::string::npos) << "the file that gave the value: " << m;
  EXPECT_EQ(m.find(a + ":"), std::string::npos) << "the first file has no problem: " << m;
  // A file that cannot be read is named, whichever layer it is.
  EXPECT_NE(error_of(ConfigSources{{a, "/nonexistent/second.yaml"}, {}}).find("/nonexistent/second.yaml: cannot open"),
            std::string::npos);
}

TEST(ConfigLayers, OneFileReadsAsBeforeAndDescribeNamesEverySource) {
  const std::string a = write_file("one.yaml", "camera:\n  fps: fast\n");
  EXPECT_NE(error_of(ConfigSources{{a}, {}}).find(a + ":2: camera.fps: expected a number"), std::string::npos);
  EXPECT_EQ(ConfigSources{}.describe(), "built-in defaults");
  EXPECT_EQ((ConfigSources{{"a.yaml", "b.yaml"}, {"x.y=1"}}.describe()), "a.yaml, b.yaml, --set x.y=1");
  EXPECT_EQ(load_options<Demo>(ConfigSources{}).width, 640);
}

}  // namespace layered
