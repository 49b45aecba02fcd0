// The dragon as one glTF scene, plain and compressed four ways: bytes, and
// time to first and final render at a simulated 10 Mbit/s in headless
// chromium through GLTFLoader (web/gltf-bench.html): Draco
// (KHR_draco_mesh_compression by glTF Transform with draco3d, edgebreaker,
// 12-bit positions, slowest and best coding), meshopt
// (EXT_meshopt_compression by Debian's gltfpack -cc, 12-bit positions) and
// kdmesh (KDMESH_progressive_compression, 12-bit grid, in the .glb and in a
// .kdm file beside it). The scene's positions are on a 12-bit grid already
// (the dragon encoded at 12 bits and decoded to glTF), so every coder keeps
// the same geometry.
//
//   node bench/gltf-bench.mjs [--throttle KBPS] [--runs N]
import { execFileSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync, statSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { NodeIO } from '@gltf-transform/core';
import { KHRDracoMeshCompression } from '@gltf-transform/extensions';
import { draco } from '@gltf-transform/functions';
import draco3d from 'draco3d';
import { launchChromium } from '../tests/browser/chromium.mjs';
import { startServer } from '../web/server.mjs';

const root = new URL('..', import.meta.url).pathname;
function option(name, fallback) {
  const at = process.argv.indexOf(name);
  return at > 0 ? Number(process.argv[at + 1]) : fallback;
}
const throttle = option('--throttle', 10000);
const runs = option('--runs', 1);
const dir = mkdtempSync(join(tmpdir(), 'kdmesh-gltf-bench-'));
process.on('exit', () => rmSync(dir, { recursive: true, force: true }));
// bench/run.sh's CLI when it has built one, else build/'s.
const cli = [join(root, 'build-bench', 'kdmesh'), join(root, 'build', 'kdmesh')].find(existsSync);
const kdm = (...args) => execFileSync(cli, [...args, '-q']);

kdm('encode', join(root, 'build', 'models', 'dragon_vrip.ply'), '-o', join(dir, 'dragon12.kdm'), '--bits', '12');
kdm('decode', join(dir, 'dragon12.kdm'), '-o', join(dir, 'dragon.glb'));
kdm('encode', join(dir, 'dragon.glb'), '-o', join(dir, 'dragon.kdm.glb'), '--bits', '12');
kdm('encode', join(dir, 'dragon.glb'), '-o', join(dir, 'streamed.kdm.glb'), '--bits', '12', '--kdm-files');
execFileSync('gltfpack', ['-i', join(dir, 'dragon.glb'), '-o', join(dir, 'dragon.meshopt.glb'), '-cc', '-vp', '12'], { stdio: 'ignore' });
const io = new NodeIO().registerExtensions([KHRDracoMeshCompression])
  .registerDependencies({ 'draco3d.encoder': await draco3d.createEncoderModule(), 'draco3d.decoder': await draco3d.createDecoderModule() });
const document = await io.read(join(dir, 'dragon.glb'));
await document.transform(draco({ method: 'edgebreaker', encodeSpeed: 0, decodeSpeed: 0, quantizePosition: 12 }));
writeFileSync(join(dir, 'dragon.draco.glb'), await io.writeBinary(document));

const variants = [
  ['plain glTF (float32, uint32 indices)', 'dragon.glb', []],
  ['Draco (KHR_draco_mesh_compression, edgebreaker, 12 bits)', 'dragon.draco.glb', []],
  ['meshopt (gltfpack -cc -vp 12)', 'dragon.meshopt.glb', []],
  ['kdmesh (stream in the .glb, 12 bits)', 'dragon.kdm.glb', []],
  ['kdmesh (stream in a .kdm beside the .glb)', 'streamed.kdm.glb', ['streamed.0-0.kdm']],
];
const server = await startServer({ port: 0, root: dir, host: '127.0.0.1' });
const base = `http://127.0.0.1:${server.address().port}`;
const browser = await launchChromium();

async function load(name) {
  const page = await browser.newPage({ viewport: { width: 800, height: 600 } });
  await page.goto(`${base}/gltf-bench.html?model=models/${name}&throttle=${throttle}`, { waitUntil: 'domcontentloaded' });
  await page.waitForFunction(() => window.gltfBench.state !== 'loading' || window.gltfBench.error, null, { timeout: 600000 });
  const result = await page.evaluate(() => ({ ...window.gltfBench }));
  await page.close();
  if (result.error) throw new Error(`${name}: ${result.error}`);
  return result;
}

const ms = (v) => (v === null ? '–' : `${(v / 1000).toFixed(2)} s`);
console.log(`| dragon scene at ${throttle / 1000} Mbit/s | bytes | first render | final render | refinements | triangles drawn | longest main-thread task |`);
console.log('|---|---:|---:|---:|---:|---:|---:|');
for (const [label, file, extra] of variants) {
  const bytes = [file, ...extra].reduce((sum, f) => sum + statSync(join(dir, f)).size, 0);
  for (let i = 1; i <= runs; ++i) {
    const r = await load(file);
    console.log(`| ${label}${runs > 1 ? `, run ${i}` : ''} | ${bytes.toLocaleString('en-US')} | ${ms(r.firstRenderMs)} | ` +
      `${ms(r.finalRenderMs)} | ${r.refinements} | ${r.triangles.toLocaleString('en-US')} | ${Math.max(0, ...r.longTasks)} ms |`);
  }
}
await browser.close();
server.close();
