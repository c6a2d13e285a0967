# SPDX-License-Identifier: MIT
"""Scores detector boxes on an imported Halmstad folder (`wingman import-halmstad --distractor-classes`: labels class 0
drone, 1 airplane, 2 bird, 3 helicopter; splits.csv gives each clip's distance bin) by the centre-in-box rule: a box
finds an object when its centre lies in the object's labelled box (each box finds at most one object, the most
confident boxes first). Prints one markdown table per threshold: the share of each kind of object found, and the boxes
that found nothing, per image; for a COCO detector also which COCO label its box on each kind of object had.
CenterNet's output is its 100 best (place, class) pairs, often several labels at one place: its boxes first go through
class-agnostic non-maximum suppression (--nms-iou, 0.4 as @vladmandic/human applies it), after the threshold.

With both, --bird-veto S,... adds rows for the shipped model's boxes without those whose centre lies in a CenterNet box
labelled bird scoring at least S (after the suppression): what COCO's bird label would take away, drones and birds.

Usage: score.py --data DIR [--split train] [--coco PROBE.json] [--wingman PREDICT_DIR] [--thresholds 0.1,0.2,0.3]
                [--nms-iou 0.4] [--bird-veto 0.3,0.4]
  --coco: probe.mjs's output (boxes in image pixels, COCO class indices 0..79);
  --wingman: `wingman predict --out` (one <stem>.txt per image: class cx cy w h confidence, normalised).
"""
import argparse
import collections
import functools
import json
import os
import sys

COCO = ['person', 'bicycle', 'car', 'motorcycle', 'airplane', 'bus', 'train', 'truck', 'boat', 'traffic light',
        'fire hydrant', 'stop sign', 'parking meter', 'bench', 'bird', 'cat', 'dog', 'horse', 'sheep', 'cow',
        'elephant', 'bear', 'zebra', 'giraffe', 'backpack', 'umbrella', 'handbag', 'tie', 'suitcase', 'frisbee', 'skis',
        'snowboard', 'sports ball', 'kite', 'baseball bat', 'baseball glove', 'skateboard', 'surfboard', 'tennis racket',
        'bottle', 'wine glass', 'cup', 'fork', 'knife', 'spoon', 'bowl', 'banana', 'apple', 'sandwich', 'orange',
        'broccoli', 'carrot', 'hot dog', 'pizza', 'donut', 'cake', 'chair', 'couch', 'potted plant', 'bed',
        'dining table', 'toilet', 'tv', 'laptop', 'mouse', 'remote', 'keyboard', 'cell phone', 'microwave', 'oven',
        'toaster', 'sink', 'refrigerator', 'book', 'clock', 'vase', 'scissors', 'teddy bear', 'hair drier', 'toothbrush']
KINDS = {0: 'drone', 1: 'airplane', 2: 'bird', 3: 'helicopter'}
# The table's columns: drones by the clip's distance bin, the distractors by kind.
COLUMNS = [('drone', 'CLOSE'), ('drone', 'MEDIUM'), ('drone', 'DISTANT'), ('airplane', ''), ('bird', ''),
           ('helicopter', '')]
FLYING = {'airplane', 'bird', 'kite'}  # the COCO labels a flying object gets


class ScoreError(Exception):
    pass


@functools.lru_cache(maxsize=None)  # score() runs once per set and threshold over the same files
def read_splits(data):
    """clip -> distance bin, from splits.csv (clip,class,distance_bin,split,images)."""
    path = os.path.join(data, 'splits.csv')
    try:
        rows = open(path).read().splitlines()
    except OSError as e:
        raise ScoreError(f'{path}: cannot read ({e.strerror})')
    if not rows or rows[0].split(',')[:3] != ['clip', 'class', 'distance_bin']:
        raise ScoreError(f'{path}: expected the header clip,class,distance_bin,...')
    return {r.split(',')[0]: r.split(',')[2] for r in rows[1:] if r}


