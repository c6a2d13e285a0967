// SPDX-License-Identifier: MIT
// The shipped model's weights (models/wingman-small.weights), assembled into the library with .incbin so that the
// detector needs no file at run time. Built without the file (WINGMAN_SMALL_WEIGHTS_PATH undefined), it has none.
#include "wingman/detector/model_loader.hpp"

#ifdef WINGMAN_SMALL_WEIGHTS_PATH
// clang-format off
asm(".pushsection .rodata\n"
    ".balign 16\n"
    "wingman_small_weights_begin:\n"
    ".incbin \"" WINGMAN_SMALL_WEIGHTS_PATH "\"\n"
    "wingman_small_weights_end:\n"
    ".popsection\n");
// clang-format on
extern "C" const char wingman_small_weights_begin[];
extern "C" const char wingman_small_weights_end[];
#endif

namespace wingman::detector {

std::vector<char> builtin_small_weights() {
#ifdef WINGMAN_SMALL_WEIGHTS_PATH
  return std::vector<char>(wingman_small_weights_begin, wingman_small_weights_end);
#else
  return {};
#endif
}

}  // namespace wingman::detector
