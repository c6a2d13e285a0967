// SPDX-License-Identifier: MIT
// `wingman experiment`: experiment files (layering of defaults, flights and quick parts; every problem at once) and the
// dry run, which writes the scenarios and plans every flight without flying.
#include <gtest/gtest.h>
#include <wingman/common/config.hpp>
#include <wingman/tools/experiment.hpp>

#include "../support/test_support.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace wingman::tools {
namespace {

namespace fs = std::filesystem;
using wingman::testing::TempDir;

std::string write(const TempDir& dir, const std::string& name, const std::string& text) {
  const std::string path = dir.file(name);
  std::ofstream(path) << text;
  return path;
}

std::string error_of(const std::string& path, bool quick) {
  try {
    read_experiment(path, quick);
  } catch (const common::ConfigError& e) {
    return e.what();
  }
  return "";
}

const ExperimentFlight& flight(const Experiment& x, size_t table, const std::string& name) {
  for (const auto& f : x.tables.at(table).flights)
    if (f.name == name) return f;
  throw std::out_of_range("no flight " + name);
}

ExperimentOptions dry_run_options(const TempDir& dir) {
  ExperimentOptions o;
  o.dry_run = true;
  o.out = dir.file("out");
  o.config_dir = wingman::testing::source_path("config");
  o.bin_dir = fs::path(wingman::testing::bin_path("wingman-sim")).parent_path().string();
  o.lcm_url = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304";
  return o;
}

TEST(Experiment, EveryShippedFileReadsInBothModes) {
  const fs::path dir = wingman::testing::source_path("config/experiments");
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() != ".yaml") continue;
    ++files;
    for (const bool quick : {false, true}) {
      EXPECT_NO_THROW(read_experiment(e.path().string(), quick)) << e.path() << (quick ? " --quick" : "");
    }
  }
  EXPECT_GE(files, 9);
  // The suite: 8 flights and 10 sweeps (and a stand-in that flies only quick, without the meshes).
  const Experiment suite = read_experiment((dir / "suite.yaml").string(), false);
  ASSERT_EQ(suite.tables.size(), 2u);
  EXPECT_EQ(suite.folder, "suite");
  EXPECT_EQ(suite.tables[0].flights.size(), 8u);
  EXPECT_EQ(suite.tables[1].flights.size(), 11u);
  EXPECT_FALSE(flight(suite, 1, "w2011").run);
  EXPECT_EQ(flight(suite, 1, "w2003").sweep->to_m, 30.0);
  EXPECT_TRUE(suite.tables[0].args.empty());
  const Experiment quick = read_experiment((dir / "suite.yaml").string(), true);
  EXPECT_EQ(quick.folder, "suite-quick");
  EXPECT_TRUE(flight(quick, 1, "w2011").run);
  EXPECT_EQ(flight(quick, 1, "w2011").meshes, "absent");
  EXPECT_EQ(flight(quick, 1, "w2001").sweep->to_m, 12.0);
  EXPECT_EQ(flight(quick, 1, "w2001").sweep->frames_per_step, 4);
  EXPECT_FALSE(flight(quick, 0, "s1002").run);
  EXPECT_EQ(flight(quick, 0, "s1005").fly.duration_s, 8.0);
  EXPECT_EQ(quick.tables[0].args,
            (std::vector<std::string>{"--max-rms", "2.5", "--max-false", "250", "--max-false-other", "0"}));
}

