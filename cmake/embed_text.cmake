# SPDX-License-Identifier: MIT
# Writes OUTPUT (.cpp) defining `const char* NAMESPACE::FUNCTION()` that returns the text of INPUT, after including
# INCLUDE (the header that declares it). Run as cmake -DINPUT=... -DOUTPUT=... -DFUNCTION=... -DNAMESPACE=...
# -DINCLUDE=... -P embed_text.cmake.
foreach(_var INPUT OUTPUT FUNCTION NAMESPACE INCLUDE)
  if(NOT ${_var})
    message(FATAL_ERROR "embed_text.cmake: ${_var} is not set")
  endif()
endforeach()
file(READ ${INPUT} _text)
file(WRITE ${OUTPUT} "// Generated from ${INPUT}; do not edit.\n#include \"${INCLUDE}\"\n\nnamespace ${NAMESPACE} {\nconst char* ${FUNCTION}() {\n  return R\"wingmantext(${_text})wingmantext\";\n}\n}  // namespace ${NAMESPACE}\n")
