#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes scenario files for training flights: a hovering camera vehicle and one leader that flies seeded random
waypoints in front of it (3-30 m, mostly near the camera's height, turning to random headings), seen the way a
follower sees its leader. The flights are recorded with tools/fly.sh (--detections truth --render --record-images)
and turned into a labelled dataset with `wingman dataset from-log` (tools/train_model.sh, stage 3).

They are not the evaluation flights: config/scenarios/*.yaml fly fixed paths with their own seeds; these draw the
camera height and heading, the leader's path, speed, heading and (for one flight in four) its airframe's colours and
size from --seed, and use scene seeds from 1000 up.

Usage: tools/make_training_flights.py --out DIR [--count N] [--seed S] [--duration S]
"""
import argparse
import math
import os
import random
import sys


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True, help="folder for train_flight_NN.yaml (created)")
    ap.add_argument("--count", type=int, default=6, help="number of flights (default 6)")
    ap.add_argument("--seed", type=int, default=1, help="seed (default 1): the same seed writes the same files")
    ap.add_argument("--duration", type=float, default=60.0, help="simulated seconds per flight (default 60)")
    a = ap.parse_args()
    if a.count < 1:
        print(f"make_training_flights: --count {a.count}: must be >= 1", file=sys.stderr)
        return 2
    if not a.duration > 0:
        print(f"make_training_flights: --duration {a.duration}: must be > 0", file=sys.stderr)
        return 2
    os.makedirs(a.out, exist_ok=True)
    for k in range(a.count):
        rng = random.Random(a.seed * 1000 + k)
        height = rng.uniform(2.5, 25.0)
        yaw = rng.uniform(0.0, 360.0)
        c, s = math.cos(math.radians(yaw)), math.sin(math.radians(yaw))

        def ahead(rng_, near, far, max_az_deg, max_el_deg):
            r = math.exp(rng_.uniform(math.log(near), math.log(far)))
            az = math.radians(rng_.uniform(-max_az_deg, max_az_deg))
            el = math.radians(rng_.uniform(-max_el_deg, max_el_deg)) if rng_.random() < 0.3 else \
                math.radians(rng_.uniform(-2.0, 2.0))
            fwd, left, up = r * math.cos(el) * math.cos(az), r * math.cos(el) * math.sin(az), r * math.sin(el)
            x, y = fwd * c - left * s, fwd * s + left * c
            return [round(x, 2), round(y, 2), round(max(1.0, height + up), 2)]

        start = ahead(rng, 4.0, 12.0, 20.0, 0.0)
        waypoints = []
        for _ in range(24):
            waypoints.append({"position": ahead(rng, 3.0, 30.0, 38.0, 12.0),
                              "speed": round(rng.uniform(0.5, 3.0), 2),
                              "stop_s": round(rng.choice([0.0, 0.0, 1.0, 3.0]), 1),
                              "yaw_deg": round(rng.uniform(-180.0, 180.0), 1)})
        drone = []
        if k % 4 == 3:  # other colours and sizes now and then; the flights' F450-like quad otherwise
            colour = lambda: "[" + ", ".join(f"{rng.uniform(0.05, 0.95):.2f}" for _ in range(3)) + "]"
            drone = ["    drone:",
                     f"      frame: {rng.choice(['quad', 'quad', 'hex'])}",
                     f"      arm_length_m: {rng.uniform(0.18, 0.4):.3f}",
                     f"      body_colour: {colour()}",
                     f"      front_arm_colour: {colour()}",
                     f"      rear_arm_colour: {colour()}"]
        lines = [
            "# Written by tools/make_training_flights.py: a training flight (not an evaluation scenario).",
            f"name: train_flight_{k:02d}",
            f"description: \"training flight {k} (seed {a.seed}): camera hovering at {height:.1f} m, leader on random"
            " waypoints 3-30 m ahead\"",
            "start_utime: 1767225600000000",
            f"duration_s: {a.duration:g}",
            "command_delay_s: 0.1",
            f"seed: {1000 + a.seed * 100 + k}",
            "",
            "vehicles:",
            "  - name: camera",
            "    id: 0",
            "    control: script",
            "    initial:",
            f"      position: [0, 0, {height:.2f}]",
            f"      yaw_deg: {yaw:.1f}",
            "",
            "  - name: leader",
            "    id: 1",
            "    control: script",
            "    initial:",
            f"      position: [{start[0]}, {start[1]}, {start[2]}]",
            f"      yaw_deg: {rng.uniform(-180.0, 180.0):.1f}",
            *drone,
            "    dynamics:",
            "      max_speed_xy: 3.0",
            "      max_accel_xy: 2.0",
            "    motion:",
            "      type: waypoints",
            "      accel: 1.0",
            "      loop: true",
            "      waypoints:",
        ]
        for w in waypoints:
            lines.append(f"        - {{position: [{w['position'][0]}, {w['position'][1]}, {w['position'][2]}], "
                         f"speed: {w['speed']}, stop_s: {w['stop_s']}, yaw_deg: {w['yaw_deg']}}}")
        path = os.path.join(a.out, f"train_flight_{k:02d}.yaml")
        with open(path, "w") as f:
            f.write("\n".join(lines) + "\n")
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
