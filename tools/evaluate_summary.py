#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""tools/evaluate_model.sh's summary: OUT/summary.md from the wingman val --json files in OUT (the metrics per set,
the negative clips' and the synthetic distractors' false positives, the truths not found and the track-level table);
printed too.

Usage: evaluate_summary.py OUT FLIGHTS SEQUENCES (FLIGHTS, SEQUENCES: true or false: whether OUT has
flights_val.json and halmstad_sequences.json)."""
import json, os, sys
out = sys.argv[1]
sets = [("halmstad_val", "Halmstad val clips (all)"), ("halmstad_val_DRONE", "Halmstad val, drone clips"),
        ("synth_val", "synthetic val (960x540, as trained)"), ("synth720_val", "synthetic 1280x720, <= 30 m"),
        ("followview_val", "follower's view, 1280x720, horizon, 4-20 m")]
if sys.argv[2] == "true":
    sets.append(("flights_val", "held-out training flight, 1280x720, 3-30 m"))
def load(n):
    return json.load(open(os.path.join(out, n + ".json")))
def recall_at_precision(c, p_min):
    return max([r for r, p, _ in c["pr_curve"] if p >= p_min] or [0.0])
lines = ["| set | images | truths | criterion | AP@0.5 | precision / recall at conf 0.2 | recall at precision >= 0.90 | mean IoU |",
         "|---|---|---|---|---|---|---|---|"]
for name, label in sets:
    r = load(name)
    for crit in ("iou", "centre"):
        a = r[crit]["all"]
        lines.append(f"| {label} | {r['images']} | {r['truths']} | {'IoU >= 0.5' if crit == 'iou' else 'centre in box'} | "
                     f"{a['ap']:.3f} | {a['precision']:.3f} / {a['recall']:.3f} | {recall_at_precision(r[crit], 0.9):.3f} | "
                     f"{a['mean_iou']:.3f} |")
lines += ["", "| negative clips (Halmstad val) | images | false positives at conf 0.2 | per image |", "|---|---|---|---|"]
for kind in ("AIRPLANE", "BIRD", "HELICOPTER"):
    r = load("halmstad_val_" + kind)
    fp = r["centre"]["all"]["false_positives"]
    lines.append(f"| {kind.lower()} | {r['images']} | {fp} | {fp / max(1, r['images']):.3f} |")
if os.path.exists(os.path.join(out, "distractors_AIRPLANE.json")):
    lines += ["", "| synthetic distractors, no drone (config/datasets/distractors.yaml, seed 61) | images | "
              "false positives at conf 0.2 | per image |", "|---|---|---|---|"]
    for kind in ("AIRPLANE", "BIRD", "HELICOPTER"):
        r = load("distractors_" + kind)
        fp = r["centre"]["all"]["false_positives"]
        lines.append(f"| {kind.lower()} | {r['images']} | {fp} | {fp / max(1, r['images']):.3f} |")
lines += ["", "| set | criterion | truths not found at conf 0.2 | missed (no box overlaps) | loose (overlapped, not matched) | "
          "at the image's edge (of the truths there) |", "|---|---|---|---|---|---|"]
for name, label in sets:
    r = load(name)
    for crit in ("iou", "centre"):
        u = r[crit]["unmatched"]
        missed = sum(1 for x in u if x["reason"] == "missed")
        edge = sum(1 for x in u if x["at_edge"])
        lines.append(f"| {label} | {'IoU >= 0.5' if crit == 'iou' else 'centre in box'} | {len(u)} of {r['truths']} | "
                     f"{missed} | {len(u) - missed} | {edge} of {r[crit]['edge_truths']} |")
if sys.argv[3] == "true":
    r = load("halmstad_sequences")
    step = "every frame" if r["frame_step"] == 1 else f"every {r['frame_step']}th frame"
    within = f"{r['confirm_within_s']:g} s"
    lines += ["", f"Track-level (Halmstad val clips, {step}, detector + wingman-localizer tracker, pinhole HFOV "
              f"{r['hfov_deg']:.0f} deg): targets <= 1 false track per hour of distractor video, >= 95 % of drone clips "
              f"confirmed within {within}", "",
              f"| clips | n | video h | false tracks | per hour (95 % upper) | drone confirmed | within {within} | "
              "median time to confirm | drone track ids |", "|---|---|---|---|---|---|---|---|---|"]
    for g in r["groups"]:
        row = f"| {g['name']} | {g['clips']} | {g['hours']:.4f} | {g['false_tracks']} | " \
              f"{g['false_tracks_per_hour']:.1f} ({g['false_tracks_per_hour_upper95']:.1f}) |"
        if g["drone"]:
            med = g["median_time_to_confirm_s"]
            row += f" {g['confirmed']}/{g['clips']} | {g['confirmed_within']}/{g['clips']} | " \
                   f"{'-' if med is None else f'{med:.2f} s'} | {g['drone_tracks']} |"
        else:
            row += " | | | |"
        lines.append(row)
open(os.path.join(out, "summary.md"), "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
