// report.mjs -- prints bench/run.sh's table for each DEM from bench/out/.
//
//   node bench/report.mjs bench/out ds1025 [ds4097 ...]
//
// Reads, per case C: C.case.json (size, seed, E), C.terratin.json
// (simplify -json), C.delatin.json (delatin_run.mjs), C.{terratin,delatin}.
// eval.json (terratin eval -json), C.{terratin,delatin}.{ns,rss} (wall time,
// peak RSS), and the baselines base_terratin.rss (simplify of a 9x9 DEM),
// base_terratin_version.rss and base_node.rss.
// Checks the goals of the spine issue: at equal max error, terratin's
// triangles <= delatin's + 1 %, its meshing >= 5x faster, and its peak
// memory net of the baseline <= 8 bytes per sample + 80 bytes per triangle.

import fs from 'node:fs';
import path from 'node:path';

const [dir, ...cases] = process.argv.slice(2);
if (!dir || cases.length === 0) {
  process.stderr.write('usage: node bench/report.mjs OUTDIR CASE...\n');
  process.exit(2);
}

const file = (name) => path.join(dir, name);
const json = (name) => {
  // The last non-empty line that parses: tolerate a stray line before it.
  const lines = fs.readFileSync(file(name), 'utf8').split('\n').filter((l) => l.trim());
  for (let i = lines.length - 1; i >= 0; i--) {
    try { return JSON.parse(lines[i]); } catch { /* earlier line */ }
  }
  return JSON.parse(lines.join('\n'));
};
const num = (name) => Number(fs.readFileSync(file(name), 'utf8').trim());
const KiB = 1024;
const MiB = 1024 * 1024;

// A number at a dotted path ('seconds.simplify'), NaN when absent.
function pick(obj, ...paths) {
  for (const p of paths) {
    let v = obj;
    for (const k of p.split('.')) v = v == null ? undefined : v[k];
    if (typeof v === 'number') return v;
  }
  return NaN;
}

const fmt = (v, d = 3) => (Number.isFinite(v) ? v.toFixed(d) : 'n/a');
const int = (v) => (Number.isFinite(v) ? Math.round(v).toLocaleString('en-US') : 'n/a');
const pad = (s, w) => String(s).padStart(w);
const row = (label, a, b, r = '') => `  ${label.padEnd(24)}${pad(a, 14)}${pad(b, 14)}${pad(r, 14)}`;

const baseTT = num('base_terratin.rss') * KiB;          // simplify of a 9x9 DEM
const baseVersion = num('base_terratin_version.rss') * KiB; // terratin --version
const baseNode = num('base_node.rss') * KiB;
let allMet = true;

