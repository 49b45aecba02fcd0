// KDMeshLoader in headless chromium, as a three.js application uses it:
// LoadingManager events and URL handling, abort(), dispose() mid-load, the
// worker pool's limit, the BufferGeometry result, refinements paced by the
// page, decoder limits, a WebAssembly file that cannot be fetched, vertex
// attributes and simplex labels. Models come from the viewer's
// dev server, paced where a load must still be running.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { serveAndLaunch, openTestPage } from './chromium.mjs';
import { decode } from 'kdmesh';
import { modelChecksum } from '../../web/model-checksum.js';
import { root, cli, colouredTorus, writePly } from '../js/fixtures.mjs';

const models = mkdtempSync(join(tmpdir(), 'kdmesh-loader-'));
let served, browser, base, expected, coloured;

// A page with three.js and kdmesh/three in its import map, as the viewer has.
const testPage = `<!doctype html><meta charset="utf-8"><link rel="icon" href="data:,">
<script type="importmap">{ "imports": { "three": "./vendor/three/build/three.module.js", "kdmesh": "./kdmesh.js", "kdmesh/three": "./three.js" } }</script>
<script type="module">
  import * as THREE from 'three';
  import { KDMeshLoader } from 'kdmesh/three';
  import { modelChecksum } from './model-checksum.js';
  Object.assign(window, { THREE, KDMeshLoader, modelChecksum, ready: true });
</script>`;

before(async () => {
  execFileSync(cli, ['encode', join(root, 'build', 'models', 'fandisk.off'), '-o', join(models, 'fandisk.kdm'), '--bits', '12', '-q']);
  const decoded = await decode(readFileSync(join(models, 'fandisk.kdm')));
  expected = { checksum: modelChecksum(decoded), vertexCount: decoded.vertexCount, indices: decoded.triangles.length, bytes: readFileSync(join(models, 'fandisk.kdm')).length };
  // A torus with colours, normals of its own, texture coordinates and a
  // 'label', in several chunks.
  writePly(join(models, 'coloured.ply'), colouredTorus());
  execFileSync(cli, ['encode', join(models, 'coloured.ply'), '-o', join(models, 'coloured.kdm'), '--bits', '12', '--chunk-bytes', '1024', '-q']);
  coloured = await decode(readFileSync(join(models, 'coloured.kdm')));
  served = await serveAndLaunch(models);
  ({ base, browser } = served);
});

after(async () => {
  await served?.close();
  rmSync(models, { recursive: true, force: true });
});

const openPage = () => openTestPage(browser, base, 'loader-test.html', testPage);

test('LoadingManager: itemStart, progress, itemError and itemEnd, resolveURL, path and request headers', async () => {
  const { page, errors } = await openPage();
  const headers = [];
  page.on('request', (request) => request.url().includes('/models/') && headers.push(request.headers()['x-kdmesh-test']));
  const result = await page.evaluate(async () => {
    const events = [];
    const manager = new THREE.LoadingManager(() => events.push('load'), (url, loaded, total) => events.push(`progress ${url.split('/').pop()} ${loaded}/${total}`),
      (url) => events.push(`error ${url.split('/').pop()}`));
    manager.onStart = (url) => events.push(`start ${url.split('/').pop()}`);
    manager.setURLModifier((url) => url.replace('renamed.kdm', 'fandisk.kdm'));
    const loader = new KDMeshLoader(manager).setPath('models/').setRequestHeader({ 'X-Kdmesh-Test': 'yes' });
    const progress = [];
    const group = await loader.loadAsync('renamed.kdm', (event) => progress.push([event.loaded, event.total]));
    const missing = await loader.loadAsync('missing.kdm').then(() => 'loaded', (error) => error.code);
    loader.dispose();
    return { events, progress, missing, checksum: modelChecksum(group.userData.stats.model) };
  });
  assert.equal(result.checksum, expected.checksum);
  assert.equal(result.missing, 'network');
  assert.deepEqual(result.events, [
    'start fandisk.kdm', 'progress fandisk.kdm 1/1', 'load',  // the URL as resolved
    'start missing.kdm', 'error missing.kdm', 'progress missing.kdm 2/2', 'load',
  ]);
  // The first event comes before the stream's header: its total is the response's Content-Length.
  assert.equal(result.progress[0][1], expected.bytes);
  assert.deepEqual(result.progress.at(-1), [expected.bytes, expected.bytes]);
  assert.deepEqual(headers, ['yes', 'yes']);
  assert.deepEqual(errors, []);
  await page.close();
});