TEST(Experiment, DefaultsThenTheFlightThenTheQuickParts) {
  TempDir dir;
  const std::string path = write(dir, "layers.yaml", R"(title: layers
tables:
  - summary: distance
    args: ["a"]
    quick: {args: ["b"]}
    defaults:
      fly: {flight: {scenario: fast_target, duration_s: 10}, processes: {localizer_set: [x=1]}}
      scenario_set: [seed=4]
      quick: {fly: {flight: {duration_s: 4}}, scenario_set: [seed=5]}
    flights:
      - name: one
        fly: {detector: {zoom_in: true}, processes: {localizer_set: [y=2]}}
        scenario_set: [duration_s=30]
        quick: {scenario_set: [duration_s=3]}
      - name: two
        fly: {flight: {duration_s: 20}}
        rescore_match_radius_m: [15]
)");
  const Experiment full = read_experiment(path, false);
  EXPECT_EQ(full.name, "layers");
  EXPECT_EQ(full.folder, "layers");
  EXPECT_EQ(full.tables[0].args, std::vector<std::string>{"a"});
  const ExperimentFlight& one = flight(full, 0, "one");
  EXPECT_EQ(one.fly.scenario, "fast_target");
  EXPECT_EQ(one.fly.duration_s, 10.0);
  EXPECT_TRUE(one.fly.zoom_in);
  EXPECT_EQ(one.fly.localizer_sets, std::vector<std::string>{"y=2"});  // a list is replaced, as any key
  EXPECT_EQ(one.scenario_sets, (std::vector<std::string>{"seed=4", "duration_s=30"}));  // appended
  EXPECT_EQ(flight(full, 0, "two").fly.duration_s, 20.0);
  EXPECT_EQ(flight(full, 0, "two").rescore_match_radii_m, std::vector<double>{15.0});

  const Experiment quick = read_experiment(path, true);
  EXPECT_EQ(quick.tables[0].args, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(flight(quick, 0, "one").fly.duration_s, 4.0);
  EXPECT_EQ(flight(quick, 0, "one").scenario_sets,
            (std::vector<std::string>{"seed=4", "duration_s=30", "seed=5", "duration_s=3"}));
  EXPECT_EQ(flight(quick, 0, "two").fly.duration_s, 4.0);  // the defaults' quick part comes after the flight's keys
}

TEST(Experiment, EveryProblemOfAFileAtOnceWithItsLine) {
  TempDir dir;
  const std::string path = write(dir, "bad.yaml", R"(title: bad
colour: red
tables:
  - summary: distance
    inputs: files
    flights:
      - name: one
        fly: {flight: {out: /tmp/x, duration_s: -1}}
      - name: one
        fly: {flight: {scenario: fast_target}}
        scenario_random: {seed: 3}
        meshes: maybe
      - fly: {flight: {duration_s: soon}}
        quick: {fly: {flight: {colour: blue}}}
)");
  const std::string e = error_of(path, false);
  EXPECT_NE(e.find("bad.yaml:2: colour: unknown key"), std::string::npos) << e;
  EXPECT_NE(e.find("bad.yaml:5: tables[0].inputs: 'files': expected eval or folder"), std::string::npos) << e;
  EXPECT_NE(e.find(":8: tables[0].flights[0].fly.flight.out: wingman experiment sets this itself"), std::string::npos)
      << e;
  EXPECT_NE(e.find(":8: tables[0].flights[0].fly.flight.duration_s = -1"), std::string::npos) << e;
  EXPECT_NE(e.find(":9: tables[0].flights[1].name: 'one' twice"), std::string::npos) << e;
  EXPECT_NE(e.find("tables[0].flights[1].fly.flight.scenario: give one scenario"), std::string::npos) << e;
  EXPECT_NE(e.find(":12: tables[0].flights[1].meshes: 'maybe': expected any, required or absent"), std::string::npos)
      << e;
  EXPECT_NE(e.find(":13: tables[0].flights[2].fly.flight.duration_s: expected a number"), std::string::npos) << e;
  EXPECT_NE(e.find("tables[0].flights[2].name: missing"), std::string::npos) << e;
  // The quick part is checked without --quick too.
  EXPECT_NE(e.find(":14: tables[0].flights[2].quick.fly.flight.colour: unknown key"), std::string::npos) << e;

  EXPECT_NE(error_of(write(dir, "empty.yaml", "title: x\n"), false).find("tables: missing"), std::string::npos);
  EXPECT_NE(error_of(dir.file("absent.yaml"), false).find("absent.yaml: cannot read"), std::string::npos);
  EXPECT_NE(error_of(write(dir, "broken.yaml", "tables: [\n"), false).find("not valid YAML"), std::string::npos);
}

TEST(Experiment, DryRunWritesTheScenariosAndPlansEveryFlightWithoutFlying) {
  TempDir dir;
  const std::string path = write(dir, "tiny.yaml", R"(title: tiny
tables:
  - summary: formation_2d
    defaults:
      fly: {flight: {scenario: formation_2d, duration_s: 3}}
    flights:
      - {name: run1, scenario_set: [seed=11]}
      - {name: drawn, scenario_random: {seed: 1005, airframe: quad, view: side, lighting: A}}
      - {name: needs, meshes: required, scenario_random: {seed: 1001, airframe: "{meshes}/no.glb"}}
      - {name: instead, meshes: absent, fly: {flight: {scenario: follow_1d}}}
      - {name: never, run: false}
)");
  ExperimentOptions o = dry_run_options(dir);
  o.names = {path};
  o.meshes = dir.file("no-meshes-here");
  std::ostringstream out, err;
  ASSERT_EQ(run_experiments(o, out, err), 0) << err.str();
  const std::string plans = out.str();
  EXPECT_NE(plans.find("# tiny / run1"), std::string::npos) << plans;
  EXPECT_NE(plans.find("# tiny / drawn"), std::string::npos) << plans;
  EXPECT_NE(plans.find("# tiny / instead"), std::string::npos) << plans;
  EXPECT_EQ(plans.find("# tiny / needs"), std::string::npos) << plans;  // no meshes: skipped, and said so
  EXPECT_EQ(plans.find("# tiny / never"), std::string::npos) << plans;
  EXPECT_NE(err.str().find("no shared meshes"), std::string::npos) << err.str();
  EXPECT_NE(plans.find("--duration 3"), std::string::npos) << plans;
  // The copy keeps the scenario's name (its config/flights files) with the seed set; the drawn one has its configs.
  const std::string copy = dir.file("out/tiny/scenarios/run1/formation_2d.yaml");
  ASSERT_TRUE(fs::exists(copy));
  std::ifstream in(copy);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("seed: 11"), std::string::npos) << text;
  EXPECT_NE(plans.find("--config " + dir.file("out/tiny/scenarios/drawn.localizer.yaml")), std::string::npos) << plans;
  EXPECT_FALSE(fs::exists(dir.file("out/tiny/run1/flight.lcmlog")));

  // With the meshes folder present, the flight that stands in for them is left out instead.
  fs::create_directories(dir.file("meshes"));
  o.meshes = dir.file("meshes");
  const std::string with = write(dir, "with.yaml", R"(tables:
  - summary: formation_2d
    flights:
      - {name: instead, meshes: absent, fly: {flight: {scenario: follow_1d}}}
      - {name: plain, fly: {flight: {scenario: follow_1d}}}
)");
  o.names = {with};
  std::ostringstream out2, err2;
  ASSERT_EQ(run_experiments(o, out2, err2), 0) << err2.str();
  EXPECT_EQ(out2.str().find("# with / instead"), std::string::npos) << out2.str();
  EXPECT_NE(out2.str().find("# with / plain"), std::string::npos) << out2.str();
}

