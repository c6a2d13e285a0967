// SPDX-License-Identifier: MIT
// Every process takes layered --config files and --set overrides through the common runtime (issue 32): the merged
// result in --print-config, every bad key at once naming its file or --set, exit 2.
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

namespace {

using wingman::testing::bin_path;
using wingman::testing::run;
using wingman::testing::source_path;
using wingman::testing::TempDir;

struct Process {
  std::string executable, config;        // its shipped config/<config>.yaml
  std::string text_key, a, b;            // a string key (section.name) layered by two files, and their values
  std::string number_key, set, printed;  // a key (section.name) set by --set, and its printed line
};
const std::vector<Process> kProcesses = {
    {"wingman-camera-driver", "camera_driver", "v4l2.device", "/dev/video5", "/dev/video6", "v4l2.width", "77",
     "width: 77"},
    {"wingman-detector", "detector", "input.channel", "IMAGE_A", "IMAGE_B", "input.max_image_width", "77",
     "max_image_width: 77"},
    {"wingman-localizer", "localizer", "input.detections_channel", "DET_A", "DET_B", "camera.width", "77", "width: 77"},
    {"wingman-follower-ctrl", "follower_ctrl", "input.targets_channel", "TARGETS_A", "TARGETS_B", "formation.offset_m",
     "[-6,2,0]", "offset_m: [-6.0, 2.0, 0.0]"},
    {"wingman-recorder", "recorder", "output.file_prefix", "flight_a", "flight_b", "output.max_segment_mib", "77",
     "max_segment_mib: 77.0"},
    {"wingman-mavlink", "mavlink_bridge", "link.url", "udp://:14550", "udp://:14551", "link.baud", "57600",
     "baud: 57600"},
#ifdef WINGMAN_WITH_SIM
    {"wingman-sim", "sim", "input.setpoint_channel", "SETPOINT_A", "SETPOINT_B", "camera.width", "77", "width: 77"},
#endif
};

void write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }
bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }
// "a.b" and "v" -> "a:\n  b: v\n" (plus `more` lines in the same section).
std::string yaml(const std::string& key, const std::string& value, const std::string& more = "") {
  const auto dot = key.find('.');
  return key.substr(0, dot) + ":\n  " + key.substr(dot + 1) + ": " + value + "\n" + more;
}
std::string name_of(const std::string& key) { return key.substr(key.find('.') + 1); }
std::string section_of(const std::string& key) { return key.substr(0, key.find('.')); }

TEST(ProcessConfigLayers, EveryProcessLayersFilesThenSetAndPrintsTheMergedResult) {
  TempDir dir;
  for (const auto& p : kProcesses) {
    SCOPED_TRACE(p.executable);
    const std::string shipped = source_path("config/" + p.config + ".yaml");
    write(dir.file("a.yaml"), yaml(p.text_key, p.a));
    write(dir.file("b.yaml"), yaml(p.text_key, p.b));
    const auto r = run({bin_path(p.executable), "--config", shipped, "--config", dir.file("a.yaml"), "--config",
                        dir.file("b.yaml"), "--set", p.number_key + "=[1, 1]", "--set", p.number_key + "=" + p.set,
                        "--print-config"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(has(r.out, "  " + name_of(p.text_key) + ": \"" + p.b + "\"\n")) << r.out;  // b over a over shipped
    EXPECT_TRUE(has(r.out, "  " + p.printed + "\n")) << r.out;  // the later --set over everything
    EXPECT_TRUE(has(r.out, "(from " + shipped + ", " + dir.file("a.yaml") + ", " + dir.file("b.yaml") + ", --set "))
        << r.out;
  }
}

TEST(ProcessConfigLayers, EveryBadKeyOfEveryLayerIsOneLineNamingItsSource) {
  TempDir dir;
  for (const auto& p : kProcesses) {
    SCOPED_TRACE(p.executable);
    write(dir.file("first.yaml"), yaml(p.text_key, p.a));
    write(dir.file("second.yaml"), yaml(p.text_key, p.b, "  colour: red\n"));
    const auto r = run({bin_path(p.executable), "--config", dir.file("first.yaml"), "--config", dir.file("second.yaml"),
                        "--set", p.number_key + "=soon", "--set", "nonsense", "--print-config"});
    EXPECT_EQ(r.exit_code, 2) << r.out;
    EXPECT_TRUE(has(r.err, "3 problems in configuration")) << r.err;
    EXPECT_TRUE(has(r.err, dir.file("second.yaml") + ":3: " + section_of(p.text_key) + ".colour: unknown key"))
        << r.err;
    EXPECT_TRUE(has(r.err, "--set " + p.number_key + ": expected a")) << r.err;
    EXPECT_TRUE(has(r.err, "--set 'nonsense': expected KEY=VALUE")) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
  }
}

}  // namespace
