#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The config fuzz target's seeds (corpus/config/): each shipped process configuration with fuzz_config.cpp's selector
# byte in front, so the fuzzer starts from every key the processes read today.
# Usage: tests/fuzz/config_seeds.sh --check|--write
#   --check  exit 1 naming each seed that is not its config file as shipped (ctest fuzz_seeds.ConfigSeedsAreShipped)
#   --write  rewrite those seeds from config/
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
mode="${1:-}"
case "$mode" in --check|--write) ;; *) echo "usage: $0 --check|--write" >&2; exit 2 ;; esac

# seed file : selector byte (fuzz_config.cpp: data[0] % 6) : config file
seeds=(
  "camera_driver.yaml:0:config/camera_driver.yaml"
  "detector.yaml:1:config/detector.yaml"
  "localizer.yaml:2:config/localizer.yaml"
  "follower_ctrl.yaml:3:config/follower_ctrl.yaml"
  "flight_follow_1d.follower_ctrl.yaml:3:config/flights/follow_1d.follower_ctrl.yaml"
  "sim.yaml:4:config/sim.yaml"
  "mavlink_bridge.yaml:5:config/mavlink_bridge.yaml"
)
stale=0
for entry in "${seeds[@]}"; do
  IFS=: read -r seed selector config <<<"$entry"
  seed_path="$root/tests/fuzz/corpus/config/$seed"
  [ -f "$root/$config" ] || { echo "config_seeds: $config: missing (named for seed $seed)" >&2; exit 2; }
  want="$(mktemp)"
  printf "\\$(printf '%03o' "$selector")" >"$want"
  cat "$root/$config" >>"$want"
  if ! cmp -s "$want" "$seed_path"; then
    if [ "$mode" = --write ]; then
      cp "$want" "$seed_path"
      echo "config_seeds: wrote tests/fuzz/corpus/config/$seed from $config"
    else
      echo "config_seeds: tests/fuzz/corpus/config/$seed is not selector byte $selector + $config as shipped" \
        "(run tests/fuzz/config_seeds.sh --write)" >&2
      stale=1
    fi
  fi
  rm -f "$want"
done
[ "$stale" = 0 ] && [ "$mode" = --check ] && echo "config_seeds: ${#seeds[@]} seeds are the shipped configs"
exit "$stale"
