// SPDX-License-Identifier: MIT
// YamlMappingReader: flattened keys, every conversion problem with file, line and key path, unknown and non-plain
// keys, nested prefixes, and the same texts as ConfigLoader.
#include <gtest/gtest.h>
#include <wingman/common/config.hpp>
#include <wingman/common/yaml_mapping_reader.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace {

using wingman::common::YamlMappingReader;
using Problems = std::vector<std::string>;

/// One value of every supported type, with defaults a test can tell apart from what a file gives.
struct Values {
  bool flag = false;
  int count = 7;
  int64_t stamp = -5;
  uint64_t seed = 9;
  double speed = 1.5;
  std::string label = "default";
  std::vector<double> gains = {0.5};
  std::vector<int> ids = {4};
  std::vector<std::string> tags = {"t"};
  std::array<double, 3> position = {1, 2, 3};

  template <class V>
  void visit(V& v) {
    v("flag", flag, "");
    v("count", count, "");
    v("stamp", stamp, "");
    v("seed", seed, "");
    v("motion.speed", speed, "");
    v("motion.label", label, "");
    v("gains", gains, "");
    v("ids", ids, "");
    v("tags", tags, "");
    v("initial.position", position, "");
  }
};

TEST(YamlMappingReader, ReadsNestedKeysOfEveryTypeAndKeepsDefaultsForMissingOnes) {
  const YAML::Node root = YAML::Load(
      "flag: true\ncount: -12\nstamp: 1700000000000000\nseed: 18446744073709551615\n"
      "motion: {speed: 2.25, label: fast}\ngains: [1, 2.5]\ntags: [a, b]\ninitial: {position: [4, -5, 6.5]}\n");
  Problems problems;
  Values v;
  YamlMappingReader r("v.yaml", root, "", &problems);
  v.visit(r);
  r.finish();
  EXPECT_EQ(problems, Problems{});
  EXPECT_TRUE(v.flag);
  EXPECT_EQ(v.count, -12);
  EXPECT_EQ(v.stamp, 1700000000000000);
  EXPECT_EQ(v.seed, UINT64_MAX);
  EXPECT_DOUBLE_EQ(v.speed, 2.25);
  EXPECT_EQ(v.label, "fast");
  EXPECT_EQ(v.gains, (std::vector<double>{1, 2.5}));
  EXPECT_EQ(v.ids, (std::vector<int>{4})) << "missing: the default";
  EXPECT_EQ(v.tags, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(v.position, (std::array<double, 3>{4, -5, 6.5}));
}

TEST(YamlMappingReader, ANullStringIsEmptyAndANullNumberIsNothing) {
  const YAML::Node root = YAML::Load("motion:\n  label:\n  speed: ~\n");
  Problems problems;
  Values v;
  YamlMappingReader r("n.yaml", root, "", &problems);
  v.visit(r);
  EXPECT_EQ(v.label, "");
  EXPECT_DOUBLE_EQ(v.speed, 1.5);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0], "n.yaml:3: motion.speed: expected a number, got nothing");
}

TEST(YamlMappingReader, EveryConversionProblemNamesFileLineAndTheFullKeyPath) {
  // The second vehicle of a list: messages carry "vehicles[1]." and the leaf's own line.
  const YAML::Node root = YAML::Load(
      "vehicles:\n"                        // 1
      "  - {flag: true}\n"                 // 2
      "  - flag: maybe\n"                  // 3
      "    count: 3000000000\n"            // 4
      "    stamp: soon\n"                  // 5
      "    seed: -1\n"                     // 6
      "    motion:\n"                      // 7
      "      speed: fast\n"                // 8
      "      label: [a, b]\n"              // 9
      "    gains: [1, x, 3]\n"             // 10
      "    ids: [1, 2.5]\n"                // 11
      "    tags: [a, {b: 1}]\n"            // 12
      "    initial: {position: [1, 2]}\n"  // 13
  );
  Problems problems;
  Values v;
  const Values defaults;
  YamlMappingReader r("t.yaml", root["vehicles"][1], "vehicles[1].", &problems);
  v.visit(r);
  r.finish();
  const Problems expected = {
      "t.yaml:3: vehicles[1].flag: expected true or false, got 'maybe'",
      "t.yaml:4: vehicles[1].count: integer 3000000000 out of range",
      "t.yaml:5: vehicles[1].stamp: expected an integer, got 'soon'",
      "t.yaml:6: vehicles[1].seed: expected a non-negative integer, got '-1'",
      "t.yaml:8: vehicles[1].motion.speed: expected a number, got 'fast'",
      "t.yaml:9: vehicles[1].motion.label: expected a string, got a sequence",
      "t.yaml:10: vehicles[1].gains[1]: expected a number, got 'x'",
      "t.yaml:11: vehicles[1].ids[1]: expected an integer, got '2.5'",
      "t.yaml:12: vehicles[1].tags[1]: expected a string, got a mapping",
      "t.yaml:13: vehicles[1].initial.position: expected 3 numbers [x, y, z], got 2",
  };
  EXPECT_EQ(problems, expected);
  // A value that does not convert keeps its default, a sequence included (not half of it).
  EXPECT_EQ(v.flag, defaults.flag);
  EXPECT_EQ(v.count, defaults.count);
  EXPECT_EQ(v.seed, defaults.seed);
  EXPECT_EQ(v.gains, defaults.gains);
  EXPECT_EQ(v.position, defaults.position);
}

