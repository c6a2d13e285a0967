#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""wingman_lcm.Udpm against LCM C++ peers on a udpm bus, inside tools/netns_run.sh's private network namespace:
C++ publishes (small and 2.7 MB fragmented messages) -> Python subscribes; `wingman replay` -> Python; malformed and
foreign datagrams are dropped and counted; Python publishes (LC02, LC03, the size at the switch) -> C++ records.
Usage: tools/netns_run.sh test_udpm.py BUS_PEER WINGMAN PUBLISH_SAMPLES"""
import os
import random
import select
import struct
import subprocess
import sys
import tempfile
import time

import wingman
from wingman_lcm import Udpm, decode, read_log
from wingman_lcm.udpm import MAGIC_LONG, MAGIC_SHORT, SHORT_MESSAGE_MAX_SIZE

if os.environ.get("WINGMAN_IN_NETNS") != "1":
    sys.exit("test_udpm.py: run me through tools/netns_run.sh (multicast only in a private network namespace)")
peer_exe, wingman_exe, samples_exe = sys.argv[1:4]
url = os.environ["WINGMAN_LCM_URL"]
work = tempfile.mkdtemp(prefix="wingman_python_udpm_")
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def events(path):
    return [(e.channel, e.data) for e in read_log(path)]


# 1. C++ publisher (lcm::LCM) -> Python: 3 rounds of TARGETS, a 1280x720 image (fragmented), OWN_POSE.
sent_log = os.path.join(work, "cpp_sent.lcmlog")
with Udpm(url) as bus:
    bus.subscribe(".*")
    check(bus.recv_buf_size >= 4 << 20, "receive buffer %d bytes (a 2.7 MB image fits)" % bus.recv_buf_size)
    peer = subprocess.Popen([peer_exe, "publish", url, sent_log, "3", "150"])
    got = [(m.channel, m.data) for m in bus.messages(max_messages=9, timeout_s=20)]
    check(peer.wait(timeout=30) == 0, "C++ publisher exits 0")
    sent = events(sent_log)
    check(len(sent) == 9 and got == sent, "the 9 messages C++ published arrive, in order, byte for byte (%d received)"
          % len(got))
    images = [decode(d) for c, d in got if c == "IMAGE_CAM0"]
    check(len(images) == 3 and all((i.width, i.height, i.size, len(i.data)) == (1280, 720, 2764800, 2764800)
                                   for i in images), "three 1280x720 images decode, 2764800 bytes each")
    targets = [wingman.targets_t.decode(d) for c, d in got if c == "TARGETS"]
    check([[t.track_id for t in m.targets] for m in targets] == [[1, 2], [11, 12], [21, 22]]
          and targets[2].targets[1].p_target_in_world == (2.5, 14.0, 10.25),
          "targets_t fields as C++ set them (track ids, world position)")
    check(bus.stats["fragmented_messages"] == 3 and bus.dropped == 0, "3 fragmented messages, none dropped: %s"
          % bus.stats)

# 2. `wingman replay` (C++) of a log -> Python: every message but STATUS_* (replay's default). Replay also listens,
#    so LCM's self test (channel LCM_SELF_TEST) is on the bus too: not subscribed here.
samples = os.path.join(work, "samples.lcmlog")
subprocess.run([samples_exe, "--log", samples, "--repeat", "4"], check=True, timeout=60)
expected = [(c, d) for c, d in events(samples) if not c.startswith("STATUS_")]
with Udpm(url) as bus:
    bus.subscribe("(?!LCM_SELF_TEST$).*")
    replay = subprocess.Popen([wingman_exe, "replay", "--lcm-url", url, "--speed", "0", samples],
                              stdout=subprocess.DEVNULL)
    got = [(m.channel, m.data) for m in bus.messages(max_messages=len(expected), timeout_s=20)]
    check(replay.wait(timeout=30) == 0, "wingman replay exits 0")
    check(got == expected, "wingman replay's %d messages arrive byte for byte (%d received)" % (len(expected), len(got)))
    check(sorted({type(decode(d)).__name__ for _, d in got}) == ["detections_t", "ground_truth_t", "image_t",
                                                                 "own_pose_t", "setpoint_t", "targets_t"],
          "each decodes by its fingerprint")

# 3. Malformed and foreign datagrams: dropped and counted, the bus goes on.
with Udpm(url, fragment_timeout_s=0.3) as bus, Udpm(url) as sender:
    bus.subscribe("TARGETS|JUNK")
    sender.publish("TARGETS", b"")  # opens the send socket
    raw = sender._send
    dest = (bus.group, bus.port)
    long_header = struct.Struct(">IIIIHH")
    junk = [
        (b"xy", "foreign"),  # shorter than any header
        (b"GARBAGE!garbage", "foreign"),  # not LCM's magic
        (struct.pack(">II", MAGIC_SHORT, 1) + b"A" * 80, "malformed"),  # channel without NUL
        (struct.pack(">II", MAGIC_SHORT, 2) + b"\0data", "malformed"),  # empty channel
        (struct.pack(">IIII", MAGIC_LONG, 3, 10, 0), "malformed"),  # cut long header
        (long_header.pack(MAGIC_LONG, 4, 10, 8, 1, 2) + b"abcdef", "malformed"),  # fragment past the message
        (long_header.pack(MAGIC_LONG, 5, 10, 0, 2, 2) + b"ab", "malformed"),  # fragment number >= count
        (long_header.pack(MAGIC_LONG, 6, 1 << 30, 0, 0, 3) + b"JUNK\0abc", "malformed"),  # too large
        (long_header.pack(MAGIC_LONG, 7, 100, 0, 0, 3) + b"JUNK\0" + b"x" * 40, "incomplete"),  # never finished
    ]
    for packet, _ in junk:
        raw.sendto(packet, dest)
    before = bus.receive(0.5)  # the empty TARGETS sent first
    check(bus.receive(0.2) is None, "the junk makes no message")
    time.sleep(0.5)  # the unfinished message goes stale
    good = wingman.targets_t()
    good.utime = 42
    sender.publish("TARGETS", good.encode())
    msg = bus.receive(5)
    check(before is not None and before.data == b"", "the message before the junk arrives")
    check(msg is not None and wingman.targets_t.decode(msg.data).utime == 42, "a message after the junk arrives")
    want = {k: sum(1 for _, w in junk if w == k) for k in ("foreign", "malformed", "incomplete")}
    got = {k: bus.stats["dropped_" + k] for k in want}
    check(got == want, "dropped and counted: %s (expected %s)" % (got, want))

# 3b. Random datagrams, most with LCM's magic numbers (no network: straight into the parser): none raises.
rng = random.Random(34)
fuzz = Udpm(url)
fuzz.subscribe(".*")
for n in range(3000):
    head = rng.choice([b"", struct.pack(">I", MAGIC_SHORT), struct.pack(">I", MAGIC_LONG),
                       long_header.pack(MAGIC_LONG, rng.randrange(4), rng.randrange(200), rng.randrange(200),
                                        rng.randrange(3), rng.randrange(4))])
    body = bytes(rng.randrange(256) if rng.random() < 0.7 else 0 for _ in range(rng.randrange(120)))
    fuzz._handle_packet(head + body, ("10.0.0.%d" % rng.randrange(3), 7667))
fuzz.close()
s = fuzz.stats
check(s["packets"] == 3000 and s["dropped_foreign"] + s["dropped_malformed"] > 0,
      "3000 random datagrams parsed without an exception: %s" % s)

# 4. Python publisher -> C++ subscriber (lcm::LCM records what it receives): LC02, the largest LC02, the smallest LC03,
#    a 1280x720 image (43 fragments), all byte for byte.
def image(size):
    i = wingman.image_t()
    i.utime, i.seq, i.width, i.height, i.stride, i.pixel_format = 7, 1, size, 1, size, wingman.image_t.GRAY8
    i.data = bytes((k * 13) & 0xFF for k in range(size))
    i.size = size
    return i.encode()


overhead = len(image(0))
small_max = SHORT_MESSAGE_MAX_SIZE - len("IMAGE_CAM0") - 1 - overhead  # image size of the largest one-datagram message
big = wingman.image_t()
big.utime, big.width, big.height, big.stride, big.pixel_format = 9, 1280, 720, 3840, wingman.image_t.BGR8
big.data = bytes(range(256)) * (2764800 // 256)
big.size = len(big.data)
t = wingman.targets_t()
t.utime, t.num_targets = 5, 1
t.targets = [wingman.target_t()]
t.targets[0].track_id = 3
to_send = [("TARGETS", t.encode()), ("IMAGE_CAM0", image(small_max)), ("IMAGE_CAM0", image(small_max + 1)),
           ("IMAGE_CAM0", big.encode())]
recorded = os.path.join(work, "cpp_recorded.lcmlog")
peer = subprocess.Popen([peer_exe, "record", url, recorded, str(len(to_send)), "20"], stdout=subprocess.PIPE, text=True)
ready = select.select([peer.stdout], [], [], 10)[0] and peer.stdout.readline().strip() == "ready"
check(bool(ready), "C++ recorder subscribed")
with Udpm(url) as bus, Udpm(url) as listener:
    listener.subscribe("TARGETS|IMAGE_CAM0")
    for channel, data in to_send:
        bus.publish(channel, data)
        time.sleep(0.05)
    heard = [(m.channel, m.data) for m in listener.messages(max_messages=len(to_send), timeout_s=10)]
    check(heard == to_send and listener.stats["fragmented_messages"] == 2,
          "a Python subscriber hears them too, the largest one-datagram message whole, the next size and the image "
          "in fragments: %s" % listener.stats)
check(peer.wait(timeout=30) == 0, "C++ recorder got %d messages" % len(to_send))
check(events(recorded) == to_send, "C++ received what Python published, byte for byte (sizes %s)"
      % [len(d) for _, d in to_send])

subprocess.run(["rm", "-rf", work])
if failures:
    print("%d check(s) failed" % len(failures))
    sys.exit(1)
print("all checks passed")
