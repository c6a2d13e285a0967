#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""wingman_lcm's log reader against logs the C++ code writes (lcm::LogFile through wingman-publish-samples and
wingman-write-report-flight), and against corrupt copies of them. Compared with `wingman loginfo`.
Usage: test_log.py matches|corrupt WINGMAN PUBLISH_SAMPLES WRITE_REPORT_FLIGHT"""
import collections
import os
import re
import subprocess
import sys
import tempfile

import wingman_lcm
from wingman_lcm import LogFormatError, LogWriter, decode, read_log

mode, wingman_exe, samples_exe, flight_exe = sys.argv[1:5]
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def run(*cmd):
    return subprocess.run(cmd, capture_output=True, text=True, timeout=60)


def loginfo_table(path):
    """{channel: (type, count, bytes, bad)} from `wingman loginfo`."""
    out = run(wingman_exe, "loginfo", path)
    assert out.returncode == 0, out.stderr
    table = {}
    for line in out.stdout.splitlines()[1:]:
        m = re.match(r"^(\S+)\s+(\S+)\s+(\d+)\s+(\d+)\s+\S+\s+(\d+)$", line)
        if not m:
            break  # the status part
        table[m[1]] = (m[2], int(m[3]), int(m[4]), int(m[5]))
    return table, out.stdout


def python_table(path):
    counts = collections.OrderedDict()
    for ev in read_log(path):
        try:
            type_name, bad = type(decode(ev.data)).__name__, 0
        except Exception:  # noqa: BLE001 -- a message that does not decode is counted, as loginfo does
            type_name, bad = "?", 1
        t, n, b, nbad = counts.get(ev.channel, (type_name, 0, 0, 0))
        counts[ev.channel] = (t if t != "?" else type_name, n + 1, b + len(ev.data), nbad + bad)
    return dict(counts)


work = tempfile.mkdtemp(prefix="wingman_python_log_")
samples, flight = os.path.join(work, "samples.lcmlog"), os.path.join(work, "flight.lcmlog")
assert run(samples_exe, "--log", samples, "--repeat", "5").returncode == 0
assert run(flight_exe, flight).returncode == 0

if mode == "matches":
    for path in (samples, flight):
        expected, text = loginfo_table(path)
        got = python_table(path)
        check(len(expected) >= 4, "%s: loginfo lists %d channels" % (os.path.basename(path), len(expected)))
        check(got == expected, "%s: per channel type, count, bytes and bad the same as loginfo's (%d channels, %d events)%s"
              % (os.path.basename(path), len(got), sum(r[1] for r in got.values()),
                 "" if got == expected else ": python %s, loginfo %s" % (got, expected)))
        # Event numbers, timestamps and bytes survive LogWriter: loginfo reads the copy the same.
        copy = path + ".copy"
        with LogWriter(copy) as log:
            for ev in read_log(path):
                log.write(ev.channel, ev.data, ev.timestamp)
        check(loginfo_table(copy)[1] == text, "%s: a LogWriter copy reads the same in loginfo" % os.path.basename(path))
        check([(e.channel, e.data) for e in read_log(copy)] == [(e.channel, e.data) for e in read_log(path)],
              "%s: the copy has the same events" % os.path.basename(path))
    img = next(decode(e.data) for e in read_log(flight) if e.channel == "IMAGE_CAM0")
    check(img.width * img.height > 0 and len(img.data) == img.size == img.stride * img.height,
          "flight image decodes: %dx%d, %d bytes" % (img.width, img.height, len(img.data)))
    # One class per lcmtypes/*.lcm file (this file sits in tests/python/ of the source tree).
    lcm_files = [f for f in os.listdir(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "lcmtypes"))
                 if f.endswith(".lcm")]
    check(len(wingman_lcm.message_classes()) == len(lcm_files),
          "%d message classes by fingerprint, one per lcmtypes/*.lcm" % len(wingman_lcm.message_classes()))
elif mode == "corrupt":
    events = list(read_log(flight))
    third, fifth = events[2].offset, events[4].offset
    data = open(flight, "rb").read()
    cases = {
        # name: (bytes, offset that must be named, words in the message)
        "truncated data": (data[:fifth + 28 + len(events[4].channel) + 3], fifth, "truncated event"),
        "truncated header": (data[:fifth + 10], fifth, "truncated event: header has 10 of 28"),
        "bad sync": (data[:third] + b"\x00\x00\x00\x00" + data[third + 4:], third, "bad sync word 0x00000000"),
    }
    for name, (content, offset, words) in cases.items():
        path = os.path.join(work, name.replace(" ", "_") + ".lcmlog")
        with open(path, "wb") as f:
            f.write(content)
        seen = []
        try:
            for ev in read_log(path):
                seen.append(ev)
            err = None
        except LogFormatError as e:
            err = e
        check(err is not None, "%s: LogFormatError" % name)
        if err is None:
            continue
        message = str(err)
        check("\n" not in message and message.startswith("%s: byte %d: " % (path, offset)) and words in message,
              "%s: one line naming the file and byte %d: %s" % (name, offset, message))
        check(err.offset == offset and err.path == path, "%s: .path and .offset" % name)
        check(len(seen) == (4 if offset == fifth else 2), "%s: the %d events before it were read" % (name, len(seen)))
        cpp = run(wingman_exe, "loginfo", path)
        check(cpp.returncode != 0 and str(offset) in cpp.stderr,
              "%s: wingman loginfo fails at the same offset: %s" % (name, cpp.stderr.strip()))
        example = subprocess.run([sys.executable, "-m", "wingman_lcm.examples.log_summary", path],
                                 capture_output=True, text=True, timeout=60)
        check(example.returncode != 0 and example.stderr.strip().splitlines()[-1].endswith(message),
              "%s: the log_summary example stops with that error" % name)
else:
    sys.exit("usage: test_log.py matches|corrupt WINGMAN PUBLISH_SAMPLES WRITE_REPORT_FLIGHT")

subprocess.run(["rm", "-rf", work])
if failures:
    print("%d check(s) failed" % len(failures))
    sys.exit(1)
print("all checks passed")