for (const c of cases) {
  const cs = json(`${c}.case.json`);
  const tt = json(`${c}.terratin.json`);
  const dl = json(`${c}.delatin.json`);
  const te = json(`${c}.terratin.eval.json`);
  const de = json(`${c}.delatin.eval.json`);
  const samples = cs.size * cs.size;
  const E = cs.max_error;

  const t = {
    // meshing as delatin's run() does it: up to the finished mesh; then
    // the error statistics (a pass over every sample) that delatin lacks
    mesh: pick(tt, 'seconds.mesh'),
    simplify: pick(tt, 'seconds.simplify'),
    e2e: num(`${c}.terratin.ns`) / 1e9,
    rss: num(`${c}.terratin.rss`) * KiB,
    v: pick(tt, 'vertices'),
    tri: pick(tt, 'triangles'),
    max: pick(te, 'max_error'),
    rms: pick(te, 'rmse'),
    uncovered: pick(te, 'uncovered'),
    overlapped: pick(te, 'overlapped'),
    rejected: pick(te, 'rejected'),
  };
  const d = {
    mesh: pick(dl, 'seconds.mesh'),
    e2e: num(`${c}.delatin.ns`) / 1e9,
    rss: num(`${c}.delatin.rss`) * KiB,
    v: pick(dl, 'vertices'),
    tri: pick(dl, 'triangles'),
    max: pick(de, 'max_error'),
    rms: pick(de, 'rmse'),
    uncovered: pick(de, 'uncovered'),
    overlapped: pick(de, 'overlapped'),
    rejected: pick(de, 'rejected'),
  };

  const out = [];
  out.push('');
  out.push(`${c}: ${cs.size} x ${cs.size} diamond-square (seed ${cs.seed}), ` +
    `${int(samples)} samples, max error E = ${E}`);
  out.push(row('', 'terratin', 'delatin', 'delatin/terr.'));
  out.push(row('meshing s', fmt(t.mesh), fmt(d.mesh), fmt(d.mesh / t.mesh, 2) + 'x'));
  out.push(row('  + error statistics s', fmt(t.simplify), '-', fmt(d.mesh / t.simplify, 2) + 'x'));
  out.push(row('end-to-end s', fmt(t.e2e), fmt(d.e2e), fmt(d.e2e / t.e2e, 2) + 'x'));
  out.push(row('peak MiB', fmt(t.rss / MiB, 1), fmt(d.rss / MiB, 1), fmt(d.rss / t.rss, 2) + 'x'));
  out.push(row('peak MiB net of baseline', fmt((t.rss - baseTT) / MiB, 1), fmt((d.rss - baseNode) / MiB, 1), ''));
  out.push(row('vertices', int(t.v), int(d.v), fmt(d.v / t.v, 3)));
  out.push(row('  % of samples', fmt(100 * t.v / samples, 2), fmt(100 * d.v / samples, 2), ''));
  out.push(row('triangles', int(t.tri), int(d.tri), fmt(d.tri / t.tri, 3)));
  out.push(row('max error (eval)', fmt(t.max, 4), fmt(d.max, 4), ''));
  out.push(row('RMS error (eval)', fmt(t.rms, 4), fmt(d.rms, 4), ''));
  // A proper TIN covers every sample once; show the coverage only when not.
  for (const [k, label] of [['uncovered', 'uncovered samples'],
    ['overlapped', 'overlapped samples'], ['rejected', 'rejected polygons']]) {
    if (t[k] || d[k]) out.push(row(label, int(t[k]), int(d[k]), ''));
  }

  // Goals (spine issue): equal error, <= delatin's triangles + 1 %, >= 5x
  // faster meshing, net peak <= 8 B/sample + 80 B/triangle.
  const net = t.rss - baseTT;
  const budget = 8 * samples + 80 * t.tri;
  const perTri = (net - 8 * samples) / t.tri;
  const goals = [
    [`max error <= E (${E}) for both`, t.max <= E && d.max <= E],
    [`triangles <= delatin + 1 % (${fmt(t.tri / d.tri, 3)} x delatin)`, t.tri <= 1.01 * d.tri],
    [`meshing >= 5x faster (${fmt(d.mesh / t.mesh, 2)}x; ` +
      `${fmt(d.mesh / t.simplify, 2)}x with the error statistics)`, d.mesh / t.mesh >= 5],
    [`net peak ${fmt(net / MiB, 1)} MiB <= budget ${fmt(budget / MiB, 1)} MiB`, net <= budget],
  ];
  out.push(`  terratin memory: ${fmt(net / samples, 2)} B/sample net of the ` +
    `${fmt(baseTT / MiB, 1)} MiB baseline (a 9x9 run; --version: ` +
    `${fmt(baseVersion / MiB, 1)} MiB);`);
  out.push(perTri > 0
    ? `    beyond 8 B/sample: ${fmt(perTri, 1)} B/triangle (goal: 8 B/sample + 80 B/triangle)`
    : `    within 8 B/sample alone (goal: 8 B/sample + 80 B/triangle)`);
  for (const [what, ok] of goals) {
    out.push(`  goal ${ok ? 'met   ' : 'NOT met'}: ${what}`);
    allMet = allMet && ok;
  }
  process.stdout.write(out.join('\n') + '\n');
}
process.stdout.write(`\n${allMet ? 'all goals met' : 'some goals NOT met'}\n`);