test('abort() stops every load in flight, keeps its level and frees the workers', async () => {
  const { page, errors } = await openPage();
  const result = await page.evaluate(async () => {
    const loader = new KDMeshLoader();
    const models = [1, 2].map(() => loader.loadProgressive('models/fandisk.kdm?throttle=20'));
    await new Promise((resolve) => {
      const check = () => (models.every((m) => m.userData.stats.refinements >= 1) ? resolve() : setTimeout(check, 20));
      check();
    });
    const returned = loader.abort() === loader;
    const outcomes = await Promise.all(models.map((m) => m.userData.loaded.then(() => 'loaded', (error) => error.code)));
    return {
      returned, outcomes, busy: loader.busyWorkers,
      vertices: models.map((m) => m.userData.stats.model.vertexCount),
      visible: models.map((m) => m.children[0].visible),
    };
  });
  assert.equal(result.returned, true);
  assert.deepEqual(result.outcomes, ['aborted', 'aborted']);
  assert.equal(result.busy, 0);
  for (const count of result.vertices) assert.ok(count > 0 && count < expected.vertexCount, `vertices: ${count}`);
  assert.deepEqual(result.visible, [true, true]);
  assert.deepEqual(errors, []);
  await page.close();
});

test('dispose() mid-load settles every load, ends every worker and returns the loader', async () => {
  const { page, errors } = await openPage();
  const result = await page.evaluate(async () => {
    const loader = new KDMeshLoader().setWorkerLimit(1);
    const streaming = loader.loadProgressive('models/fandisk.kdm?throttle=20');
    const queued = loader.loadGeometry('models/fandisk.kdm');  // waits for the only worker
    await new Promise((resolve) => {
      const check = () => (streaming.userData.stats.bytesReceived > 0 ? resolve() : setTimeout(check, 20));
      check();
    });
    const returned = loader.dispose() === loader;
    const outcomes = await Promise.all([streaming, queued].map((m) => m.userData.loaded.then(() => 'loaded', (error) => error.code)));
    return { returned, outcomes, workers: loader.workers.size };
  });
  assert.equal(result.returned, true);
  assert.deepEqual(result.outcomes, ['disposed', 'disposed']);
  assert.equal(result.workers, 0);
  assert.deepEqual(errors, []);
  await page.close();
});

test('setWorkerLimit caps the workers; queued loads wait, then every load completes exactly', async () => {
  const { page, errors } = await openPage();
  const result = await page.evaluate(async () => {
    const runs = {};
    for (const limit of [1, 2]) {
      const loader = new KDMeshLoader().setWorkerLimit(limit);
      let most = 0;
      const models = [1, 2, 3].map(() => loader.loadProgressive('models/fandisk.kdm?throttle=400', {
        onProgress: () => (most = Math.max(most, loader.workers.size)),
      }));
      const groups = await Promise.all(models.map((m) => m.userData.loaded));
      runs[limit] = { most, workers: loader.workers.size, busy: loader.busyWorkers, checksums: groups.map((g) => modelChecksum(g.userData.stats.model)) };
      loader.dispose();
    }
    return runs;
  });
  for (const limit of [1, 2]) {
    const run = result[limit];
    assert.equal(run.most, limit, `limit ${limit}`);
    assert.equal(run.workers, limit, 'finished workers stay for the next loads');
    assert.equal(run.busy, 0);
    assert.deepEqual(run.checksums, [expected.checksum, expected.checksum, expected.checksum]);
  }
  assert.deepEqual(errors, []);
  await page.close();
});

