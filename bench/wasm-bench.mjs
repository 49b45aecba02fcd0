// WebAssembly decoder benchmark, in one Node process: kdmesh's WASM decoder
// against the native decoder (its in-process time, as `kdmesh decode`
// reports it) and against draco3d (Draco's own WASM decoder from npm) on the
// same models at the same quantization, each model's stream encoded by
// default and with --fast-decode. Warm medians of 5 runs.
//
//   node bench/wasm-bench.mjs [--quick] MODEL...
import { execFileSync, spawnSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { basename, join } from 'node:path';
import draco3d from 'draco3d';
import { createDecoder, decode } from 'kdmesh';

const args = process.argv.slice(2);
const quick = args.includes('--quick');
const models = args.filter((a) => a !== '--quick');
const runs = quick ? 3 : 5;
const work = mkdtempSync(join(tmpdir(), 'kdmesh-wasm-bench-'));
const cli = new URL('../build-bench/kdmesh', import.meta.url).pathname;

async function median(body) {
  await body();
  const times = [];
  for (let i = 0; i < runs; ++i) {
    const start = performance.now();
    await body();
    times.push(performance.now() - start);
  }
  times.sort((a, b) => a - b);
  return times[times.length >> 1] / 1000;
}

function nativeDecodeSeconds(kdm) {
  const times = [];
  for (let i = 0; i <= runs; ++i) {
    const run = spawnSync(cli, ['decode', kdm, '-o', join(work, 'native.ply')], { encoding: 'utf8' });
    const match = /\[decode ([0-9.]+)s\]/.exec(run.stderr);
    if (!match) throw new Error(`kdmesh decode printed no time: ${run.stderr}`);
    if (i > 0) times.push(Number(match[1]));  // the first run warms the file cache
  }
  times.sort((a, b) => a - b);
  return times[times.length >> 1];
}

const dracoModule = await draco3d.createDecoderModule({});
function dracoDecode(bytes) {
  const decoder = new dracoModule.Decoder();
  const mesh = new dracoModule.Mesh();
  const status = decoder.DecodeArrayToMesh(bytes, bytes.length, mesh);
  if (!status.ok()) throw new Error(`draco3d: ${status.error_msg()}`);
  const faces = mesh.num_faces();
  const indices = new Uint32Array(faces * 3);
  const indexPtr = dracoModule._malloc(indices.byteLength);
  decoder.GetTrianglesUInt32Array(mesh, indices.byteLength, indexPtr);
  const position = decoder.GetAttributeId(mesh, dracoModule.POSITION);
  const attribute = decoder.GetAttribute(mesh, position);
  const floats = mesh.num_points() * 3;
  const positionPtr = dracoModule._malloc(floats * 4);
  decoder.GetAttributeDataArrayForAllPoints(mesh, attribute, dracoModule.DT_FLOAT32, floats * 4, positionPtr);
  dracoModule._free(indexPtr);
  dracoModule._free(positionPtr);
  dracoModule.destroy(mesh);
  dracoModule.destroy(decoder);
  return faces;
}

console.log(`| model | triangles | kdmesh bytes | kdmesh WASM decode s | native CLI decode s (fresh process) | WASM / native | ` +
  `WASM MB/s | WASM Mtri/s | Draco -cl 10 bytes | draco3d decode s | kdmesh WASM / draco3d | first snapshot after |`);
console.log('|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|');
for (const [model, coding] of models.flatMap((m) => [[m, []], [m, ['--fast-decode']]])) {
  const name = [basename(model), ...coding].join(' ');
  const kdm = join(work, `${basename(model)}${coding.length ? '-fast' : ''}.kdm`);
  const drc = join(work, `${basename(model)}.drc`);
  execFileSync(cli, ['encode', model, '-o', kdm, '--bits', '12', '-q', ...coding]);
  if (!existsSync(drc)) {
    // draco_encoder reads PLY, OBJ and STL: hand it a lossless PLY copy.
    const ply = join(work, `${basename(model)}.ply`);
    execFileSync(cli, ['encode', model, '-o', `${ply}.kdm`, '--exact', '-q']);
    execFileSync(cli, ['decode', `${ply}.kdm`, '-o', ply, '-q']);
    execFileSync('draco_encoder', ['-i', ply, '-o', drc, '-qp', '12', '-cl', '10'], { stdio: 'ignore' });
  }
  const bytes = readFileSync(kdm);
  const dracoBytes = readFileSync(drc);
  let triangles = 0;
  const wasm = await median(async () => { triangles = (await decode(bytes)).triangles.length / 3; });
  const native = nativeDecodeSeconds(kdm);
  const draco = await median(() => dracoDecode(dracoBytes));
  // The first snapshot: header plus first chunk.
  const decoder = await createDecoder();
  let firstAt = 0;
  for (let at = 256; at <= bytes.length && !firstAt; at += 256) {
    decoder.push(bytes.subarray(at - 256, at));
    if (decoder.progress.chunksApplied > 0) firstAt = at;
  }
  decoder.dispose();
  console.log(`| ${name} | ${triangles} | ${bytes.length} | ${wasm.toFixed(3)} | ${native.toFixed(3)} | ` +
    `${(wasm / native).toFixed(2)} | ${(bytes.length / wasm / 1e6).toFixed(2)} | ${(triangles / wasm / 1e6).toFixed(2)} | ` +
    `${dracoBytes.length} | ${draco.toFixed(3)} | ${(wasm / draco).toFixed(2)} | ` +
    `${firstAt} B (${((100 * firstAt) / bytes.length).toFixed(2)} %) |`);
}
rmSync(work, { recursive: true, force: true });
