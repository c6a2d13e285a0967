#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs Wingman's build and test dependencies from Debian 12's archive, only what is missing.
# Called by the README's two commands; safe to run again (does nothing when all is present).
set -euo pipefail

# One list, grouped by what needs it. Later components append here.
packages=(
  # build
  build-essential cmake pkg-config ninja-build clang-format
  # LCM (C/C++ library, lcm-gen and tools, Java classes for lcm-spy and the tcpq hub)
  liblcm-dev liblcm-bin liblcm-java libjchart2d-java libglib2.0-dev default-jdk-headless
  # vision, maths, OpenCL (PoCL on the CPU), V4L2
  libopencv-dev libeigen3-dev pocl-opencl-icd ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers
  clinfo libv4l-dev
  # simulator (WINGMAN_WITH_SIM): offscreen OpenGL through EGL on Mesa llvmpipe, mesh loading
  libegl-dev libgles-dev libgl1-mesa-dri libassimp-dev
  # trainer (WINGMAN_WITH_TRAINING): libtorch on the CPU
  libtorch-dev
  # configuration, CLI, logging
  libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev
  # JSON reading and writing (the tools' and the metrics' JSON documents)
  nlohmann-json3-dev
  # SHA-256 of a model's weights (detections_t.model_id, the box relation's model check)
  libssl-dev
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
  # private network namespaces for multi-process tests and the demo (unshare, ip)
  util-linux iproute2
  # lcm-spy screenshot check under a virtual X server
  xvfb xauth x11-apps netpbm
  # `wingman report` opened in a headless browser (tests/tools/report_chromium_test.sh)
  chromium
  # reliability (docs/reliability.md): supervisord for the supervision fault tests, clang for libFuzzer targets and
  # the AddressSanitizer/UndefinedBehaviorSanitizer/ThreadSanitizer builds
  supervisor clang
  # `systemd-analyze verify` of the shipped systemd units (nothing is started)
  systemd
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# The MAVLink codec's cross-check (tests/mavlink): node and npm from Debian, unless another install provides them,
# and the npm packages it checks against (node-mavlink, pinned by tests/mavlink/node/package-lock.json). Without them
# ctest mavlink.NodeCrosscheck skips; a failing `npm ci` (no registry) is reported, not fatal.
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  missing+=(nodejs npm)
fi
npm_project="$(cd "$(dirname "$0")/.." && pwd)/tests/mavlink/node"
install_npm_packages() {
  if [ -d "$npm_project/node_modules/node-mavlink" ] || ! command -v npm >/dev/null 2>&1; then return 0; fi
  echo "install_deps: npm ci in $npm_project (node-mavlink, for the MAVLink codec's cross-check)" >&2
  (cd "$npm_project" && npm ci --no-audit --no-fund --loglevel=error) ||
    echo "install_deps: npm ci failed: ctest mavlink.NodeCrosscheck will skip" >&2
}

if [ ${#missing[@]} -eq 0 ]; then
  install_npm_packages
  exit 0
fi

echo "install_deps: installing ${#missing[@]} missing Debian packages: ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "install_deps: need root (or sudo) to install: ${missing[*]}" >&2; exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
install_npm_packages
