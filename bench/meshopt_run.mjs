// meshopt_run.mjs -- meshoptimizer's simplifier on the full-grid TIN of a
// DEM, for bench/decimate_peers.sh.
//
//   node bench/meshopt_run.mjs --meshopt PATH/index.js --raw DEM.raw \
//        --info DEM.info.json --vertices N --out TIN.geojsonl
//
// The full-grid TIN: one vertex per sample at (column, row, z) and two
// triangles per cell. MeshoptSimplifier.simplify() collapses edges until
// the target triangle count (scaled to leave about N vertices) is reached,
// with the border locked
// (a terrain's outline must stay) and a target error of 1 (relative: no
// error limit, the count decides). Its vertices stay samples (it collapses
// onto existing vertices). The triangles are written as GeoJSON text
// sequence in the DEM's map coordinates (sample (c, r) at the pixel centre,
// as terratin puts it), for `terratin eval`. Prints one JSON object:
// vertices and triangles kept, meshoptimizer's own error, seconds.
import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const args = {};
const argv = process.argv.slice(2);
for (let i = 0; i + 1 < argv.length; i += 2) args[argv[i].replace(/^--/, '')] = argv[i + 1];
for (const k of ['meshopt', 'raw', 'info', 'vertices', 'out'])
  if (!(k in args)) throw new Error(`missing --${k}`);

const mod = await import(pathToFileURL(path.resolve(args.meshopt)).href);
const S = mod.MeshoptSimplifier;
await S.ready;
const info = JSON.parse(fs.readFileSync(args.info, 'utf8'));
const [w, h] = info.size;
const gt = info.geoTransform;
const buf = fs.readFileSync(args.raw);
const z = new Float32Array(buf.buffer.slice(buf.byteOffset, buf.byteOffset + w * h * 4));

const pos = new Float32Array(3 * w * h);
for (let r = 0; r < h; r++)
  for (let c = 0; c < w; c++) {
    const i = r * w + c;
    pos[3 * i] = c;
    pos[3 * i + 1] = r;
    pos[3 * i + 2] = z[i];
  }
const idx = new Uint32Array(6 * (w - 1) * (h - 1));
let k = 0;
for (let r = 0; r + 1 < h; r++)
  for (let c = 0; c + 1 < w; c++) {
    const a = r * w + c, b = a + 1, d = a + w, e = d + 1;
    idx.set([a, b, e, a, e, d], k);
    k += 6;
  }
// The locked border keeps its vertices, so a target of 2N triangles leaves
// more than N vertices: the target is scaled by want / kept and the
// simplification redone from the full grid (at most 5 tries) until the
// count is within 1 % of N. The time is that of the last try.
const want = Number(args.vertices);
let target = 6 * want, out, err, secs, used;
for (let tries = 0; tries < 5; tries++) {
  const t0 = process.hrtime.bigint();
  [out, err] = S.simplify(idx, pos, 3, target, 1.0, ['LockBorder']);
  secs = Number(process.hrtime.bigint() - t0) / 1e9;
  used = new Set(out);
  if (Math.abs(used.size - want) <= 0.01 * want) break;
  target = 3 * Math.round(target / 3 * want / used.size);
}
const px = (i) => gt[0] + (pos[3 * i] + 0.5) * gt[1] + (pos[3 * i + 1] + 0.5) * gt[2];
const py = (i) => gt[3] + (pos[3 * i] + 0.5) * gt[4] + (pos[3 * i + 1] + 0.5) * gt[5];
const pt = (i) => `[${px(i)},${py(i)},${pos[3 * i + 2]}]`;
const lines = [];
for (let t = 0; t < out.length; t += 3) {
  let a = out[t], b = out[t + 1], c = out[t + 2];
  const cross = (px(b) - px(a)) * (py(c) - py(a)) - (py(b) - py(a)) * (px(c) - px(a));
  if (cross < 0) [b, c] = [c, b];
  lines.push(`{"type":"Feature","properties":{},"geometry":{"type":"Polygon",` +
    `"coordinates":[[${pt(a)},${pt(b)},${pt(c)},${pt(a)}]]}}\n`);
}
fs.writeFileSync(args.out, lines.join(''));
process.stdout.write(JSON.stringify({ tool: 'meshoptimizer', vertices: used.size,
  triangles: out.length / 3, own_error: err, seconds: secs }) + '\n');
