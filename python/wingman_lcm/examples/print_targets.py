# SPDX-License-Identifier: MIT
"""Prints each target on TARGETS: track id and world position.
Usage: python3 -m wingman_lcm.examples.print_targets [URL [MESSAGES [SECONDS]]]  (URL "": $LCM_DEFAULT_URL)"""
import sys

import wingman
from wingman_lcm import Udpm

url, count, seconds = (sys.argv[1:] + ["", "10", "10"][len(sys.argv) - 1:])[:3]
with Udpm(url) as bus:
    bus.subscribe("TARGETS")
    for msg in bus.messages(max_messages=int(count), timeout_s=float(seconds)):
        targets = wingman.targets_t.decode(msg.data)
        for t in targets.targets:
            x, y, z = t.p_target_in_world
            print("utime %d track %d world (%.2f, %.2f, %.2f) m" % (targets.utime, t.track_id, x, y, z))
