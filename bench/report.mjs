// report.mjs -- prints bench/run.sh's table for each DEM from bench/out/.
//
//   node bench/report.mjs bench/out ds1025 [crater hood ds4097 ...]
//
// Reads, per case C: C.case.json (DEM, E), C.info.json (size),
// C.<tool>.json (terratin simplify -json, hmm's printed phases, delatin
// delatin_run.mjs), C.<tool>.eval.json (terratin eval -json of its TIN),
// C.<tool>.{ns,rss} (wall time, peak RSS), for the tools whose files are
// there (hmm is optional). Checks the goals of issue 16 against hmm:
// terratin's write <= its meshing; its wall clock below hmm's on every DEM
// and at most 0.6x hmm's on ds4097; its meshing at least 2x hmm's
// throughput on DEMs of 1 M samples or more and no slower on Crater Lake;
// its peak memory at most hmm's on ds4097.

import fs from 'node:fs';
import path from 'node:path';

const [dir, ...cases] = process.argv.slice(2);
if (!dir || cases.length === 0) {
  process.stderr.write('usage: node bench/report.mjs OUTDIR CASE...\n');
  process.exit(2);
}

const file = (name) => path.join(dir, name);
const exists = (name) => fs.existsSync(file(name));
const json = (name) => {
  // The last non-empty line that parses: tolerate a stray line before it.
  const lines = fs.readFileSync(file(name), 'utf8').split('\n').filter((l) => l.trim());
  for (let i = lines.length - 1; i >= 0; i--) {
    try { return JSON.parse(lines[i]); } catch { /* earlier line */ }
  }
  return JSON.parse(lines.join('\n'));
};
const num = (name) => Number(fs.readFileSync(file(name), 'utf8').trim());
const MiB = 1024 * 1024;

// A number at a dotted path ('seconds.mesh'), NaN when absent.
function pick(obj, ...paths) {
  for (const p of paths) {
    let v = obj;
    for (const k of p.split('.')) v = v == null ? undefined : v[k];
    if (typeof v === 'number') return v;
  }
  return NaN;
}

const fmt = (v, d = 3) => (Number.isFinite(v) ? v.toFixed(d) : '-');
const int = (v) => (Number.isFinite(v) ? Math.round(v).toLocaleString('en-US') : '-');
const ratio = (a, b) => (Number.isFinite(a) && Number.isFinite(b) && b > 0 ? `${(a / b).toFixed(2)}x` : '-');
const pad = (s, w) => String(s).padStart(w);

let allMet = true;
for (const c of cases) {
  const cs = json(`${c}.case.json`);
  const gi = json(`${c}.info.json`); // bench/peer_input.py: size, z range
  const samples = gi.size[0] * gi.size[1];
  const tools = ['terratin', 'hmm', 'delatin'].filter((t) => exists(`${c}.${t}.json`));
  const m = {};
  for (const t of tools) {
    const j = json(`${c}.${t}.json`);
    const e = exists(`${c}.${t}.eval.json`) ? json(`${c}.${t}.eval.json`) : {};
    m[t] = {
      read: pick(j, 'seconds.read'),
      mesh: pick(j, 'seconds.mesh'),
      stats: t === 'terratin' ? pick(j, 'seconds.statistics') : NaN,
      write: pick(j, 'seconds.write'),
      wall: num(`${c}.${t}.ns`) / 1e9,
      rss: num(`${c}.${t}.rss`) * 1024,
      v: pick(j, 'vertices'),
      tri: pick(j, 'triangles'),
      max: pick(e, 'max_error'),
      rms: pick(e, 'rmse'),
    };
  }
  const peers = tools.filter((t) => t !== 'terratin');
  const head = ['', ...tools, ...peers.map((p) => `${p}/terr.`)];
  const widths = [26, ...head.slice(1).map(() => 13)];
  const line = (cells) => '  ' + cells.map((x, i) => (i === 0 ? String(x).padEnd(widths[0]) : pad(x, widths[i]))).join('');
  const out = [''];
  out.push(`${c}: ${path.basename(cs.dem)}, ${gi.size[0]} x ${gi.size[1]} = ${int(samples)} samples, ` +
    `max error E = ${cs.max_error}`);
  out.push(line(head));
  const rowOf = (label, key, f = fmt, withRatio = true) =>
    line([label, ...tools.map((t) => f(m[t][key])),
      ...peers.map((p) => (withRatio ? ratio(m[p][key], m.terratin[key]) : ''))]);
  out.push(rowOf('read s', 'read'));
  out.push(rowOf('meshing s', 'mesh'));
  out.push(rowOf('error statistics s', 'stats', fmt, false));
  out.push(rowOf('write s', 'write'));
  out.push(rowOf('wall s (whole process)', 'wall'));
  out.push(rowOf('peak MiB', 'rss', (v) => fmt(v / MiB, 1)));
  out.push(rowOf('vertices', 'v', int));
  out.push(rowOf('triangles', 'tri', int));
  out.push(rowOf('max error (eval)', 'max', (v) => fmt(v, 4), false));
  out.push(rowOf('RMSE (eval)', 'rms', (v) => fmt(v, 4), false));

  const t = m.terratin;
  const goals = [[`terratin's write ${fmt(t.write)} s <= its meshing ${fmt(t.mesh)} s`, t.write <= t.mesh]];
  if (m.hmm) {
    const h = m.hmm;
    goals.push([`wall ${fmt(t.wall)} s < hmm's ${fmt(h.wall)} s (${ratio(t.wall, h.wall)} of hmm)`, t.wall < h.wall]);
    if (c === 'ds4097') {
      goals.push([`wall <= 0.6x hmm's on ds4097 (${ratio(t.wall, h.wall)})`, t.wall <= 0.6 * h.wall]);
      goals.push([`peak memory ${fmt(t.rss / MiB, 1)} MiB <= hmm's ${fmt(h.rss / MiB, 1)} MiB`, t.rss <= h.rss]);
    }
    if (samples >= 1e6) {
      goals.push([`meshing >= 2x hmm's throughput (${ratio(h.mesh, t.mesh)})`, h.mesh >= 2 * t.mesh]);
    } else if (c === 'crater') {
      goals.push([`meshing no slower than hmm's (${ratio(h.mesh, t.mesh)})`, h.mesh >= t.mesh]);
    }
  }
  for (const [what, ok] of goals) {
    out.push(`  goal ${ok ? 'met   ' : 'NOT met'}: ${what}`);
    allMet = allMet && ok;
  }
  process.stdout.write(out.join('\n') + '\n');
}
process.stdout.write(`\n${allMet ? 'all goals met' : 'some goals NOT met'}\n`);
