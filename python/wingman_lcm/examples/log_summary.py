# SPDX-License-Identifier: MIT
"""Per channel of an LCM log: message type, count, first and last utime of the decoded messages.
Usage: python3 -m wingman_lcm.examples.log_summary LOG"""
import sys

from wingman_lcm import decode, read_log

summary = {}  # channel -> [type, count, first utime, last utime]
for event in read_log(sys.argv[1]):
    msg = decode(event.data)
    row = summary.setdefault(event.channel, [type(msg).__name__, 0, msg.utime, msg.utime])
    row[1] += 1
    row[3] = msg.utime
for channel, (type_name, count, first, last) in summary.items():
    print("%-20s %-16s %7d %d %d" % (channel, type_name, count, first, last))