TEST(Experiment, ListsExpandAndDetectionsAreChecked) {
  TempDir dir;
  ExperimentOptions o = dry_run_options(dir);
  o.names = {"all"};
  o.detections = "truth";
  std::ostringstream out, err;
  try {
    run_experiments(o, out, err);
    FAIL() << "static_sweep needs the detector";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("static_sweep"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--detections cnn only"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(out.str().empty());  // nothing planned: every file is checked first
  o.names = {"formation_2d", "follow_1d"};
  ASSERT_EQ(run_experiments(o, out, err), 0) << err.str();
  EXPECT_NE(out.str().find("# formation_2d / run3"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("# follow_1d / run"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("from_ground_truth: true"), std::string::npos);

  o.names = {"no_such_experiment"};
  EXPECT_THROW(run_experiments(o, out, err), common::ConfigError);
  std::ostringstream listed;
  list_experiments(wingman::testing::source_path("config"), listed);
  EXPECT_NE(listed.str().find("suite "), std::string::npos) << listed.str();
}

TEST(Experiment, MeshesPlaceholder) {
  EXPECT_EQ(expand_meshes("{meshes}/a.glb", "/m"), "/m/a.glb");
  EXPECT_EQ(expand_meshes("quad", "/m"), "quad");
  EXPECT_EQ(expand_meshes("{meshes}{meshes}", "{meshes}"), "{meshes}{meshes}");
}

}  // namespace
}  // namespace wingman::tools
