// SPDX-License-Identifier: MIT
// Fuzz target: the Darknet .weights reader (detector/src/darknet_weights.cpp) and the model loader
// (detector/src/model_loader.cpp), as model.cfg / model.weights read them. The input is records
// (fuzz_support.hpp): the first record's payload is a .weights file for tiny_model.hpp's network (read from
// memory); when a second record follows, the first is written as the .cfg file and the second as the .weights
// file and both go through load_model(). Anything wrong must be a DarknetFormatError.
#include "fuzz_support.hpp"
#include "tiny_model.hpp"

#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>
#include <wingman/detector/model_loader.hpp>

#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace wingman::detector;
  static const DarknetModel tiny = parse_darknet_cfg_string(wingman::fuzz::tiny_cfg(), "tiny.cfg");
  static wingman::fuzz::TempFile cfg_file(".cfg");
  static wingman::fuzz::TempFile weights_file(".weights");
  wingman::fuzz::Records records(data, size);
  uint8_t selector = 0;
  const uint8_t* first = nullptr;
  size_t first_size = 0;
  if (!records.next(&selector, &first, &first_size)) return 0;
  const uint8_t* second = nullptr;
  size_t second_size = 0;
  if (!records.next(&selector, &second, &second_size)) {
    DarknetModel model = tiny;
    try {
      load_darknet_weights_from_buffer(model, std::vector<char>(first, first + first_size), "<fuzz>.weights");
    } catch (const DarknetFormatError&) {
    }
    return 0;
  }
  try {
    const DarknetModel model = load_model(cfg_file.write(first, first_size), weights_file.write(second, second_size));
    (void)model;
  } catch (const DarknetFormatError&) {
  }
  return 0;
}
