#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Fails when a C++ source of the project differs from .clang-format's layout (fix: clang-format -i FILE).
set -euo pipefail
cd "$1"
mapfile -t files < <(find common camera_driver detector localizer follower_ctrl mavlink mavlink_bridge sim tools tests training \
  -name '*.cpp' -o -name '*.hpp' | sort)
[ ${#files[@]} -gt 0 ] || { echo "check_format: no sources found under $1" >&2; exit 1; }
if ! clang-format --dry-run -Werror "${files[@]}"; then
  echo "check_format: run 'clang-format -i' on the files above" >&2
  exit 1
fi
echo "check_format: ${#files[@]} files formatted"
