// delatin_run.mjs -- runs the npm package delatin on a DEM, for bench/run.sh.
//
//   node bench/delatin_run.mjs --delatin PATH/index.js --raw DEM.raw \
//        --info DEM.info.json --max-error E --out TIN.obj
//
// Node has no GeoTIFF reader, so run.sh exports the DEM with
// `gdal_translate -of ENVI -ot Float32` (DEM.raw + DEM.hdr, row-major
// float32) and its `gdalinfo -json` (size). This script reads the raw
// samples, meshes them with `new Delatin(data, w, h).run(E)` and writes
// delatin's own result as it holds it, a Wavefront OBJ of its `coords`
// (`v x y z`) and `triangles` (`f a b c`), with no georeferencing:
// `terratin eval` reads it straight, in the DEM's pixel frame.
//
// Delatin's coordinates are sample indices: vertex (x, y) is column x, row y
// counted down, height data[y * width + x] (its heightAt()). eval's pixel
// frame counts rows up (as hmm's STL does), so run.sh measures the OBJ
// with `-tin_frame pixel -tin_transform 1,-1,1,0,HEIGHT-1,0`.
//
// Prints one JSON object on stdout: vertices, triangles, delatin's own max
// error, and seconds {read, mesh, write, total} from process.hrtime (total
// runs from the first read to the last write; node's start-up is not in it,
// run.sh's wall clock has it).

import fs from 'node:fs';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

function parseArgs(argv) {
  const opt = {};
  for (let i = 0; i < argv.length; i += 2) {
    const k = argv[i];
    const v = argv[i + 1];
    if (!k.startsWith('--') || v === undefined) {
      throw new Error(`bad argument near ${k}`);
    }
    opt[k.slice(2)] = v;
  }
  for (const k of ['delatin', 'raw', 'info', 'max-error', 'out']) {
    if (!(k in opt)) throw new Error(`missing --${k}`);
  }
  return opt;
}

const seconds = (t0) => Number(process.hrtime.bigint() - t0) / 1e9;

// The few ENVI header fields we rely on, checked rather than assumed.
function checkEnviHeader(hdrPath, width, height) {
  const text = fs.readFileSync(hdrPath, 'utf8');
  const field = (name) => {
    const m = text.match(new RegExp(`^\\s*${name}\\s*=\\s*(\\S+)`, 'm'));
    return m ? m[1] : undefined;
  };
  const want = {
    samples: String(width), lines: String(height), bands: '1',
    'data type': '4', // float32
    'byte order': '0', // little endian
    'header offset': '0',
  };
  for (const [k, v] of Object.entries(want)) {
    if (field(k) !== v) {
      throw new Error(`${hdrPath}: expected "${k} = ${v}", found ${field(k)}`);
    }
  }
  if (new Uint8Array(new Uint16Array([1]).buffer)[0] !== 1) {
    throw new Error('this script assumes a little-endian machine');
  }
}

async function main() {
  const opt = parseArgs(process.argv.slice(2));
  const { default: Delatin } = await import(pathToFileURL(path.resolve(opt.delatin)).href);
  const info = JSON.parse(fs.readFileSync(opt.info, 'utf8'));
  const [width, height] = info.size;
  const maxError = Number(opt['max-error']);
  if (!(maxError >= 0)) throw new Error(`bad --max-error ${opt['max-error']}`);
  checkEnviHeader(opt.raw.replace(/\.[^./]*$/, '') + '.hdr', width, height);

  // --- read
  const tStart = process.hrtime.bigint();
  const buf = fs.readFileSync(opt.raw);
  if (buf.length !== width * height * 4) {
    throw new Error(`${opt.raw}: ${buf.length} bytes, expected ${width * height * 4}`);
  }
  // A Buffer may start at any byte of its pool: copy when not 4-aligned.
  const data = buf.byteOffset % 4 === 0
    ? new Float32Array(buf.buffer, buf.byteOffset, width * height)
    : new Float32Array(buf.buffer.slice(buf.byteOffset, buf.byteOffset + buf.length));
  for (let i = 0; i < data.length; i++) {
    if (!Number.isFinite(data[i])) throw new Error(`sample ${i} is not finite: delatin has no nodata`);
  }
  const tRead = seconds(tStart);

  // --- mesh
  const tMesh0 = process.hrtime.bigint();
  const tin = new Delatin(data, width, height);
  tin.run(maxError);
  const tMesh = seconds(tMesh0);
  const ownMaxError = tin.getMaxError();

  // --- write
  const tWrite0 = process.hrtime.bigint();
  const { coords, triangles } = tin;
  const nv = coords.length >> 1;
  const nt = triangles.length / 3;
  const fd = fs.openSync(opt.out, 'w');
  let chunk = [`# delatin ${nv} vertices, ${nt} triangles\n`];
  const flush = () => {
    fs.writeSync(fd, chunk.join(''));
    chunk = [];
  };
  for (let i = 0; i < nv; i++) {
    const x = coords[2 * i];
    const y = coords[2 * i + 1];
    chunk.push(`v ${x} ${y} ${data[y * width + x]}\n`);
    if (chunk.length === 8192) flush();
  }
  for (let t = 0; t < nt; t++) {
    chunk.push(`f ${triangles[3 * t] + 1} ${triangles[3 * t + 1] + 1} ${triangles[3 * t + 2] + 1}\n`);
    if (chunk.length === 8192) flush();
  }
  flush();
  fs.closeSync(fd);
  const tWrite = seconds(tWrite0);

  process.stdout.write(JSON.stringify({
    tool: 'delatin',
    width, height,
    max_error_requested: maxError,
    vertices: nv,
    triangles: nt,
    delatin_max_error: ownMaxError,
    seconds: { read: tRead, mesh: tMesh, write: tWrite, total: seconds(tStart) },
  }) + '\n');
}

main().catch((err) => {
  process.stderr.write(`delatin_run: ${err.message}\n`);
  process.exit(1);
});
