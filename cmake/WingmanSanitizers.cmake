# SPDX-License-Identifier: MIT
# Sanitizer and libFuzzer builds (docs/reliability.md, tools/sanitize.sh).
#   WINGMAN_SANITIZE        "" (default), "address,undefined" or "thread": instruments every target (libraries,
#                           processes, tests). UBSan findings abort (-fno-sanitize-recover), so they fail the test.
#   WINGMAN_BUILD_FUZZERS   OFF (default); ON needs clang: the project is compiled with -fsanitize=fuzzer-no-link
#                           and the targets in tests/fuzz are linked with -fsanitize=fuzzer.
#   WINGMAN_FUZZ_SECONDS    the most seconds each fuzz.<target> test runs libFuzzer (default 60).
#   WINGMAN_FUZZ_RUNS       inputs each fuzz.<target> test tries (default 0: until WINGMAN_FUZZ_SECONDS). With a
#                           fixed seed (run_fuzzer.sh) a run count makes the run the same on every machine, fast
#                           or slow, as long as it ends before WINGMAN_FUZZ_SECONDS: CI uses it.
# Without these options the build is unchanged.

set(WINGMAN_SANITIZE "" CACHE STRING "Sanitizers for every target: '', 'address,undefined' or 'thread'")
set_property(CACHE WINGMAN_SANITIZE PROPERTY STRINGS "" "address,undefined" "thread")
option(WINGMAN_BUILD_FUZZERS "Build the libFuzzer targets (clang only)" OFF)
set(WINGMAN_FUZZ_SECONDS 60 CACHE STRING "The most seconds each fuzz.<target> test runs libFuzzer")
set(WINGMAN_FUZZ_RUNS 0 CACHE STRING "Inputs each fuzz.<target> test tries (0: until WINGMAN_FUZZ_SECONDS)")

if(WINGMAN_SANITIZE STREQUAL "address,undefined")
  # No vptr check: it needs RTTI of every polymorphic type, which uninstrumented libraries (OpenCV, LCM) lack.
  set(_wingman_san_flags -fsanitize=address,undefined -fno-sanitize=vptr -fno-sanitize-recover=undefined
                         -fno-omit-frame-pointer)
elseif(WINGMAN_SANITIZE STREQUAL "thread")
  set(_wingman_san_flags -fsanitize=thread -fno-omit-frame-pointer)
elseif(NOT WINGMAN_SANITIZE STREQUAL "")
  message(FATAL_ERROR "WINGMAN_SANITIZE='${WINGMAN_SANITIZE}': must be '', 'address,undefined' or 'thread'")
endif()

if(WINGMAN_BUILD_FUZZERS)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang" OR NOT CMAKE_C_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "WINGMAN_BUILD_FUZZERS needs clang (libFuzzer): configure with "
                        "-DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++")
  endif()
  if(WINGMAN_SANITIZE STREQUAL "thread")
    message(FATAL_ERROR "WINGMAN_BUILD_FUZZERS: use WINGMAN_SANITIZE='' or 'address,undefined', not 'thread'")
  endif()
  list(APPEND _wingman_san_flags -fsanitize=fuzzer-no-link)
endif()

if(_wingman_san_flags)
  # Directory-wide from here on: every target below the top-level CMakeLists gets them, compile and link.
  add_compile_options(${_wingman_san_flags})
  list(REMOVE_ITEM _wingman_san_flags -fsanitize=fuzzer-no-link)  # the fuzzer runtime links only into fuzz targets
  add_link_options(${_wingman_san_flags})
  message(STATUS "wingman: WINGMAN_SANITIZE='${WINGMAN_SANITIZE}' WINGMAN_BUILD_FUZZERS=${WINGMAN_BUILD_FUZZERS}")
endif()