test('loadGeometry refines one BufferGeometry in place and ends on the model', async () => {
  const { page, errors } = await openPage();
  const result = await page.evaluate(async () => {
    const loader = new KDMeshLoader();
    const seen = [];
    // Paced over two seconds or so: several chunks arrive after the worker
    // has started, however slowly it starts on a loaded machine.
    const geometry = loader.loadGeometry('models/fandisk.kdm?throttle=40', {
      onRefine: (g, stats) => seen.push({ same: g === geometry, count: g.drawRange.count, vertices: stats.model.vertexCount }),
    });
    const mesh = new THREE.Mesh(geometry, new THREE.MeshNormalMaterial());
    const resolved = await geometry.userData.loaded;
    const position = geometry.getAttribute('position');
    const model = geometry.userData.stats.model;
    const drawn = Array.from(position.array.subarray(0, 3 * model.vertexCount));
    // The worker's area-weighted normals against three.js's own on the same triangles.
    const normal = geometry.getAttribute('normal');
    const reference = geometry.clone();
    reference.deleteAttribute('normal');
    reference.computeVertexNormals();
    let normalError = 0;
    for (let i = 0; i < 3 * model.vertexCount; ++i)
      normalError = Math.max(normalError, Math.abs(normal.array[i] - reference.getAttribute('normal').array[i]));
    loader.dispose();
    return {
      seen, sameResolved: resolved === geometry, primitive: geometry.userData.primitive, isMeshGeometry: mesh.geometry === geometry,
      indexCount: geometry.drawRange.count, positionsMatch: drawn.every((v, i) => v === model.positions[i]),
      normals: normal?.count, normalError, radius: geometry.boundingSphere.radius, checksum: modelChecksum(model),
    };
  });
  assert.ok(result.seen.length >= 3, `refinements: ${result.seen.length}`);
  assert.ok(result.seen.every((s) => s.same));
  for (let i = 1; i < result.seen.length; ++i) assert.ok(result.seen[i].vertices >= result.seen[i - 1].vertices, JSON.stringify(result.seen));
  assert.ok(result.seen[0].vertices < expected.vertexCount && result.seen[0].count < expected.indices, JSON.stringify(result.seen[0]));
  assert.equal(result.sameResolved, true);
  assert.equal(result.primitive, 'triangles');
  assert.equal(result.indexCount, expected.indices);
  assert.equal(result.positionsMatch, true);
  assert.equal(result.normals, expected.vertexCount);
  assert.ok(result.normalError < 1e-5, `largest normal difference ${result.normalError}`);
  assert.ok(result.radius > 0);
  assert.equal(result.checksum, expected.checksum);
  assert.deepEqual(errors, []);
  await page.close();
});

test('a promise from onRefine holds the next level back; the complete model comes when decoded', async () => {
  const { page, errors } = await openPage();
  const result = await page.evaluate(async () => {
    const loader = new KDMeshLoader();
    // Paced over two seconds or so, a level about every chunk of the
    // stream: each level holds the next back for 400 ms, or for good.
    const load = async (hold) => {
      const levels = [];
      let holding = false;
      const model = loader.loadProgressive('models/fandisk.kdm?throttle=40', {
        onRefine(object, stats) {
          levels.push({ complete: stats.complete, duringHold: holding });
          if (stats.complete) return undefined;
          holding = true;
          return hold === Infinity ? new Promise(() => {})
            : new Promise((resolve) => setTimeout(() => { holding = false; resolve(); }, hold));
        },
      });
      await model.userData.loaded;
      return { levels, checksum: modelChecksum(model.userData.stats.model) };
    };
    const paced = await load(400);
    const heldForGood = await load(Infinity);
    loader.dispose();
    return { paced, heldForGood };
  });
  const { paced, heldForGood } = result;
  assert.ok(paced.levels.length >= 2, JSON.stringify(paced.levels));
  assert.deepEqual(paced.levels.filter((level) => !level.complete && level.duringHold), []);
  assert.equal(paced.levels.at(-1).complete, true);
  assert.equal(paced.checksum, expected.checksum);
  // The first level holds every later one back, but not the complete model.
  assert.deepEqual(heldForGood.levels, [{ complete: false, duringHold: false }, { complete: true, duringHold: true }]);
  assert.equal(heldForGood.checksum, expected.checksum);
  assert.deepEqual(errors, []);
  await page.close();
});

test('decoder limits reach the worker, and an unreachable wasm rejects with wasm-unavailable', async () => {
  const { page, errors } = await openPage();
  const result = await page.evaluate(async () => {
    const limited = new KDMeshLoader().setDecoderLimits({ maxVertices: 100 });
    const code = (promise) => promise.then(() => 'loaded', (error) => error.code);
    const loaderLimit = await code(limited.loadProgressive('models/fandisk.kdm').userData.loaded);
    const loadLimit = await code(new KDMeshLoader().loadProgressive('models/fandisk.kdm', { limits: { maxSimplices: 100 } }).userData.loaded);
    const unlimited = await code(limited.loadProgressive('models/fandisk.kdm', { limits: {} }).userData.loaded);
    const started = performance.now();
    const noWasm = await code(new KDMeshLoader().setDecoderPath('/nowhere/').loadProgressive('models/fandisk.kdm').userData.loaded);
    return { loaderLimit, loadLimit, unlimited, noWasm, ms: performance.now() - started };
  });
  assert.deepEqual({ ...result, ms: undefined }, {
    loaderLimit: 'limit-exceeded', loadLimit: 'limit-exceeded', unlimited: 'loaded', noWasm: 'wasm-unavailable', ms: undefined,
  });
  assert.ok(result.ms < 5000, `rejected after ${result.ms} ms`);
  assert.deepEqual(errors, []);
  await page.close();
});

