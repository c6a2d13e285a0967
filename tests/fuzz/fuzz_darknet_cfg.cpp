// SPDX-License-Identifier: MIT
// Fuzz target: the Darknet .cfg reader (detector/src/darknet_cfg.cpp), as model.cfg reads it. Anything wrong must
// be a DarknetFormatError; a cfg that parses must write back to a cfg that parses to the same shapes.
#include "fuzz_support.hpp"

#include <wingman/detector/darknet_cfg.hpp>

#include <cstdlib>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace wingman::detector;
  const std::string text(reinterpret_cast<const char*>(data), size);
  DarknetModel model;
  try {
    model = parse_darknet_cfg_string(text, "<fuzz>");
  } catch (const DarknetFormatError&) {
    return 0;
  }
  const std::string written = write_darknet_cfg(model);
  try {
    const DarknetModel again = parse_darknet_cfg_string(written, "<written>");
    if (again.layers.size() != model.layers.size() || again.weight_count() != model.weight_count()) {
      std::fprintf(stderr, "write_darknet_cfg does not round-trip:\n%s\n", written.c_str());
      std::abort();
    }
  } catch (const DarknetFormatError& e) {
    std::fprintf(stderr, "write_darknet_cfg output does not parse: %s\n%s\n", e.what(), written.c_str());
    std::abort();
  }
  return 0;
}