@functools.lru_cache(maxsize=None)
def read_truths(path, width, height):
    """((kind, x1, y1, x2, y2), ...) in pixels from a YOLO label file (absent: none)."""
    out = []
    if not os.path.exists(path):
        return ()
    for n, line in enumerate(open(path).read().splitlines(), 1):
        f = line.split()
        if not f:
            continue
        if len(f) < 5 or int(f[0]) not in KINDS:
            raise ScoreError(f'{path}:{n}: expected "class cx cy w h" with class 0..3')
        cx, cy, w, h = float(f[1]) * width, float(f[2]) * height, float(f[3]) * width, float(f[4]) * height
        out.append((KINDS[int(f[0])], cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2))
    return tuple(out)


def read_coco(path):
    """image -> (width, height, [(cx, cy, score, label, x1, y1, x2, y2)])."""
    try:
        d = json.load(open(path))
    except (OSError, ValueError) as e:
        raise ScoreError(f'{path}: not a probe.mjs JSON ({e})')
    out = {}
    for im in d.get('images', []):
        boxes = []
        for b in im['boxes']:
            c = int(b['cls'])
            boxes.append(((b['x1'] + b['x2']) / 2, (b['y1'] + b['y2']) / 2, b['score'],
                          COCO[c] if 0 <= c < len(COCO) else f'class {c}', b['x1'], b['y1'], b['x2'], b['y2']))
        out[im['image']] = (im['width'], im['height'], boxes)
    return out


def read_wingman(folder, images, width=640, height=512):
    """image -> (width, height, [(cx, cy, score, 'drone' | 'class N', x1, y1, x2, y2)]) from `wingman predict`."""
    out = {}
    for image in images:
        path = os.path.join(folder, os.path.splitext(image)[0] + '.txt')
        boxes = []
        if os.path.exists(path):
            for n, line in enumerate(open(path).read().splitlines(), 1):
                f = line.split()
                if not f:
                    continue
                if len(f) < 6:
                    raise ScoreError(f'{path}:{n}: expected "class cx cy w h confidence"')
                cx, cy, w, h = float(f[1]) * width, float(f[2]) * height, float(f[3]) * width, float(f[4]) * height
                boxes.append((cx, cy, float(f[5]), 'drone' if f[0] == '0' else f'class {f[0]}',
                              cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2))
        out[image] = (width, height, boxes)
    return out


def iou(a, b):
    """Intersection over union of two (..., x1, y1, x2, y2) boxes (their last four fields)."""
    ax1, ay1, ax2, ay2 = a[-4:]
    bx1, by1, bx2, by2 = b[-4:]
    inter = max(0.0, min(ax2, bx2) - max(ax1, bx1)) * max(0.0, min(ay2, by2) - max(ay1, by1))
    union = (ax2 - ax1) * (ay2 - ay1) + (bx2 - bx1) * (by2 - by1) - inter
    return inter / union if union > 0 else 0.0


def suppress(boxes, nms_iou):
    """Greedy class-agnostic non-maximum suppression: the most confident box first; boxes sorted by score."""
    kept = []
    for b in sorted(boxes, key=lambda b: -b[2]):
        if all(iou(b, k) <= nms_iou for k in kept):
            kept.append(b)
    return kept


def bird_veto(wingman, coco, min_score, nms_iou):
    """wingman's detections without the boxes centred in a CenterNet 'bird' box scoring >= min_score."""
    out = {}
    for image, (w, h, boxes) in wingman.items():
        coco_boxes = suppress([b for b in coco.get(image, (0, 0, []))[2] if b[2] >= min_score], nms_iou)
        birds = [c for c in coco_boxes if c[3] == 'bird']
        out[image] = (w, h, [b for b in boxes
                             if not any(c[4] <= b[0] <= c[6] and c[5] <= b[1] <= c[7] for c in birds)])
    return out