test('parse() decodes bytes in memory, from an ArrayBuffer or a view of one', async () => {
  const { page, errors } = await openPage();
  const result = await page.evaluate(async () => {
    const loader = new KDMeshLoader();
    const bytes = new Uint8Array(await (await fetch('models/fandisk.kdm')).arrayBuffer());
    const padded = new Uint8Array(bytes.length + 16);
    padded.set(bytes, 8);
    const fromBuffer = await new Promise((resolve, reject) => loader.parse(bytes.buffer, resolve, reject));
    const fromView = await new Promise((resolve, reject) => loader.parse(padded.subarray(8, 8 + bytes.length), resolve, reject));
    const truncated = await new Promise((resolve) => loader.parse(bytes.subarray(0, 5000), () => resolve('loaded'), (error) => resolve(error.code)));
    loader.dispose();
    return { buffer: modelChecksum(fromBuffer.userData.stats.model), view: modelChecksum(fromView.userData.stats.model), truncated };
  });
  assert.deepEqual(result, { buffer: expected.checksum, view: expected.checksum, truncated: 'truncated' });
  assert.deepEqual(errors, []);
  await page.close();
});

test('preload() starts a worker that the first load then uses', async () => {
  const { page, errors } = await openPage();
  const result = await page.evaluate(async () => {
    const loader = new KDMeshLoader();
    const returned = loader.preload() === loader;
    await new Promise((resolve) => {
      const check = () => (loader.workers.size === 1 ? resolve() : setTimeout(check, 10));
      check();
    });
    const [worker] = loader.workers;
    const before = { workers: loader.workers.size, busy: loader.busyWorkers };
    let during = null;
    const model = loader.loadProgressive('models/fandisk.kdm', { onRefine: () => (during ??= { busy: loader.busyWorkers }) });
    await model.userData.loaded;
    const after = { workers: loader.workers.size, busy: loader.busyWorkers, same: [...loader.workers][0] === worker };
    loader.dispose();
    return { returned, before, during, after };
  });
  assert.deepEqual(result, {
    returned: true, before: { workers: 1, busy: 0 }, during: { busy: 1 }, after: { workers: 1, busy: 0, same: true },
  });
  assert.deepEqual(errors, []);
  await page.close();
});

test('an idle worker ends after workerIdleTime', async () => {
  const { page, errors } = await openPage();
  const result = await page.evaluate(async () => {
    const loader = new KDMeshLoader();
    loader.workerIdleTime = 300;
    await loader.loadProgressive('models/fandisk.kdm').userData.loaded;
    const right = loader.workers.size;
    // Reused within the idle time, the worker is kept.
    await new Promise((resolve) => setTimeout(resolve, 150));
    await loader.loadProgressive('models/fandisk.kdm').userData.loaded;
    await new Promise((resolve) => setTimeout(resolve, 200));
    const reused = loader.workers.size;
    await new Promise((resolve) => setTimeout(resolve, 400));
    return { right, reused, later: loader.workers.size };
  });
  assert.deepEqual(result, { right: 1, reused: 1, later: 0 });
  assert.deepEqual(errors, []);
  await page.close();
});

