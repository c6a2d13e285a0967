# SPDX-License-Identifier: MIT
# Writes OUTPUT (.cpp) defining wingman::detector::builtin_thesis_cfg() with the text of INPUT.
file(READ ${INPUT} _text)
file(WRITE ${OUTPUT} "// Generated from ${INPUT}; do not edit.\n#include \"wingman/detector/model_loader.hpp\"\n\nnamespace wingman::detector {\nconst char* builtin_thesis_cfg() {\n  return R\"wingmancfg(${_text})wingmancfg\";\n}\n}  // namespace wingman::detector\n")
