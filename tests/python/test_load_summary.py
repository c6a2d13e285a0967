#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""tools/load_summary.py (the figures and checks of tools/load_test.sh and tools/soak.sh) on small logs written here
with wingman_lcm.LogWriter and the generated types, without running the pipeline: every figure of the three modes
(realtime, replay, soak) against the values the logs were built with, the failed checks and exit codes, a log cut
inside its last event, a bad sync word, and the message when the generated types cannot be imported. The logs are
left in a temporary folder when a check fails.
Usage: test_load_summary.py LOAD_SUMMARY_PY   (PYTHONPATH: build/python)"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

import wingman
from wingman_lcm import LogWriter

script = sys.argv[1]
failures = []
T0 = 1767225600000000  # the first heartbeat, microseconds
CAM = {0: dict(published=300, received=290, dropped=100, processed=198),  # 2 unaccounted, 10 lost on the bus
       1: dict(published=300, received=300, dropped=0, processed=299)}  # 1 unaccounted (the frame in hand)
TARGETS_N = 400  # targets_t the fusing localizer published (of the 497 detections_t it heard)


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def run(*args, env=None):
    return subprocess.run([sys.executable, script, *args], capture_output=True, text=True, timeout=120, env=env)


def status(process, utime, state, channels, p50, p99):
    m = wingman.status_t()
    m.utime, m.process, m.pid, m.state, m.detail = utime, process, 1000, state, ""
    m.uptime_us, m.messages_handled = utime - T0 + 1_000_000, 1
    m.latency_p50_ms, m.latency_p90_ms, m.latency_p99_ms, m.latency_max_ms = p50, p50, p99, p99
    m.last_error = ""
    for name, direction, count, drops in channels:
        c = wingman.channel_stats_t()
        c.channel, c.direction, c.count, c.drops, c.rate_hz = name, direction, count, drops, 30.0
        m.channels.append(c)
    m.num_channels = len(m.channels)
    return m.encode()


def detections(utime, seq, camera_id, inference_us):
    m = wingman.detections_t()
    m.utime, m.seq, m.camera_id, m.image_width, m.image_height = utime, seq, camera_id, 1280, 720
    m.inference_latency_us, m.model_id = inference_us, "builtin:wingman-small"
    d = wingman.detection_t()
    m.detections, m.num_detections = [d], 1
    return m.encode()


def image(utime, seq, camera_id):
    m = wingman.image_t()
    m.utime, m.seq, m.camera_id, m.width, m.height, m.stride = utime, seq, camera_id, 1280, 720, 3840
    m.pixel_format, m.data = wingman.image_t.BGR8, bytes(720 * 3840)
    m.size = len(m.data)
    return m.encode()