test('vertex attributes: color, the stream\'s normals, uv and others on the geometry, refined in place, with vertex colours', async () => {
  const { page, errors } = await openPage();
  const result = await page.evaluate(async () => {
    // Whether the geometry's attribute `name` starts with the level's values.
    const holds = (geometry, name, { array }) => {
      const drawn = geometry.getAttribute(name)?.array;
      return Boolean(drawn) && array.every((value, i) => Object.is(drawn[i], value));
    };
    const describe = (attribute) => ({
      type: attribute.array.constructor.name, itemSize: attribute.itemSize, normalized: attribute.normalized,
      capacity: attribute.array.length,
    });
    const loader = new KDMeshLoader();
    const levels = [];
    const group = loader.loadProgressive('models/coloured.kdm?throttle=100', {
      onRefine(model, stats) {
        const [surface, lines, points] = model.children;
        const { attributes } = stats.model;
        levels.push({
          vertices: stats.model.vertexCount,
          names: Object.keys(attributes),
          held: Object.entries(attributes).every(([name, attribute]) => holds(surface.geometry, name, attribute)),
          capacities: ['color', 'normal', 'uv', 'label'].map((name) => surface.geometry.getAttribute(name).array.length),
          shared: ['color', 'normal', 'uv', 'label'].every((name) =>
            lines.geometry.getAttribute(name) === surface.geometry.getAttribute(name) &&
            points.geometry.getAttribute(name) === surface.geometry.getAttribute(name)),
        });
      },
    });
    await group.userData.loaded;
    const { geometry, material } = group.children[0];
    const model = group.userData.stats.model;
    const n = model.vertexCount;
    const normals = Array.from(geometry.getAttribute('normal').array.subarray(0, 3 * n));
    const computed = geometry.clone();
    computed.computeVertexNormals();
    const recomputed = Array.from(computed.getAttribute('normal').array.subarray(0, 3 * n));
    const coloured = {
      levels, normals, recomputed,
      color: describe(geometry.getAttribute('color')), normal: describe(geometry.getAttribute('normal')),
      uv: describe(geometry.getAttribute('uv')), label: describe(geometry.getAttribute('label')),
      colors: Array.from(geometry.getAttribute('color').array.subarray(0, 3 * n)),
      uvs: Array.from(geometry.getAttribute('uv').array.subarray(0, 2 * n)),
      labels: Array.from(geometry.getAttribute('label').array.subarray(0, n)),
      streamColors: Array.from(model.attributes.color.array),
      vertexColors: group.children.map((object) => object.material.vertexColors),
      white: material.color.getHex(),
      loaderMaterials: Object.values(loader.materials).map((m) => m.vertexColors),
    };
    // A model without colours from the same loader keeps the loader's materials.
    const plain = await loader.loadAsync('models/fandisk.kdm');
    const uncoloured = {
      same: plain.children.every((object, i) => object.material === Object.values(loader.materials)[i]),
      color: plain.children[0].geometry.hasAttribute('color'),
    };
    // loadGeometry: the same attributes on the one geometry.
    const single = loader.loadGeometry('models/coloured.kdm');
    await single.userData.loaded;
    const singleModel = single.userData.stats.model;
    const geometryView = {
      names: Object.keys(single.attributes).sort(),
      held: Object.entries(singleModel.attributes).every(([name, attribute]) => holds(single, name, attribute)),
      color: describe(single.getAttribute('color')),
    };
    // A material the page puts in `materials` is drawn as it is.
    const own = new THREE.MeshBasicMaterial();
    loader.materials.surface = own;
    const kept = (await loader.loadAsync('models/coloured.kdm')).children[0].material;
    loader.dispose();
    return { coloured, uncoloured, geometryView, pageMaterial: { same: kept === own, vertexColors: kept.vertexColors } };
  });
  const { coloured: c } = result;
  const n = coloured.vertexCount;
  assert.ok(c.levels.length >= 3, `refinements: ${c.levels.length}`);
  assert.ok(c.levels[0].vertices < n, JSON.stringify(c.levels[0]));
  for (const level of c.levels) {
    assert.deepEqual(level.names, ['color', 'normal', 'uv', 'label'], JSON.stringify(level));
    assert.ok(level.held && level.shared, JSON.stringify(level));
    // Sized for the final model from the first level on.
    assert.deepEqual(level.capacities, [3 * n, 3 * n, 2 * n, n], JSON.stringify(level));
  }
  // The stream's types; colours normalized.
  assert.deepEqual(c.color, { type: 'Uint8Array', itemSize: 3, normalized: true, capacity: 3 * n });
  assert.deepEqual(c.normal, { type: 'Float32Array', itemSize: 3, normalized: false, capacity: 3 * n });
  assert.deepEqual(c.uv, { type: 'Float32Array', itemSize: 2, normalized: false, capacity: 2 * n });
  assert.deepEqual(c.label, { type: 'Int16Array', itemSize: 1, normalized: false, capacity: n });
  // The stream's values, the normals not recomputed from the triangles.
  assert.deepEqual(c.colors, Array.from(coloured.attributes.color.array));
  assert.deepEqual(c.streamColors, c.colors);
  assert.deepEqual(c.normals, Array.from(coloured.attributes.normal.array));
  const differing = c.normals.filter((v, i) => Math.abs(v - c.recomputed[i]) > 1e-3).length;
  assert.ok(differing > c.normals.length / 4, `${differing} of ${c.normals.length} normal components differ from computed ones`);
  assert.deepEqual(c.uvs, Array.from(coloured.attributes.uv.array));
  assert.deepEqual(c.labels, Array.from(coloured.attributes.label.array));
  // Vertex colours on the model's copies of the loader's materials, white so
  // that the colours show as they are; the loader's own stay as they were.
  assert.deepEqual(c.vertexColors, [true, true, true]);
  assert.equal(c.white, 0xffffff);
  assert.deepEqual(c.loaderMaterials, [false, false, false]);
  assert.deepEqual(result.uncoloured, { same: true, color: false });
  assert.deepEqual(result.geometryView, {
    names: ['color', 'label', 'normal', 'position', 'uv'], held: true,
    color: { type: 'Uint8Array', itemSize: 3, normalized: true, capacity: 3 * n },
  });
  assert.deepEqual(result.pageMaterial, { same: true, vertexColors: false });
  assert.deepEqual(errors, []);
  await page.close();
});

