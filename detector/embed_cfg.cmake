# SPDX-License-Identifier: MIT
# Writes OUTPUT (.cpp) defining wingman::detector::FUNCTION() (default builtin_thesis_cfg) with the text of INPUT.
if(NOT FUNCTION)
  set(FUNCTION builtin_thesis_cfg)
endif()
file(READ ${INPUT} _text)
file(WRITE ${OUTPUT} "// Generated from ${INPUT}; do not edit.\n#include \"wingman/detector/model_loader.hpp\"\n\nnamespace wingman::detector {\nconst char* ${FUNCTION}() {\n  return R\"wingmancfg(${_text})wingmancfg\";\n}\n}  // namespace wingman::detector\n")
