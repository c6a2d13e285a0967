#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Runs a command in a private network namespace whose loopback carries LCM multicast, so nothing
# is ever sent on the host's network. Usage: tools/netns_run.sh COMMAND [ARGS...]
# Inside, use udpm URLs with ttl=0 and recv_buf_size (see WINGMAN_LCM_URL, exported for the command).
set -euo pipefail
if [ "${WINGMAN_IN_NETNS:-}" != "1" ]; then
  exec unshare --user --map-root-user --net -- env WINGMAN_IN_NETNS=1 "$0" "$@"
fi
ip link set lo up
ip link set lo multicast on
ip route add 224.0.0.0/4 dev lo
# LCM 1.3.1 does not raise SO_RCVBUF on Linux; without recv_buf_size large images are lost.
export WINGMAN_LCM_URL="${WINGMAN_LCM_URL:-udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304}"
export LCM_DEFAULT_URL="$WINGMAN_LCM_URL"
exec "$@"