// A 40 × 1 sheet of 40 × 10 quads facing the camera (z a little wavy),
// two triangles each, labelled 5 on the left half and -2 on the right;
// coded exactly in small chunks, for many levels. `labelled.kdm`, decoded
// in Node.
let labelled;
async function labelledStrip() {
  if (labelled) return labelled;
  const columns = 40, rows = 10, vertices = [], faces = [];
  for (let j = 0; j <= rows; ++j)
    for (let i = 0; i <= columns; ++i) vertices.push(`${i} ${j / rows} ${(0.05 * Math.sin(3 * i + 7 * j)).toFixed(6)}`);
  for (let j = 0; j < rows; ++j)
    for (let i = 0; i < columns; ++i) {
      const label = i < columns / 2 ? 5 : -2;
      const a = j * (columns + 1) + i, b = a + 1, c = a + columns + 2, d = a + columns + 1;
      faces.push(`3 ${a} ${b} ${c} ${label}`, `3 ${a} ${c} ${d} ${label}`);
    }
  const header = ['ply', 'format ascii 1.0', `element vertex ${vertices.length}`, 'property float x', 'property float y',
    'property float z', `element face ${faces.length}`, 'property list uchar int vertex_indices', 'property int label', 'end_header'];
  writeFileSync(join(models, 'labelled.ply'), [...header, ...vertices, ...faces].join('\n') + '\n');
  execFileSync(cli, ['encode', join(models, 'labelled.ply'), '-o', join(models, 'labelled.kdm'), '--exact', '--chunk-bytes', '256', '-q']);
  labelled = await decode(readFileSync(join(models, 'labelled.kdm')));
  return labelled;
}

test('simplex labels reach stats.model as the decoder gives them', async () => {
  const decoded = await labelledStrip();
  const { page, errors } = await openPage();
  const result = await page.evaluate(async () => {
    const loader = new KDMeshLoader();
    const group = await loader.loadAsync('models/labelled.kdm');
    const { labels, triangles } = group.userData.stats.model;
    loader.dispose();
    return { triangles: Array.from(labels.triangles), count: triangles.length / 3 };
  });
  assert.deepEqual(result, { triangles: Array.from(decoded.labels.triangles), count: decoded.triangles.length / 3 });
  assert.deepEqual(errors, []);
  await page.close();
});