def score(data, split, detections, threshold, labels=None, nms_iou=None):
    """Found and total objects per column, the label of the box that found each kind, boxes on nothing per image.
    labels: only boxes with these labels count (None: all); nms_iou: suppress overlaps above it first (None: no)."""
    bins = read_splits(data)
    found, total = collections.Counter(), collections.Counter()
    label_of = collections.defaultdict(collections.Counter)
    on_nothing = 0
    for image, (w, h, boxes) in sorted(detections.items()):
        clip = image[:image.rfind('_')]
        truths = read_truths(os.path.join(data, 'labels', split, os.path.splitext(image)[0] + '.txt'), w, h)
        boxes = sorted((b for b in boxes if b[2] >= threshold and (labels is None or b[3] in labels)),
                       key=lambda b: -b[2])
        if nms_iou is not None:
            boxes = suppress(boxes, nms_iou)
        used = set()
        for kind, x1, y1, x2, y2 in truths:
            column = (kind, bins.get(clip, '?') if kind == 'drone' else '')
            total[column] += 1
            for i, b in enumerate(boxes):
                if i not in used and x1 <= b[0] <= x2 and y1 <= b[1] <= y2:
                    used.add(i)
                    found[column] += 1
                    label_of[kind][b[3]] += 1
                    break
        on_nothing += len(boxes) - len(used)
    return found, total, label_of, on_nothing / max(len(detections), 1)


def table(rows):
    """rows: (name, threshold, found, total, on_nothing per image)."""
    head = ['boxes', 'threshold'] + [f'{k} {b}'.strip() for k, b in COLUMNS] + ['boxes on nothing per image']
    lines = ['| ' + ' | '.join(head) + ' |', '|' + '---|' * len(head)]
    for name, t, found, total, nothing in rows:
        cells = [f'{found[c] / total[c]:.2f} ({found[c]}/{total[c]})' if total[c] else '—' for c in COLUMNS]
        lines.append(f'| {name} | {t:g} | ' + ' | '.join(cells) + f' | {nothing:.2f} |')
    return '\n'.join(lines)


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    p.add_argument('--data', required=True)
    p.add_argument('--split', default='train')
    p.add_argument('--coco')
    p.add_argument('--wingman')
    p.add_argument('--thresholds', default='0.1,0.2,0.3')
    p.add_argument('--nms-iou', type=float, default=0.4)
    p.add_argument('--bird-veto', default='')
    a = p.parse_args(argv)
    thresholds = [float(t) for t in a.thresholds.split(',')]
    image_dir = os.path.join(a.data, 'images', a.split)
    try:
        images = sorted(f for f in os.listdir(image_dir) if f.lower().endswith('.jpg'))
    except OSError as e:
        raise ScoreError(f'{image_dir}: cannot list ({e.strerror})')
    sets = []
    if a.coco:
        coco = read_coco(a.coco)
        sets += [('MB3-CenterNet (COCO), any label', coco, None, a.nms_iou),
                 ('MB3-CenterNet (COCO), airplane/bird/kite', coco, FLYING, a.nms_iou)]
    if a.wingman:
        wingman = read_wingman(a.wingman, images)
        sets.append(('wingman-small, drone boxes', wingman, {'drone'}, None))
        if a.coco:
            for v in (float(x) for x in a.bird_veto.split(',') if x):
                sets.append((f'wingman-small, drone boxes not in a CenterNet bird box >= {v:g}',
                             bird_veto(wingman, coco, v, a.nms_iou), {'drone'}, None))
    if not sets:
        raise ScoreError('nothing to score: give --coco and/or --wingman')
    rows = []
    for name, dets, labels, nms_iou in sets:
        for t in thresholds:
            found, total, _, nothing = score(a.data, a.split, dets, t, labels, nms_iou)
            rows.append((name, t, found, total, nothing))
    print(table(rows))
    if a.coco:
        t = thresholds[0]
        _, _, label_of, _ = score(a.data, a.split, coco, t, None, a.nms_iou)
        print(f'\nThe COCO label of the box that found each kind of object (threshold {t:g}):\n')
        for kind in ('drone', 'airplane', 'bird', 'helicopter'):
            c = label_of.get(kind)
            if c:
                n = sum(c.values())
                print(f'- {kind} ({n}): ' + ', '.join(f'{label} {v / n:.0%}' for label, v in c.most_common(5)))
    return 0


if __name__ == '__main__':
    try:
        sys.exit(main(sys.argv[1:]))
    except ScoreError as e:
        print(f'score.py: {e}', file=sys.stderr)
        sys.exit(1)
