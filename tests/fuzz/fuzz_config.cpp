// SPDX-License-Identifier: MIT
// Fuzz target: the YAML config loader (common/src/config.cpp) through each process's options, as --config reads
// them (load_options; here from the text). The first byte picks the process; the rest is the YAML file. A
// config that loads must print (--print-config) and load again from what was printed.
#include "fuzz_support.hpp"

#include <wingman/camera_driver/camera_driver_options.hpp>
#include <wingman/common/config.hpp>
#include <wingman/detector/detector_options.hpp>
#include <wingman/follower_ctrl/follower_options.hpp>
#include <wingman/localizer/localizer_options.hpp>
#include <wingman/mavlink_bridge/bridge_options.hpp>
#ifdef WINGMAN_FUZZ_WITH_SIM
#include <wingman/sim/sim_options.hpp>
#endif

#include <cstdlib>

namespace {

template <class Options>
void one(const std::string& text) {
  Options options;
  try {
    options = wingman::common::load_options_from_string<Options>(text, "<fuzz>");
  } catch (const wingman::common::ConfigError&) {
    return;  // the process exits 2 with the message
  }
  const std::string printed = wingman::common::print_options(options);
  try {
    (void)wingman::common::load_options_from_string<Options>(printed, "<printed>");
  } catch (const wingman::common::ConfigError& e) {
    std::fprintf(stderr, "--print-config output does not load again: %s\n---\n%s\n", e.what(), printed.c_str());
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  switch (data[0] % 6) {
    case 0:
      one<wingman::camera_driver::CameraDriverOptions>(text);
      break;
    case 1:
      one<wingman::detector::DetectorOptions>(text);
      break;
    case 2:
      one<wingman::localizer::LocalizerOptions>(text);
      break;
    case 3:
      one<wingman::follower_ctrl::FollowerOptions>(text);
      break;
    case 5:
      one<wingman::mavlink_bridge::BridgeOptions>(text);
      break;
    default:
#ifdef WINGMAN_FUZZ_WITH_SIM
      one<wingman::sim::SimOptions>(text);
#else
      one<wingman::localizer::LocalizerOptions>(text);
#endif
      break;
  }
  return 0;
}
