#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Installs what is missing (Debian packages) and builds Wingman into build/ (RelWithDebInfo, -j2).
# Used by both README commands. Extra arguments go to CMake's configure step.
set -euo pipefail
cd "$(dirname "$0")/.."
export PYENV_VERSION=system
tools/install_deps.sh
if [ ! -f build/CMakeCache.txt ] || [ $# -gt 0 ]; then
  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "$@"
fi
cmake --build build -j2