test('labels become geometry groups: a material array draws each label with its own material', async () => {
  const decoded = await labelledStrip();
  const { page, errors } = await openPage();
  const result = await page.evaluate(async () => {
    const renderer = new THREE.WebGLRenderer({ preserveDrawingBuffer: true });
    renderer.setSize(160, 64, false);
    const camera = new THREE.OrthographicCamera(-0.5, 40.5, 1.1, -0.1, -10, 10);
    // Red for the lower label (-2, the right half), green for the higher (5, the left).
    const materials = [0xff0000, 0x00ff00].map((color) => new THREE.MeshBasicMaterial({ color, side: THREE.DoubleSide }));
    // Pixels of a frame whose red or green is the larger, in the left and the right half of the canvas.
    const halves = (scene) => {
      renderer.render(scene, camera);
      const gl = renderer.getContext();
      const pixels = new Uint8Array(160 * 64 * 4);
      gl.readPixels(0, 0, 160, 64, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
      const out = { left: { red: 0, green: 0 }, right: { red: 0, green: 0 } };
      for (let i = 0; i < pixels.length; i += 4) {
        const half = (i / 4) % 160 < 80 ? out.left : out.right;
        if (pixels[i] > 200 && pixels[i + 1] < 50) half.red += 1;
        if (pixels[i + 1] > 200 && pixels[i] < 50) half.green += 1;
      }
      return out;
    };
    const loader = new KDMeshLoader();
    const levels = [];
    const group = loader.loadProgressive('models/labelled.kdm?throttle=40', {
      materials,
      onRefine(model, stats) {
        const { geometry } = model.children[0];
        levels.push({
          groups: geometry.groups.map(({ start, count, materialIndex }) => ({ start, count, materialIndex })),
          expected: stats.model.groups.map(({ start, count, materialIndex }) => ({ start, count, materialIndex })),
          labels: Array.from(geometry.userData.labels), header: Array.from(stats.header.labels),
          modelLabels: stats.model.groups.map((g) => g.label),
          drawCount: geometry.drawRange.count, surface: stats.model.surface.length,
        });
      },
    });
    await group.userData.loaded;
    const arrayScene = new THREE.Scene().add(group);
    const drawn = halves(arrayScene);
    const mesh = group.children[0];
    const material = mesh.material;
    // The same geometry with one material draws whole, groups or not.
    mesh.material = materials[0];
    const single = halves(arrayScene);
    mesh.material = material;
    // loadGeometry: the groups on the one geometry, for the page's own Mesh.
    const geometry = loader.loadGeometry('models/labelled.kdm');
    await geometry.userData.loaded;
    const own = halves(new THREE.Scene().add(new THREE.Mesh(geometry, materials)));
    // A model without labels: no groups, and one material as before.
    const plain = await loader.loadAsync('models/fandisk.kdm');
    loader.dispose();
    renderer.dispose();
    return {
      levels, drawn, single, own, sameMaterial: material === materials,
      geometryGroups: geometry.groups.length, geometryLabels: Array.from(geometry.userData.labels),
      plain: { groups: plain.children[0].geometry.groups.length, labels: plain.children[0].geometry.userData.labels ?? null },
    };
  });
  assert.ok(result.levels.length >= 2, `levels: ${result.levels.length}`);
  for (const level of result.levels) {
    // Every level's groups are the worker's, and cover what is drawn.
    assert.deepEqual(level.groups, level.expected, JSON.stringify(level));
    // userData.labels is the header's table at every level, each group's label at its materialIndex.
    assert.deepEqual(level.labels, [-2, 5], JSON.stringify(level));
    assert.deepEqual(level.header, [-2, 5], JSON.stringify(level));
    assert.deepEqual(level.groups.map((g) => level.labels[g.materialIndex]), level.modelLabels, JSON.stringify(level));
    assert.equal(level.groups.reduce((sum, g) => sum + g.count, 0), level.drawCount, JSON.stringify(level));
    assert.equal(level.drawCount, level.surface);
  }
  const last = result.levels.at(-1);
  const counts = [-2, 5].map((label) => 3 * decoded.labels.triangles.filter((l) => l === label).length);
  assert.deepEqual(last.groups, [{ start: 0, count: counts[0], materialIndex: 0 }, { start: counts[0], count: counts[1], materialIndex: 1 }]);
  assert.equal(result.sameMaterial, true);
  // Label 5 (materialIndex 1, green) on the left, -2 (materialIndex 0, red) on the right.
  for (const drawn of [result.drawn, result.own]) {
    assert.ok(drawn.left.green > 1000 && drawn.left.red === 0, JSON.stringify(drawn));
    assert.ok(drawn.right.red > 1000 && drawn.right.green === 0, JSON.stringify(drawn));
  }
  assert.ok(result.single.left.red > 1000 && result.single.right.red > 1000 && result.single.left.green === 0, JSON.stringify(result.single));
  assert.equal(result.geometryGroups, 2);
  assert.deepEqual(result.geometryLabels, [-2, 5]);
  assert.deepEqual(result.plain, { groups: 0, labels: null });
  assert.deepEqual(errors, []);
  await page.close();
});