def write_flight(path, final=True, seconds=20, per_camera_targets=False):
    """Two camera chains over `seconds` s: a heartbeat per process per second (counts growing linearly to CAM's,
    then STOPPING with the final counts unless final is False for camera 1), and the detections: detector i's k-th
    arrives at T0 + 0.5 s + k * (seconds - 1) / n s, 100 ms + (k % 10) ms after its image's utime (plus 100 ms in
    the second half for camera 1), inference 20 + k % 5 ms. The one localizer fusing them (it hears every
    detections_t) publishes TARGETS_N targets_t, logged 50 ms after their exposure, which the follower all hears; an
    image beside them."""
    events = []
    for i, c in CAM.items():
        n = c["processed"]
        for k in range(n):
            recv = T0 + 500_000 + k * (seconds - 1) * 1_000_000 // n
            e2e = 100_000 + (k % 10) * 1000 + (100_000 if i == 1 and k >= n // 2 else 0)
            events.append((recv, f"DETECTIONS_CAM{i}", detections(recv - e2e, k, i, 20_000 + (k % 5) * 1000)))
        for s in range(seconds + 1):
            last = s == seconds
            f = 1.0 if last else s / seconds
            state = 4 if last and (final or i == 0) else 1
            cam_ch = [(f"IMAGE_CAM{i}", 1, round(c["published"] * f), 0)]
            det_ch = [(f"IMAGE_CAM{i}", 0, round(c["received"] * f), round(c["dropped"] * f)),
                      (f"DETECTIONS_CAM{i}", 1, round(c["processed"] * f), 0)]
            u = T0 + s * 1_000_000
            p99 = 40.0 + s  # grows: first vs last third differ
            events.append((u + 1, f"STATUS_camera_{i}", status(f"camera_{i}", u, state, cam_ch, 1.5, 3.0)))
            events.append((u + 2, f"STATUS_detector_{i}", status(f"detector_{i}", u, state, det_ch, 25.0 + i, p99)))
    # The one localizer fusing the cameras (every detections_t heard) into TARGETS_N targets_t, and the follower on
    # them; each targets_t is logged 50 ms after its exposure.
    for s in range(seconds + 1):
        f = 1.0 if s == seconds else s / seconds
        state = 4 if s == seconds else 1
        u = T0 + s * 1_000_000
        loc_ch = [(f"DETECTIONS_CAM{i}", 0, round(c["processed"] * f), 0) for i, c in CAM.items()]
        loc_ch.append(("TARGETS", 1, round(TARGETS_N * f), 0))
        events.append((u + 3, "STATUS_localizer", status("localizer", u, state, loc_ch, 0.5, 1.0)))
        events.append((u + 4, "STATUS_follower_ctrl",
                       status("follower_ctrl", u, state, [("TARGETS", 0, round(TARGETS_N * f), 0)], 0.1, 0.2)))
    for k in range(TARGETS_N):
        t = wingman.targets_t()
        t.utime = T0 + 500_000 + k * (seconds - 1) * 1_000_000 // TARGETS_N
        events.append((t.utime + 50_000, "TARGETS", t.encode()))
    if per_camera_targets:  # a localizer per camera, as before the rig: not one fused stream
        events.append((T0 + 5, "TARGETS_CAM0", wingman.targets_t().encode()))
    events.append((T0 + 4, "IMAGE_CAM0", image(T0, 0, 0)))  # skipped by realtime (not a status or detections)
    events.sort(key=lambda e: e[0])
    with LogWriter(path) as log:
        for recv, channel, data in events:
            log.write(channel, data, recv)


def write_proc_csv(path, seconds=20):
    with open(path, "w") as f:
        f.write("t_s,process,rss_kib,cpu_s\n")
        for t in range(seconds + 1):
            for p, base, growth in (("camera_0", 50_000, 0), ("detector_0", 200_000, 700)):
                f.write(f"{t},{p},{base + growth * t},{0.5 * t if p == 'camera_0' else 0.9 * t}\n")


def lines_with(out, prefix):
    return [line for line in out.splitlines() if line.startswith(prefix)]


work = tempfile.mkdtemp(prefix="wingman_load_summary_")
flight, proc = os.path.join(work, "flight.lcmlog"), os.path.join(work, "processes.csv")
write_flight(flight)
write_proc_csv(proc)

# --- realtime: the accounting table, latencies, heartbeat and CPU.
js = os.path.join(work, "realtime.json")
r = run("realtime", flight, "--cameras", "2", "--proc-csv", proc, "--udp-rcvbuf-errors", "12", "--json", js)
print(r.stdout + r.stderr)
check(r.returncode == 0, f"realtime: a passing log exits 0 (got {r.returncode})")
check(lines_with(r.stdout, "       0 ") == [
    "       0        300       290        198      100            2                 10      14.3      9.43",
    "       0    198      104      108      109      109   22/24"],
    "realtime: camera 0's accounting (300 published, 290 received, 198 processed, 100 dropped, 2 unaccounted, "
    "10 lost, 21 s uptime) and latencies (p50/p90/p99/max 104/108/109/109 ms, inference 22/24 ms)")
check(lines_with(r.stdout, "       1 ") == [
    "       1        300       300        299        0            1                  0      14.3     14.24",
    "       1    299      200      208      209      209   22/24"],
    "realtime: camera 1's accounting and latencies (+100 ms in the second half)")
check("load: 10 frames and 0 detections_t or targets_t lost on the bus in all; the kernel dropped 12 datagrams on "
      "full socket receive buffers in this namespace (every socket on the bus receives every image)" in r.stdout,
      "realtime: the bus-loss line")
check("load: the localizer fused 497 detections_t into 400 targets_t on TARGETS (400 in the log; 97 detections_t went "
      "into no targets_t of their own: late for their exposure, or waiting at the stop); the follower received 400"
      in r.stdout and "fused latency = arrival of TARGETS at lcm-logger minus targets_t.utime (its exposure's capture "
      "time): p50 50 ms, p99 50 ms" in r.stdout, "realtime: the fusing localizer's line and its latency")
check("load: end-to-end p50/p99 first half 104/109 ms, second half 201/209 ms" in r.stdout,
      "realtime: end-to-end p50/p99 per half")
check("  detector_0       p50    25.00 ms  p99    59.00 ms  CPU   90 %  (the detection's time, on its worker thread)"
      in r.stdout and "  camera_0         p50     1.50 ms  p99     3.00 ms  CPU   50 %" in r.stdout
      and "  camera_1         p50     1.50 ms  p99     3.00 ms  CPU    - %" in r.stdout,
      "realtime: heartbeat latency from the last heartbeat before STOPPING, CPU from the samples")
with open(js) as f:
    j = json.load(f)
check(j["failures"] == [] and j["lost_in_transport"] == 10 and j["end_to_end_s"]["n"] == 497
      and abs(j["end_to_end_s"]["50"] - 0.107) < 1e-9 and abs(j["inference_s"]["99"] - 0.024) < 1e-9
      and [c["unaccounted"] for c in j["cameras"]] == [2, 1]
      and [c["final_status"] for c in j["cameras"]] == [True, True],
      "realtime: --json holds the same figures")

# --- realtime failures: no final status of camera 1, lost frames without kernel drops, a low p99 bound.
bad = os.path.join(work, "no_final.lcmlog")
write_flight(bad, final=False)
r = run("realtime", bad, "--cameras", "2", "--udp-rcvbuf-errors", "0", "--max-p99-s", "0.15")
print(r.stdout + r.stderr)
check(r.returncode == 1 and lines_with(r.stdout, "load_summary: FAILED: ") == [
    "load_summary: FAILED: camera 1: camera_1 or detector_1 published no final STOPPING status",
    "load_summary: FAILED: 10 frames and 0 detections_t or targets_t lost on the bus without any kernel receive-buffer "
    "drop",
    "load_summary: FAILED: end-to-end p99 0.21 s above the bound 0.15 s"],
    "realtime: failed checks are one line each, exit 1")
check("  (no final STOPPING status)" in lines_with(r.stdout, "       1 ")[0], "realtime: the table marks it")
per_camera = os.path.join(work, "per_camera_targets.lcmlog")
write_flight(per_camera, per_camera_targets=True)
r = run("realtime", per_camera, "--cameras", "2", "--udp-rcvbuf-errors", "12")
check(r.returncode == 1 and lines_with(r.stdout, "load_summary: FAILED: ") == [
    "load_summary: FAILED: targets channels in the log: ['TARGETS', 'TARGETS_CAM0']; expected one fused stream, "
    "TARGETS"], "realtime: a targets channel beside the fused TARGETS fails, named")
r = run("realtime", bad, "--cameras", "2", "--udp-rcvbuf-errors", "0", "--max-p99-s", "0.15", "--report-only")
check(r.returncode == 1 and "load_summary: beyond the bound (reported only): end-to-end p99 0.21 s above the bound "
      "0.15 s" in r.stdout and len(lines_with(r.stdout, "load_summary: FAILED: ")) == 2,
      "realtime --report-only: the p99 bound reported, the accounting checks still fail")
r = run("realtime", flight, "--cameras", "3")
check(r.returncode == 1 and "load_summary: FAILED: camera 2: no status from camera_2 or detector_2" in r.stdout,
      "realtime: a camera without statuses fails")

# --- a log cut inside its last event reads up to it; a bad sync word is one line, exit 1.
with open(flight, "rb") as f:
    whole = f.read()
r_whole = run("realtime", flight, "--cameras", "2")
for what, tail in (("inside its last event's data", whole[:40]), ("inside its last event's header", whole[:10])):
    cut = os.path.join(work, "cut.lcmlog")
    with open(cut, "wb") as f:
        f.write(whole + tail)
    r = run("realtime", cut, "--cameras", "2")
    check(r.returncode == r_whole.returncode == 0 and r.stderr == "" and r.stdout == r_whole.stdout,
          f"a log cut {what}: the figures of the whole events, exit 0")
corrupt = os.path.join(work, "corrupt.lcmlog")
first_len = 28 + int.from_bytes(whole[20:24], "big") + int.from_bytes(whole[24:28], "big")
with open(corrupt, "wb") as f:
    f.write(whole[:first_len] + b"\0\0\0\0" + whole[first_len + 4:])
r = run("realtime", corrupt, "--cameras", "2")
check(r.returncode == 1 and r.stderr.strip() == f"load_summary: {corrupt}: not an LCM log (bad sync word at byte "
      f"{first_len})", f"a bad sync word: one line naming the byte, exit 1 (got {r.returncode}: {r.stderr.strip()})")
r = run("realtime", os.path.join(work, "absent.lcmlog"), "--cameras", "2")
check(r.returncode == 1 and r.stderr.startswith("load_summary: cannot read "), "an absent log: one line, exit 1")

# --- replay: every image with its detections; then one lost, one duplicated, one with another utime.
images, det0, det1 = (os.path.join(work, n) for n in ("images.lcmlog", "det0.lcmlog", "det1.lcmlog"))
with LogWriter(images) as log:
    for i in range(2):
        for k in range(3):
            log.write(f"IMAGE_CAM{i}", image(T0 + k * 33_333, k, i), T0 + k)
for path, cam in ((det0, 0), (det1, 1)):
    with LogWriter(path) as log:
        for k in range(3):
            log.write(f"DETECTIONS_CAM{cam}", detections(T0 + k * 33_333, k, cam, 20_000), T0 + k)
            log.write(f"STATUS_detector_{cam}", status(f"detector_{cam}", T0, 1, [], 1.0, 2.0), T0 + k)
js = os.path.join(work, "replay.json")
r = run("replay", images, det0, det1, "--json", js)
print(r.stdout + r.stderr)
check(r.returncode == 0 and r.stdout.splitlines() == [
    "replay: camera  images  with detections",
    "             0       3                3",
    "             1       3                3",
    "replay: 6 images in, 6 with their detections_t, 0 lost, 0 duplicated, 0 unexpected, 0 with a wrong utime"],
    "replay: 6 images (1280x720 BGR), each with its detections, exit 0")
with open(js) as f:
    check(json.load(f) == {"images": 6, "lost": 0, "duplicated": 0, "unexpected": 0,
                           "per_camera": {"0": {"images": 3, "with_detections": 3},
                                          "1": {"images": 3, "with_detections": 3}}, "failures": []},
          "replay: --json")
with LogWriter(det1) as log:
    log.write("DETECTIONS_CAM1", detections(T0, 0, 1, 20_000), T0)
    log.write("DETECTIONS_CAM1", detections(T0 + 1, 1, 1, 20_000), T0)  # another utime
    log.write("DETECTIONS_CAM1", detections(T0, 0, 1, 20_000), T0)  # duplicated; seq 2 lost
r = run("replay", images, det0, det1)
print(r.stdout + r.stderr)
check(r.returncode == 1 and r.stdout.splitlines()[-4:] == [
    "replay: 6 images in, 5 with their detections_t, 1 lost, 1 duplicated, 0 unexpected, 1 with a wrong utime",
    "load_summary: FAILED: 1 images without detections (camera, seq): [(1, 2)]",
    "load_summary: FAILED: 1 duplicated detections (camera, seq): [(1, 0)]",
    "load_summary: FAILED: 1 detections with another utime (camera, seq): [(1, 1)]"],
    "replay: a lost, a duplicated and a wrongly dated detection fail, exit 1")

# --- soak: RSS growth per process, the latency trend.
js = os.path.join(work, "soak.json")
r = run("soak", flight, "--proc-csv", proc, "--warmup-s", "2", "--max-rss-growth-pct", "5", "--json", js)
print(r.stdout + r.stderr)
check(r.returncode == 0 and "  camera_0                        48.8      48.8       0.00              48.8      50"
      in r.stdout and "  detector_0                     200.1     209.0       4.44             209.0      90"
      in r.stdout and "  detector_0         heartbeat p50    25.00 ->    25.00 ms   p99    43.00 ->    56.00 ms"
      in r.stdout and "  end-to-end         p50      104 ->      201 ms   p99      109 ->      209 ms" in r.stdout
      and lines_with(r.stdout, "load_summary: FAILED: ") == [],
      "soak: RSS envelope growth (4.4 % under 5 %), heartbeat and end-to-end trend, exit 0")
with open(js) as f:
    j = json.load(f)
check(abs(j["rss"]["detector_0"]["growth_pct"] - 100.0 * (214000 - 204900) / 204900) < 1e-9
      and j["latency"]["detector_1"]["last_p99_ms"] == 56.0, "soak: --json")
r = run("soak", flight, "--proc-csv", proc, "--warmup-s", "2", "--max-rss-growth-pct", "4")
check(r.returncode == 1 and lines_with(r.stdout, "load_summary: FAILED: ") == [
    "load_summary: FAILED: detector_0: RSS grew 4.4 % after the warm-up (peak 204900 -> 214000 KiB), above 4.0 %"],
    "soak: RSS growth above the bound fails, exit 1")

# --- without the generated types: one line naming them, exit 2 (only where python3 does not find them unaided).
env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
if subprocess.run([sys.executable, "-c", "import wingman, wingman_lcm"], env=env, capture_output=True).returncode:
    r = run("--help", env=env)
    check(r.returncode == 2 and r.stdout == "" and r.stderr.startswith(
        "tools/load_summary.py: the generated Python types are missing (No module named 'wingman'): build the "
        "project (they are in build/python) and set PYTHONPATH=build/python"),
        f"without PYTHONPATH: the missing types named, exit 2 (got {r.returncode}: {r.stderr.strip()})")
else:
    print("skip the missing-types check: python3 finds wingman without PYTHONPATH (installed to /usr)")

print(f"test_load_summary: {len(failures)} failed (logs in {work})" if failures else "test_load_summary: all passed")
if not failures:
    shutil.rmtree(work)
sys.exit(1 if failures else 0)