TEST(YamlMappingReader, AScalarWhereASequenceBelongsNamesTheSequenceType) {
  const YAML::Node root = YAML::Load("gains: 3\nids: one\ntags: x\ninitial:\n  position: 5\n");
  Problems problems;
  Values v;
  YamlMappingReader r("s.yaml", root, "", &problems);
  v.visit(r);
  const Problems expected = {
      "s.yaml:1: gains: expected a sequence of numbers, got '3'",
      "s.yaml:2: ids: expected a sequence of integers, got 'one'",
      "s.yaml:3: tags: expected a sequence of strings, got 'x'",
      "s.yaml:5: initial.position: expected a sequence of numbers, got '5'",
  };
  EXPECT_EQ(problems, expected);
}

TEST(YamlMappingReader, UnknownKeysAreNamedWithTheirLineAndTheHint) {
  const YAML::Node root = YAML::Load("waypoints:\n  - position: [0, 0, 1]\n    colour: red\n    motion: {sped: 2}\n");
  Problems problems;
  Values v;
  YamlMappingReader r("u.yaml", root["waypoints"][0], "waypoints[0].", &problems);
  v.visit(r);
  r.finish(" (see the docs)");
  const Problems expected = {
      "u.yaml:3: waypoints[0].colour: unknown key (see the docs)",
      "u.yaml:4: waypoints[0].motion.sped: unknown key (see the docs)",
      "u.yaml:2: waypoints[0].position: unknown key (see the docs)",  // keys in sorted order
  };
  EXPECT_EQ(problems, expected);
}

TEST(YamlMappingReader, TakeListGivesTheItemsOrNamesWhatIsThereInstead) {
  const YAML::Node root = YAML::Load("flights:\n  - {name: a}\n  - {name: b}\ntables: 3\nnone:\n");
  Problems problems;
  YamlMappingReader r("l.yaml", root, "", &problems);
  const auto flights = r.take_list("flights", true);
  ASSERT_EQ(flights.size(), 2u);
  EXPECT_EQ(flights[1]["name"].as<std::string>(), "b");
  EXPECT_TRUE(r.take_list("tables", true).empty());
  EXPECT_TRUE(r.take_list("none", false).empty());    // null, optional: nothing, no problem
  EXPECT_TRUE(r.take_list("absent", false).empty());  // absent, optional: the same
  EXPECT_TRUE(r.take_list("stages", true).empty());
  r.finish();  // every key taken: none unknown
  const Problems expected = {"l.yaml:4: tables: expected a list of mappings, got '3'",
                             "l.yaml: stages: missing (a list of mappings)"};
  EXPECT_EQ(problems, expected);
}

TEST(YamlMappingReader, AKeyThatIsNotAPlainNameIsNamedByTheMappingHoldingIt) {
  // Found by fuzz.config in ConfigLoader: YAML's complex keys ("? ...") made yaml-cpp throw.
  const YAML::Node root = YAML::Load(
      "? [a, b]\n"        // 1
      ": 1\n"             // 2
      "vehicles:\n"       // 3
      "  - ? [c]\n"       // 4
      "    : 2\n"         // 5
      "    motion:\n"     // 6
      "      ? {d: 1}\n"  // 7
      "      : 3\n"       // 8
      "      speed: 4\n"  // 9
  );
  Problems problems;
  Values top_values;
  YamlMappingReader top("k.yaml", root, "", &problems);
  (void)top.take("vehicles");
  Values v;
  YamlMappingReader vehicle("k.yaml", root["vehicles"][0], "vehicles[0].", &problems);
  v.visit(vehicle);
  vehicle.finish();
  const Problems expected = {
      "k.yaml:1: (top level): a key must be a plain name, got a sequence",
      "k.yaml:4: vehicles[0]: a key must be a plain name, got a sequence",
      "k.yaml:7: vehicles[0].motion: a key must be a plain name, got a mapping",
  };
  EXPECT_EQ(problems, expected);
  EXPECT_DOUBLE_EQ(v.speed, 4.0) << "the other keys are still read";
}

TEST(YamlMappingReader, SomethingOtherThanAMappingIsOneProblemAndNothingIsRead) {
  const YAML::Node root = YAML::Load("vehicles:\n  - [1, 2]\n  - plain\n  -\n");
  Problems problems;
  for (size_t i = 0; i < 3; ++i) {
    Values v;
    YamlMappingReader r("m.yaml", root["vehicles"][i], "vehicles[" + std::to_string(i) + "].", &problems);
    v.visit(r);
    r.finish();
    EXPECT_FALSE(r.has("flag"));
  }
  const Problems expected = {
      "m.yaml:2: vehicles[0]: expected a mapping, got a sequence",
      "m.yaml:3: vehicles[1]: expected a mapping, got 'plain'",
      // vehicles[2] is null: an empty mapping, no problem
  };
  EXPECT_EQ(problems, expected);
}

