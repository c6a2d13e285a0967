// SPDX-License-Identifier: MIT
// The localizer and the simulator read the shared camera.* keys (geometry::CameraModelOptions) alike: the same values,
// the same printed lines, the same problems; each keeps its own extra key and the simulator its image size limit.
#include <gtest/gtest.h>
#include <wingman/common/config.hpp>
#include <wingman/geometry/calibration.hpp>
#include <wingman/localizer/localizer_options.hpp>
#include <wingman/sim/sim_options.hpp>

#include <sstream>
#include <string>

namespace {

using wingman::common::ConfigError;
using wingman::common::load_options_from_string;
using wingman::geometry::CameraModelOptions;
using wingman::localizer::LocalizerOptions;
using wingman::sim::SimOptions;

const char* const kCamera =
    "camera:\n"
    "  calibration: \"\"\n"
    "  kalibr_camera: cam3\n"
    "  camera_id: 2\n"
    "  width: 641\n"
    "  height: 479\n"
    "  focal_px: 333.25\n";

/// The shared keys' values, compared as a whole.
std::string shared(const CameraModelOptions& o) {
  return o.calibration + "|" + o.kalibr_camera + "|" + std::to_string(o.camera_id) + "|" + std::to_string(o.width) +
         "|" + std::to_string(o.height) + "|" + std::to_string(o.focal_px);
}

/// The lines of --print-config's camera: section that name one of the shared keys (and their comments).
std::string printed_camera_section(const std::string& printed) {
  std::istringstream in(printed);
  std::string line, out;
  bool inside = false;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] != ' ') inside = line == "camera:";
    if (inside && line.find("scale_to_image") == std::string::npos && line.find("rate_hz") == std::string::npos &&
        line.find("rescale intrinsics") == std::string::npos && line.find("frames per simulated") == std::string::npos)
      out += line + "\n";
  }
  return out;
}

TEST(SharedCameraKeys, LocalizerAndSimulatorReadThemIdentically) {
  const auto loc = load_options_from_string<LocalizerOptions>(kCamera, "<localizer>");
  const auto sim = load_options_from_string<SimOptions>(kCamera, "<sim>");
  EXPECT_EQ(shared(loc.camera), "|cam3|2|641|479|333.250000");
  EXPECT_EQ(shared(loc.camera), shared(sim.camera));
  EXPECT_EQ(make_camera(loc.camera).describe(), make_camera(sim.camera).describe());
  // Their own keys stay at their defaults.
  EXPECT_FALSE(loc.camera.scale_to_image);
  EXPECT_EQ(sim.camera.rate_hz, 30.0);
}

TEST(SharedCameraKeys, DefaultsAreTheSameCameraAndPrintTheSame) {
  const LocalizerOptions loc;
  const SimOptions sim;
  EXPECT_EQ(shared(loc.camera), shared(sim.camera));
  const std::string loc_printed = printed_camera_section(wingman::common::print_options(loc));
  EXPECT_NE(loc_printed.find("camera_id: 0"), std::string::npos) << loc_printed;
  EXPECT_EQ(loc_printed, printed_camera_section(wingman::common::print_options(sim)));
}

TEST(SharedCameraKeys, ABadValueIsTheSameProblemInBoth) {
  const std::string bad = "camera:\n  camera_id: -1\n  focal_px: 0\n";
  for (const char* line : {"camera.camera_id = -1: must be >= 0", "camera.focal_px = 0: must be finite and > 0"}) {
    try {
      (void)load_options_from_string<LocalizerOptions>(bad, "<localizer>");
      ADD_FAILURE() << "the localizer accepted " << bad;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(line), std::string::npos) << e.what();
    }
    try {
      (void)load_options_from_string<SimOptions>(bad, "<sim>");
      ADD_FAILURE() << "the simulator accepted " << bad;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(line), std::string::npos) << e.what();
    }
  }
}

TEST(SharedCameraKeys, TheSimulatorBoundsTheImageByWhatSubscribersAccept) {
  // The localizer takes a camera up to 16384 px a side; the simulator's images must pass common::ImageLimits (8192).
  const std::string wide = "camera:\n  width: 9000\n";
  EXPECT_EQ(load_options_from_string<LocalizerOptions>(wide, "<localizer>").camera.width, 9000);
  try {
    (void)load_options_from_string<SimOptions>(wide, "<sim>");
    ADD_FAILURE() << "the simulator accepted " << wide;
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("camera.width = 9000: must be in 1..8192"), std::string::npos) << e.what();
  }
}

}  // namespace
