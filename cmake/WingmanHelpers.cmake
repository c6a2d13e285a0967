# SPDX-License-Identifier: MIT
# Small helpers shared by every folder's CMakeLists: warnings and one-line test registration.

# wingman_warnings(<target>): the project's warning set (not -Werror: Debian's headers vary).
function(wingman_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wno-unused-parameter)
endfunction()

# wingman_add_test(<name> SOURCES <files...> [LIBS <targets...>] [LABEL <label>] [TIMEOUT <s>] [NETNS])
# Builds one GoogleTest executable and registers each of its tests with CTest. NETNS runs each test
# in its own private network namespace (tools/netns_run.sh), for tests that use LCM multicast.
function(wingman_add_test name)
  cmake_parse_arguments(ARG "NETNS" "TIMEOUT;LABEL" "SOURCES;LIBS" ${ARGN})
  if(NOT ARG_LABEL)
    set(ARG_LABEL unit)
  endif()
  add_executable(${name} ${ARG_SOURCES})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  if(WINGMAN_UNITY_BUILD)  # up to 8 files a unit: no two may define the same name in an anonymous namespace
    set_target_properties(${name} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
  endif()
  # The test environment goes through the emulator (`env VAR=...`): gtest_discover_tests keeps only the first entry
  # of an ENVIRONMENT list property. NETNS tests then run inside tools/netns_run.sh's private network namespace.
  set(_emulator env "WINGMAN_BIN_DIR=${CMAKE_BINARY_DIR}/bin" "WINGMAN_TEST_BIN_DIR=${CMAKE_BINARY_DIR}/tests"
                "WINGMAN_SOURCE_DIR=${CMAKE_SOURCE_DIR}" "WINGMAN_BUILD_DIR=${CMAKE_BINARY_DIR}" "POCL_AFFINITY=1"
                "OMP_WAIT_POLICY=PASSIVE")
  if(ARG_NETNS)
    list(APPEND _emulator ${CMAKE_SOURCE_DIR}/tools/netns_run.sh)
  endif()
  set_target_properties(${name} PROPERTIES CROSSCOMPILING_EMULATOR "${_emulator}")
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gmock GTest::gtest_main)
  wingman_warnings(${name})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 120)
  endif()
  gtest_discover_tests(${name}
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR}
    PROPERTIES TIMEOUT ${ARG_TIMEOUT} LABELS ${ARG_LABEL}
    DISCOVERY_TIMEOUT 60)
endfunction()
