#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""tools/pretrained_probe/score.py (tools/probe_pretrained.sh's tables) on a hand-made imported folder: two frames of
a DISTANT drone clip and one of a bird clip, CenterNet boxes in probe.mjs's JSON and wingman-small's in `wingman
predict`'s labels, every figure against the values worked out by hand (centre in box, most confident box first, one
object a box); bad input is one error naming the file.
Usage: test_pretrained_score.py SCORE_PY"""
import json
import os
import subprocess
import sys
import tempfile

script = sys.argv[1]
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def run(*args):
    return subprocess.run([sys.executable, script, *args], capture_output=True, text=True, timeout=60)


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, 'w') as f:
        f.write(text)


with tempfile.TemporaryDirectory() as d:
    data = os.path.join(d, 'data')
    write(os.path.join(data, 'splits.csv'),
          'clip,class,distance_bin,split,images\nV_DRONE_001,DRONE,DISTANT,val,2\nV_BIRD_001,BIRD,CLOSE,val,1\n')
    for image in ('V_DRONE_001_0000', 'V_DRONE_001_0020', 'V_BIRD_001_0000'):
        write(os.path.join(data, 'images', 'train', image + '.jpg'), '')
    # 640 x 512: the drone's box 100..140 x 100..120 in both frames; the bird's 300..320 x 200..210.
    drone = '0 0.1875 0.21484375 0.0625 0.0390625\n'
    write(os.path.join(data, 'labels', 'train', 'V_DRONE_001_0000.txt'), drone)
    write(os.path.join(data, 'labels', 'train', 'V_DRONE_001_0020.txt'), drone)
    write(os.path.join(data, 'labels', 'train', 'V_BIRD_001_0000.txt'), '2 0.484375 0.400390625 0.03125 0.01953125\n')
    coco = {'images': [
        # Frame 0: an airplane box (0.4) and a kite box (0.3) on the drone (IoU 0.68: non-maximum suppression at 0.4
        # keeps the airplane box, which finds it; without it the kite box is on nothing); a person box (0.5) on the
        # ground is on nothing.
        {'image': 'V_DRONE_001_0000.jpg', 'width': 640, 'height': 512, 'boxes': [
            {'x1': 110, 'y1': 105, 'x2': 130, 'y2': 115, 'score': 0.4, 'cls': 4},
            {'x1': 112, 'y1': 106, 'x2': 132, 'y2': 116, 'score': 0.3, 'cls': 33},
            {'x1': 400, 'y1': 450, 'x2': 420, 'y2': 480, 'score': 0.5, 'cls': 0}]},
        # Frame 20: a bird box of 0.15 on the drone (found at 0.1 only).
        {'image': 'V_DRONE_001_0020.jpg', 'width': 640, 'height': 512, 'boxes': [
            {'x1': 115, 'y1': 105, 'x2': 125, 'y2': 115, 'score': 0.15, 'cls': 14}]},
        # The bird: a bird box of 0.6 whose centre (330, 205) is outside its box, then one of 0.2 inside.
        {'image': 'V_BIRD_001_0000.jpg', 'width': 640, 'height': 512, 'boxes': [
            {'x1': 320, 'y1': 200, 'x2': 340, 'y2': 210, 'score': 0.6, 'cls': 14},
            {'x1': 305, 'y1': 202, 'x2': 315, 'y2': 208, 'score': 0.2, 'cls': 14}]}]}
    write(os.path.join(d, 'coco.json'), json.dumps(coco))
    # wingman-small: a drone box of 0.7 on the drone in frame 0, none in frame 20, a drone box of 0.25 on the bird.
    pred = os.path.join(d, 'pred')
    write(os.path.join(pred, 'V_DRONE_001_0000.txt'), '0 0.1875 0.21484375 0.05 0.03 0.7\n')
    write(os.path.join(pred, 'V_BIRD_001_0000.txt'), '0 0.484375 0.400390625 0.03 0.02 0.25\n')

    def table(*args):
        r = run('--data', data, '--coco', os.path.join(d, 'coco.json'), '--wingman', pred, '--thresholds', '0.1,0.3',
                *args)
        check(r.returncode == 0, f'exit 0 (got {r.returncode}: {r.stderr.strip()})')
        rows = {tuple(c.strip() for c in line.split('|')[1:3]): [c.strip() for c in line.split('|')[3:-1]]
                for line in r.stdout.splitlines() if line.startswith('| ') and not line.startswith('| boxes')}
        return r, rows

    # Columns: drone CLOSE, MEDIUM, DISTANT, airplane, bird, helicopter, boxes on nothing per image.
    r, rows = table()
    _, raw = table('--nms-iou', '1')
    CN, FLY, WS = 'MB3-CenterNet (COCO), any label', 'MB3-CenterNet (COCO), airplane/bird/kite', 'wingman-small, drone boxes'
    expected = [  # (table, row, threshold, cells, why)
        (rows, CN, '0.1', ['—', '—', '1.00 (2/2)', '—', '1.00 (1/1)', '—', '0.67'],
         'CenterNet, any label: both drone frames and the bird found; the person and the bird box outside its bird on '
         'nothing: 2 in 3 images'),
        (rows, CN, '0.3', ['—', '—', '0.50 (1/2)', '—', '0.00 (0/1)', '—', '0.67'], 'CenterNet, any label: frame 0 only'),
        (rows, FLY, '0.3', ['—', '—', '0.50 (1/2)', '—', '0.00 (0/1)', '—', '0.33'],
         'CenterNet, flying labels: the person box left out'),
        (raw, CN, '0.1', ['—', '—', '1.00 (2/2)', '—', '1.00 (1/1)', '—', '1.00'],
         'without suppression the kite box on the found drone is on nothing too'),
        (rows, WS, '0.1', ['—', '—', '0.50 (1/2)', '—', '1.00 (1/1)', '—', '0.00'],
         'wingman-small: the drone in frame 0, a drone box on the bird'),
        (rows, WS, '0.3', ['—', '—', '0.50 (1/2)', '—', '0.00 (0/1)', '—', '0.00'], 'wingman-small'),
    ]
    for got_rows, row, threshold, cells, why in expected:
        got = got_rows.get((row, threshold))
        check(got == cells, f'{why}, threshold {threshold} ({got})')
    ws01 = rows.get((WS, '0.1'))
    check('- drone (2): airplane 50%, bird 50%' in r.stdout, 'the labels that found the drone at 0.1')
    # The bird veto: CenterNet's bird box of 0.2 holds the centre of wingman-small's box on the bird; its 0.15 bird box
    # in drone frame 20 holds no wingman-small box.
    _, veto = table('--bird-veto', '0.2,0.7')
    v02 = veto.get(('wingman-small, drone boxes not in a CenterNet bird box >= 0.2', '0.1'))
    check(v02 == ['—', '—', '0.50 (1/2)', '—', '0.00 (0/1)', '—', '0.00'],
          f'a bird box of 0.2 takes wingman-small\'s box off the bird ({v02})')
    v07 = veto.get(('wingman-small, drone boxes not in a CenterNet bird box >= 0.7', '0.1'))
    check(v07 == ws01, f'no bird box reaches 0.7: the rows without the veto ({v07})')
    check('- bird (1): bird 100%' in r.stdout, 'the label that found the bird')

    # Bad input: one line naming the file.
    write(os.path.join(pred, 'V_DRONE_001_0020.txt'), '0 0.5 0.5\n')
    r = run('--data', data, '--wingman', pred)
    check(r.returncode == 1 and 'V_DRONE_001_0020.txt:1: expected "class cx cy w h confidence"' in r.stderr,
          f'a short label line is named with its file and line ({r.returncode}: {r.stderr.strip()})')
    r = run('--data', os.path.join(d, 'nowhere'), '--wingman', pred)
    check(r.returncode == 1 and 'nowhere' in r.stderr, f'a missing folder is named ({r.stderr.strip()})')
    write(os.path.join(d, 'bad.json'), '{')
    r = run('--data', data, '--coco', os.path.join(d, 'bad.json'))
    check(r.returncode == 1 and 'bad.json: not a probe.mjs JSON' in r.stderr, f'a bad JSON is named ({r.stderr.strip()})')

print(f'{len(failures)} failure(s)')
sys.exit(1 if failures else 0)
