#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Sanitizer runs of the test suite (docs/reliability.md). Builds with clang and runs ctest there.
# Usage: tools/sanitize.sh asan|tsan [ctest args...]
#   asan  build-asan: AddressSanitizer + UndefinedBehaviorSanitizer, libFuzzer targets ON, training OFF.
#         Without ctest args: stage 1 runs the whole suite (except the fuzz label and the exclusions below),
#         stage 2 the fuzz targets (fuzz.*: WINGMAN_FUZZ_RUNS inputs each, default 100000 here, from a fixed seed,
#         so CI tries the same inputs on any machine; at most WINGMAN_FUZZ_SECONDS each, default 90 here).
#   tsan  build-tsan: ThreadSanitizer. Without ctest args: the multi-process tests and the tests whose code
#         runs threads (TSAN_TESTS below).
# With ctest args, only `ctest <args>` runs (e.g. `tools/sanitize.sh asan -R fuzz_corpus`).
# The trainer (libtorch) is not built. asan builds the simulator (for the scenario parser's fuzz target) but runs
# none of the tests that render (label sim, and the supervision fault test's flight): Mesa's llvmpipe is not
# instrumented and a rendered flight takes minutes even without a sanitizer; nor does it build the test executables
# that only render (WINGMAN_BUILD_RENDER_TESTS=OFF). tsan builds no simulator.
# Environment: WINGMAN_FUZZ_RUNS, WINGMAN_FUZZ_SECONDS (inputs and the most seconds per fuzz target; RUNS=0:
#   fuzz for the whole time, e.g. WINGMAN_FUZZ_RUNS=0 WINGMAN_FUZZ_SECONDS=600 for a longer hunt), JOBS (build and ctest parallelism, default 2),
#   SANITIZE_TARGETS (build only these targets, space-separated; default: everything the stage needs).
# Each stage's wall time is printed ("sanitize: <stage> took N s").
set -euo pipefail
cd "$(dirname "$0")/.."
if [[ $# -lt 1 || ( $1 != asan && $1 != tsan ) ]]; then
  echo "usage: $0 asan|tsan [ctest args...]" >&2
  exit 2
fi
kind=$1
shift
jobs=${JOBS:-2}
root=$(pwd)
supp=$root/tools/sanitizers
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$(dirname "$root")}
export POCL_AFFINITY=1 OMP_WAIT_POLICY=PASSIVE OPENBLAS_NUM_THREADS=1

# shellcheck source=tools/lib/stage.sh
. tools/lib/stage.sh  # stage PREFIX NAME CMD...: runs CMD and prints its wall time

# Line tables only (-gline-tables-only, not -g): the sanitizers' reports need functions, files and lines, not
# variables and types; a translation unit compiles about a quarter faster (tools/src/replay.cpp under ASan: 21 -> 16 s)
# and its object is a third smaller, which shortens CI's two sanitizer builds.
common_cmake=(-G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++
  "-DCMAKE_C_FLAGS_RELWITHDEBINFO=-O2 -gline-tables-only -DNDEBUG"
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -gline-tables-only -DNDEBUG"
  -DWINGMAN_WITH_TRAINING=OFF -DWINGMAN_BUILD_BENCHMARKS=OFF)
# ccache where installed (developers); CI builds without it.
if command -v ccache > /dev/null; then
  common_cmake+=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi

if [[ $kind == asan ]]; then
  build=build-asan
  stage sanitize "asan configure" cmake -S . -B $build "${common_cmake[@]}" -DWINGMAN_SANITIZE=address,undefined \
    -DWINGMAN_BUILD_RENDER_TESTS=OFF -DWINGMAN_BUILD_FUZZERS=ON -DWINGMAN_FUZZ_SECONDS="${WINGMAN_FUZZ_SECONDS:-90}" \
    -DWINGMAN_FUZZ_RUNS="${WINGMAN_FUZZ_RUNS:-100000}" --log-level=WARNING
  # shellcheck disable=SC2086  # SANITIZE_TARGETS is a list
  stage sanitize "asan build" nice -n 5 cmake --build $build -j"$jobs" ${SANITIZE_TARGETS:+--target $SANITIZE_TARGETS}
  # Leaks fail a test (a process exits non-zero at its end); suppressions name third-party libraries only.
  export ASAN_OPTIONS="detect_leaks=1:halt_on_error=1:detect_stack_use_after_return=0:strict_init_order=1:${ASAN_OPTIONS:-}"
  export LSAN_OPTIONS="suppressions=$supp/lsan.supp:print_suppressions=0:${LSAN_OPTIONS:-}"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:${UBSAN_OPTIONS:-}"
  if [[ $# -gt 0 ]]; then
    stage sanitize "asan ctest $*" ctest --test-dir $build --output-on-failure -j"$jobs" "$@"
    exit
  fi
  # Excluded under ASan:
  #  lint.ClangFormat: checks sources, not code; it runs in the normal build.
  #  label sim and supervision.KillEach...: they render with Mesa's uninstrumented llvmpipe (see above).
  #  load.*: four CNN detectors at 30 fps measure throughput and latency, which an ASan build does not have.
  #  accuracy_guard, box_relation_guard: they measure the shipped model (the normal build runs them) and render their sets
  #  with Mesa's uninstrumented llvmpipe, as the sim label does. track_guard: it measures the shipped model and tracker
  #  over 2400 video frames (the normal build runs it), minutes of detector time under ASan.
  #  Replay.LockstepReplayThroughLiveProcesses...: it starts the OpenCL detector ten times and gives each frame 10 s;
  #  under ASan each run's start-up and first inference take most of that (275 s in all, and one frame not settled
  #  in 10 s on a loaded machine). The normal build runs it; under ASan the same processes run in
  #  Replay.CameraDriverFileToFile..., ProcessFileIo.*, DetectorProcess.* and demo.*. TSan leaves it out too.
  rc=0
  stage sanitize "asan suite" ctest --test-dir $build --output-on-failure -j"$jobs" --timeout 1800 -LE '^(fuzz|sim)$' \
    -E '^lint\.|^load\.|^supervision\.KillEach|^accuracy_guard$|^box_relation_guard$|^track_guard$|^Replay\.LockstepReplayThroughLiveProcesses' || rc=$?
  stage sanitize "asan fuzz" ctest --test-dir $build --output-on-failure -j"$jobs" -L '^fuzz$' || rc=$?
  exit $rc
fi

build=build-tsan
# The multi-process tests (processes talk over LCM in private network namespaces) and the tests whose code uses
# threads: only `wingman bench` starts threads of its own (tools/src/bench.cpp); LCM's receive thread, OpenCV's
# and PoCL's workers run inside every process.
# The recorder runs a writer thread of its own (recorder/), and the real-time detector a worker thread (Runtime::wake()
# hands its results back): their tests run here too.
TSAN_TESTS='^(Runtime|ProcessConfig|ProcessFileIo|ProcessSignals|Replay|LocalizerProcess|FollowerProcess|DetectorProcess|DetectorRealtime|RecorderTest|RecorderProcess)\.|^recorder\.|^demo\.|^sim_flight\.'
tsan_targets=(wingman-camera-driver wingman-detector wingman-localizer wingman-follower-ctrl wingman-recorder wingman
  test_process_runtime test_replay test_localizer_process test_detector_process test_detector_realtime
  test_follower_process test_recorder test_recorder_process test_recorder_disk_full test_common)
stage sanitize "tsan configure" cmake -S . -B $build "${common_cmake[@]}" -DWINGMAN_SANITIZE=thread -DWINGMAN_WITH_SIM=OFF \
  --log-level=WARNING
if [[ -n ${SANITIZE_TARGETS:-} ]]; then
  # shellcheck disable=SC2086  # a list
  stage sanitize "tsan build" nice -n 5 cmake --build $build -j"$jobs" --target $SANITIZE_TARGETS
elif [[ $# -gt 0 ]]; then
  stage sanitize "tsan build" nice -n 5 cmake --build $build -j"$jobs"
else
  stage sanitize "tsan build" nice -n 5 cmake --build $build -j"$jobs" --target "${tsan_targets[@]}" \
    $(grep -q 'WINGMAN_WITH_SIM:BOOL=ON' $build/CMakeCache.txt && echo wingman-sim)
fi
# A race fails the process (exit 66) and so its test; suppressions name third-party libraries only.
export TSAN_OPTIONS="halt_on_error=0:exitcode=66:second_deadlock_stack=1:suppressions=$supp/tsan.supp:${TSAN_OPTIONS:-}"
if [[ $# -gt 0 ]]; then
  stage sanitize "tsan ctest $*" ctest --test-dir $build --output-on-failure -j"$jobs" "$@"
  exit
fi
# Left out under TSan: the lockstep replay through live processes starts the OpenCL detector ten times (each start
# waited for up to 90 s), and under TSan the detector's start-up (model load, kernel build) is many times longer.
stage sanitize "tsan multi-process tests" ctest --test-dir $build --output-on-failure -j"$jobs" --timeout 1800 -R "$TSAN_TESTS" \
  -E '^Replay\.LockstepReplayThroughLiveProcesses'