TEST(YamlMappingReader, ProblemsAndValidationLinesCarryTheLeafsLineOrNoneWhenItIsAbsent) {
  const YAML::Node root = YAML::Load("vehicles:\n  - name: a\n    motion:\n      speed: -2\n");
  Problems problems;
  YamlMappingReader r("p.yaml", root["vehicles"][0], "vehicles[0].", &problems);
  EXPECT_TRUE(r.has("motion.speed"));
  EXPECT_FALSE(r.has("motion"));
  r.problem("name", "must not be a");
  r.problem("id", "missing: every vehicle needs an id");
  r.validation_problem("motion.speed = -2: must be >= 0");
  r.validation_problem("motion.accel: must be > 0");
  const Problems expected = {
      "p.yaml:2: vehicles[0].name: must not be a",
      "p.yaml: vehicles[0].id: missing: every vehicle needs an id",
      "p.yaml:4: vehicles[0].motion.speed = -2: must be >= 0",
      "p.yaml: vehicles[0].motion.accel: must be > 0",
  };
  EXPECT_EQ(problems, expected);
  EXPECT_EQ(r.source_name(), "p.yaml");
  EXPECT_EQ(r.path_prefix(), "vehicles[0].");
}

TEST(YamlMappingReader, TakeHandsOverASequenceAndMarksItKnown) {
  const YAML::Node root = YAML::Load("waypoints:\n  - {speed: 1}\n  - {speed: x}\nother: 1\nempty:\n");
  Problems problems;
  YamlMappingReader top("w.yaml", root, "", &problems);
  const YAML::Node list = top.take("waypoints");
  EXPECT_FALSE(top.take("absent").IsDefined()) << "absent: undefined (scenarios report it as missing)";
  EXPECT_TRUE(top.take("empty").IsDefined() && top.take("empty").IsNull()) << "'empty:' is there, a null";
  top.finish();
  ASSERT_TRUE(list.IsSequence());
  for (size_t i = 0; i < list.size(); ++i) {
    double speed = 0;
    YamlMappingReader w(top.source_name(), list[i], "waypoints[" + std::to_string(i) + "].", &problems);
    w("speed", speed, "");
    w.finish();
  }
  const Problems expected = {
      "w.yaml:4: other: unknown key",
      "w.yaml:3: waypoints[1].speed: expected a number, got 'x'",
  };
  EXPECT_EQ(problems, expected);
}

TEST(YamlMappingReader, DescribeNamesWhatANodeHolds) {
  EXPECT_EQ(YamlMappingReader::describe(YAML::Load("abc")), "'abc'");
  EXPECT_EQ(YamlMappingReader::describe(YAML::Load("[1]")), "a sequence");
  EXPECT_EQ(YamlMappingReader::describe(YAML::Load("{a: 1}")), "a mapping");
  EXPECT_EQ(YamlMappingReader::describe(YAML::Load("~")), "nothing");
  EXPECT_EQ(YamlMappingReader::describe(YAML::Node()), "nothing");
  const YAML::Node map = YAML::Load("{a: 1}");
  EXPECT_EQ(YamlMappingReader::describe(map["absent"]), "nothing");
}

/// The types ConfigLoader reads too, for the comparison below.
struct ConfigValues {
  bool flag = false;
  int count = 7;
  int64_t stamp = -5;
  double speed = 1.5;
  std::string label = "default";
  std::vector<double> gains = {0.5};
  std::vector<int> ids = {4};
  std::vector<std::string> tags = {"t"};

  template <class V>
  void visit(V& v) {
    v("a.flag", flag, "");
    v("a.count", count, "");
    v("a.stamp", stamp, "");
    v("a.speed", speed, "");
    v("b.label", label, "");
    v("b.gains", gains, "");
    v("b.ids", ids, "");
    v("b.tags", tags, "");
  }
  std::vector<std::string> validate() const { return {}; }
};

TEST(YamlMappingReader, GivesTheSameTextsAsConfigLoader) {
  // One conversion and one flattening behind both: every problem of the reader is one of ConfigLoader's.
  const std::string text =
      "a:\n  flag: 2\n  count: 1e99\n  stamp: [1]\n  speed: ~\n  ? [x]\n  : 1\n"
      "b:\n  label: [c]\n  gains: [1, [2]]\n  ids: 3\n  tags: [a, [b]]\n  extra: 1\n";
  Problems problems;
  ConfigValues reader_values;
  YamlMappingReader r("same.yaml", YAML::Load(text), "", &problems);
  reader_values.visit(r);
  r.finish();
  ASSERT_EQ(problems.size(), 10u);
  try {
    wingman::common::load_options_from_string<ConfigValues>(text, "same.yaml");
    FAIL() << "expected ConfigError";
  } catch (const wingman::common::ConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("10 problems"), std::string::npos) << m;
    for (const auto& p : problems) EXPECT_NE(m.find(p), std::string::npos) << p << "\nnot in\n" << m;
  }
}

}  // namespace
