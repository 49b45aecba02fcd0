// kdmesh/gltf in headless chromium: GLTFLoader with KDMeshGLTFExtension
// loads scenes encoded by the CLI through the dev server, paced: the scene
// graph comes before the geometry is complete, the geometry refines in
// several levels, and the final geometry is the stream's.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { serveAndLaunch, openTestPage } from './chromium.mjs';
import { decode } from 'kdmesh';
import { modelChecksum } from '../../web/model-checksum.js';
import { cli } from '../js/fixtures.mjs';
import { writeTestScene, readGlb } from '../js/gltf-fixtures.mjs';

const models = mkdtempSync(join(tmpdir(), 'kdmesh-gltf-'));
let served, browser, base, expected;

const testPage = `<!doctype html><meta charset="utf-8"><link rel="icon" href="data:,">
<script type="importmap">{ "imports": { "three": "./vendor/three/build/three.module.js",
  "three/addons/": "./vendor/three/examples/jsm/", "kdmesh": "./kdmesh.js", "kdmesh/three": "./three.js", "kdmesh/gltf": "./gltf.js" } }</script>
<script type="module">
  import * as THREE from 'three';
  import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
  import { KDMeshLoader } from 'kdmesh/three';
  import { KDMeshGLTFExtension } from 'kdmesh/gltf';
  import { modelChecksum } from './model-checksum.js';
  // The drawn geometry as a decoded model, for modelChecksum.
  const drawn = (geometry) => ({
    positions: geometry.getAttribute('position').array.subarray(0, 3 * geometry.getAttribute('position').count),
    points: new Uint32Array(0), edges: new Uint32Array(0), tetrahedra: new Uint32Array(0),
    triangles: geometry.index.array.subarray(0, geometry.drawRange.count),
  });
  // Loads url with the plugin; what the torus looked like when the scene came, and at the end.
  window.loadScene = async (url, kdmesh) => {
    const loader = new GLTFLoader().register((parser) => new KDMeshGLTFExtension(parser, { loader: kdmesh }));
    const gltf = await loader.loadAsync(url);
    const torus = gltf.scene.getObjectByName('torus');
    const names = [];
    gltf.scene.traverse((object) => names.push(object.name));
    const atScene = { complete: torus.geometry.userData.stats?.complete ?? false, names, streams: gltf.userData.kdmesh.streams };
    await gltf.userData.kdmesh.loaded;
    const { stats } = torus.geometry.userData;
    return { atScene, refinements: stats.refinements, complete: stats.complete, checksum: modelChecksum(drawn(torus.geometry)),
             colour: torus.geometry.getAttribute('color').normalized };
  };
  Object.assign(window, { THREE, KDMeshLoader, ready: true });
</script>`;

before(async () => {
  // A torus large enough to take several levels, and the stream's own decode.
  writeTestScene(join(models, 'scene.glb'), { rows: 120, columns: 200 });
  execFileSync(cli, ['encode', join(models, 'scene.glb'), '-o', join(models, 'scene.kdm.glb'), '--chunk-bytes', '4096', '-q']);
  execFileSync(cli, ['encode', join(models, 'scene.glb'), '-o', join(models, 'uris.kdm.glb'), '--kdm-files', '--chunk-bytes', '4096', '-q']);
  const { json, bin } = readGlb(readFileSync(join(models, 'scene.kdm.glb')));
  const view = json.bufferViews[json.meshes[0].primitives[0].extensions.KDMESH_progressive_compression.bufferView];
  const decoded = await decode(bin.subarray(view.byteOffset, view.byteOffset + view.byteLength));
  expected = modelChecksum({ ...decoded, points: new Uint32Array(0) });
  served = await serveAndLaunch(models);
  ({ base, browser } = served);
});

after(async () => {
  await served?.close();
  rmSync(models, { recursive: true, force: true });
});

const openPage = () => openTestPage(browser, base, 'gltf-test.html', testPage);

test('a paced .kdm.glb: the scene comes before its geometry is complete, which then refines to the stream', async () => {
  const { page, errors } = await openPage();
  const result = await page.evaluate(() => window.loadScene('models/scene.kdm.glb?throttle=4000', new KDMeshLoader()));
  assert.equal(result.atScene.complete, false);
  assert.equal(result.atScene.streams, 3);
  for (const name of ['root', 'torus', 'quad']) assert.ok(result.atScene.names.includes(name), name);
  assert.equal(result.complete, true);
  assert.ok(result.refinements >= 2, `refinements: ${result.refinements}`);
  assert.equal(result.checksum, expected);
  assert.equal(result.colour, true);
  assert.deepEqual(errors, []);
  await page.close();
});

test('streams in .kdm files download, paced, after the scene has come', async () => {
  const { page, errors } = await openPage();
  const result = await page.evaluate(() => {
    // The streams paced to 400 kbit/s; the .glb (no geometry) at full speed.
    const manager = new THREE.LoadingManager();
    manager.setURLModifier((url) => (url.endsWith('.kdm') ? `${url}?throttle=400` : url));
    return window.loadScene('models/uris.kdm.glb', new KDMeshLoader(manager));
  });
  assert.equal(result.atScene.complete, false);
  assert.equal(result.complete, true);
  assert.ok(result.refinements >= 2, `refinements: ${result.refinements}`);
  assert.equal(result.checksum, expected);
  assert.deepEqual(errors, []);
  await page.close();
});
