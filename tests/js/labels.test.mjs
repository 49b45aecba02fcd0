// Simplex labels through the WebAssembly decoder: a torus whose triangles
// carry region labels (a PLY face property), encoded by the native CLI,
// decodes with every triangle's label, and every prefix snapshot has one
// label per listed simplex. The loader's worker (web/kdmesh-worker.js, run
// in a Node worker thread) orders every level's triangles by label into
// the groups that KDMeshLoader gives three.js. Run with `node --test tests/js/`.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';
import { Worker } from 'node:worker_threads';
import { decode, createDecoder } from 'kdmesh';
import { cli, labelledTorus, root, workDir, writeLabelledPly } from './fixtures.mjs';

// A block of n³ cubes, six tetrahedra each, labelled by the cube's layer
// along x (labels 7, -3, 7, -3, ...: two regions, the higher one first).
// The grid's points are moved a little (a regular grid codes in so few
// bytes that it makes few levels).
function labelledBlock(n = 6) {
  const m = n + 1, positions = [], tetrahedra = [], labels = [];
  const jitter = (a) => Math.fround(0.2 * Math.sin(a));
  for (let k = 0; k < m; ++k)
    for (let j = 0; j < m; ++j)
      for (let i = 0; i < m; ++i) positions.push(i + jitter(7 * i + 3 * j + k), j + jitter(i + 5 * j + 2 * k), k + jitter(2 * i + j + 11 * k));
  const id = (p) => (p[2] * m + p[1]) * m + p[0];
  const orders = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
  for (let k = 0; k < n; ++k)
    for (let j = 0; j < n; ++j)
      for (let i = 0; i < n; ++i)
        for (const order of orders) {
          const p = [i, j, k], t = [id(p)];
          for (const axis of order) {
            ++p[axis];
            t.push(id(p));
          }
          tetrahedra.push(...t);
          labels.push(i % 2 ? -3 : 7);
        }
  return { positions, tetrahedra, labels };
}

// Each triangle as its sorted vertex positions and its label.
function labelledTriangles({ positions, triangles, labels }) {
  const keys = [];
  for (let t = 0; t < triangles.length / 3; ++t) {
    const corners = [0, 1, 2].map((k) => Array.from(positions.slice(3 * triangles[3 * t + k], 3 * triangles[3 * t + k] + 3)).join(','));
    keys.push(`${corners.sort().join(' ')} ${labels[t]}`);
  }
  return keys.sort();
}

const shape = labelledTorus();
const ply = join(workDir, 'labelled-torus.ply');
writeLabelledPly(ply, shape);
const kdm = join(workDir, 'labelled-torus.kdm');
execFileSync(cli, ['encode', ply, '-o', kdm, '--exact', '--chunk-bytes', '256', '-q']);
const bytes = readFileSync(kdm);

test('a whole stream decodes with every triangle label', async () => {
  const model = await decode(bytes);
  assert.ok(model.labels instanceof Object);
  assert.ok(model.labels.triangles instanceof Int32Array);
  assert.equal(model.labels.edges.length, 0);
  assert.deepEqual(labelledTriangles({ ...model, labels: model.labels.triangles }), labelledTriangles(shape));
  const info = JSON.parse(execFileSync(cli, ['info', kdm, '--json'], { encoding: 'utf8' }));
  assert.equal(info.labels.distinct, 4);
});

// The input's distinct labels, ascending.
const distinctLabels = (labels) => [...new Set(labels)].sort((a, b) => a - b);

test('every prefix snapshot has one label per simplex, of the input labels', async () => {
  const decoder = await createDecoder();
  const inputLabels = new Set(shape.labels);
  for (let at = 0; at < bytes.length; at += 97) {
    decoder.push(bytes.subarray(at, at + 97));
    assert.equal(decoder.header?.labelled ?? true, true);
    const model = decoder.snapshot({ copy: false });
    if (!decoder.header) continue;
    // The label table arrives with the first chunk, before any snapshot has a simplex.
    if (decoder.progress.chunksApplied) assert.deepEqual(decoder.header.labels, Int32Array.from(distinctLabels(shape.labels)));
    assert.equal(model.labels.triangles.length, model.triangles.length / 3, `at ${at} bytes`);
    assert.equal(model.labels.edges.length, model.edges.length / 2, `at ${at} bytes`);
    for (const label of model.labels.triangles) assert.ok(inputLabels.has(label), `label ${label} at ${at} bytes`);
  }
  decoder.finish();
  decoder.dispose();
});

test('the header gives the label table once it has arrived, byte by byte', async () => {
  const decoder = await createDecoder();
  const seen = [];  // header.labels after each byte, from the header's last
  for (let at = 0; !decoder.header?.labels; ++at) {
    decoder.push(bytes.subarray(at, at + 1));
    if (decoder.header) seen.push(decoder.header.labels);
  }
  // null while the table's nine bytes (count, four labels, checksum) arrive.
  assert.ok(seen.length >= 10, `bytes from the header's last to the table's: ${seen.length}`);
  assert.ok(seen.slice(0, -1).every((labels) => labels === null));
  assert.ok(seen.at(-1) instanceof Int32Array);
  assert.deepEqual(Array.from(seen.at(-1)), [-1, 10, 20, 30]);
  assert.equal(decoder.progress.chunksApplied, 0);
  decoder.dispose();
});

test('streams without labels have no labels', async () => {
  const plain = join(workDir, 'unlabelled-torus.ply');
  writeLabelledPly(plain, shape, false);
  const out = join(workDir, 'unlabelled-torus.kdm');
  execFileSync(cli, ['encode', plain, '-o', out, '-q']);
  const decoder = await createDecoder();
  decoder.push(readFileSync(out));
  assert.equal(decoder.header.labelled, false);
  assert.deepEqual(decoder.header.labels, new Int32Array(0));
  assert.equal(decoder.snapshot().labels, undefined);
  decoder.dispose();
});

// Runs the loader's worker in a Node worker thread, with the two globals of
// a web worker it uses (postMessage, onmessage), streams `bytes` to it in
// pieces of `piece` bytes a few milliseconds apart, asks for every level
// as the page does, and resolves with the header and the levels it handed
// over.
// The levels the worker sends while `bytes` arrive, `piece` bytes every
// `pause` ms. The worker holds snapshots back while received bytes wait
// (kHandOverShare in web/kdmesh-worker.js): a small stream sent faster than
// a loaded machine decodes it comes in fewer levels.
async function workerLevels(bytes, { piece = 64, pause = 3 } = {}) {
  const script = pathToFileURL(join(root, 'web', 'kdmesh-worker.js')).href;
  const worker = new Worker(`
    const { parentPort } = require('node:worker_threads');
    globalThis.postMessage = (message, transfer) => parentPort.postMessage(message, transfer);
    globalThis.onmessage = null;  // the worker module sets it
    parentPort.on('message', (data) => globalThis.onmessage({ data }));
    import(${JSON.stringify(script)}).then(() => parentPort.postMessage({ type: 'ready' }));`, { eval: true });
  try {
    return await new Promise((resolve, reject) => {
      const levels = [];
      let header = null;
      worker.on('error', reject);
      worker.on('message', async (data) => {
        if (data.type === 'error') reject(new Error(`${data.code}: ${data.message}`));
        if (data.type === 'header') header = data.header;
        if (data.type === 'snapshot') {
          if (!header) reject(new Error('a level came before the header'));
          levels.push(data.model);
          if (data.model.complete) resolve({ header, levels });
          else worker.postMessage({ type: 'next' });
        }
        if (data.type !== 'ready') return;
        worker.postMessage({ type: 'start' });  // no module: the worker compiles the embedded decoder
        for (let at = 0; at < bytes.length; at += piece) {
          worker.postMessage({ type: 'bytes', bytes: bytes.slice(at, at + piece) });
          // Until the header comes back the decoder may still be compiling.
          await new Promise((wake) => setTimeout(wake, header ? pause : 50));
        }
        worker.postMessage({ type: 'end' });
      });
    });
  } finally {
    await worker.terminate();
  }
}

// Checks a level's surface index and groups against its lists and the
// stream's label table (the header's labels): the groups cover the index
// exactly, one after the other, one per distinct label of the level in
// ascending order with its index in the table as materialIndex (not its
// rank among the level's labels), and each holds exactly the triangles
// drawn with its label (the triangles with theirs, then the boundary of the
// tetrahedra with its tetrahedron's), in their order there.
function assertLabelGroups(model, table, what) {
  const drawn = [...model.triangles, ...model.boundary];
  assert.equal(model.surface.length, drawn.length, `${what}: surface length`);
  if (!model.labels) {
    assert.deepEqual(model.groups, [], `${what}: no groups without labels`);
    assert.deepEqual(Array.from(model.surface), drawn, `${what}: the surface is the triangles as decoded`);
    return;
  }
  // A boundary face's label: that of the one tetrahedron it belongs to.
  const faceLabels = new Map();
  const key = (a, b, c) => [a, b, c].sort((x, y) => x - y).join(',');
  const faces = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];
  for (let t = 0; t < model.tetrahedra.length / 4; ++t)
    for (const face of faces) faceLabels.set(key(...face.map((c) => model.tetrahedra[4 * t + c])), model.labels.tetrahedra[t]);
  const triangleCount = model.triangles.length / 3;
  const labelOf = (t) => (t < triangleCount ? model.labels.triangles[t] : faceLabels.get(key(...drawn.slice(3 * t, 3 * t + 3))));
  const byLabel = new Map();
  for (let t = 0; t < drawn.length / 3; ++t) {
    const label = labelOf(t);
    if (!byLabel.has(label)) byLabel.set(label, []);
    byLabel.get(label).push(...drawn.slice(3 * t, 3 * t + 3));
  }
  const labels = [...byLabel.keys()].sort((a, b) => a - b);
  assert.deepEqual(model.groups.map((g) => g.label), labels, `${what}: one group per label, ascending`);
  let end = 0;
  model.groups.forEach((group) => {
    assert.ok(table.includes(group.label), `${what}: label ${group.label} in the table`);
    assert.equal(group.materialIndex, table.indexOf(group.label), `${what}: materialIndex of label ${group.label}`);
    assert.equal(group.start, end, `${what}: group of label ${group.label} starts where the last ended`);
    assert.deepEqual(Array.from(model.surface.subarray(group.start, group.start + group.count)), byLabel.get(group.label),
      `${what}: the triangles of label ${group.label}`);
    end += group.count;
  });
  assert.equal(end, model.surface.length, `${what}: the groups cover the surface`);
}

// Triangles per label, as a sorted list of [label, count].
const labelCounts = (labels) => [...labels.reduce((m, l) => m.set(l, (m.get(l) ?? 0) + 1), new Map())].sort((a, b) => a[0] - b[0]);

test('the loader\'s worker orders every level\'s triangles by label into groups', async () => {
  const { header, levels } = await workerLevels(bytes);
  assert.deepEqual(header.labels, Int32Array.from([-1, 10, 20, 30]));
  assert.ok(levels.length >= 5, `levels: ${levels.length}`);
  const counts = new Set();
  for (const [i, model] of levels.entries()) {
    assertLabelGroups(model, header.labels, `level ${i}`);
    // As many triangles per group as the level's labels say.
    assert.deepEqual(model.groups.map((g) => [g.label, g.count / 3]), labelCounts(model.labels.triangles), `level ${i}`);
    counts.add(model.groups.length);
  }
  assert.ok(counts.size > 1 || levels[0].groups.length === 4, 'coarse levels show fewer labels, or all four from the start');
  // The last level's groups count the whole model's labels.
  const whole = await decode(bytes);
  assert.deepEqual(levels.at(-1).groups.map((g) => [g.label, g.count / 3]), labelCounts(whole.labels.triangles));
  assert.deepEqual(levels.at(-1).groups.map((g) => g.label), [-1, 10, 20, 30]);
});

test('a label absent from coarse levels shifts no other label\'s materialIndex', async () => {
  // The torus with one quad (the 101st, which the first chunks leave out)
  // labelled -50, below every other label: with ranks among a level's
  // labels, each other label's would grow by one once -50 first shows.
  const spotted = labelledTorus();
  spotted.labels[200] = spotted.labels[201] = -50;
  const path = join(workDir, 'spotted-torus.ply');
  writeLabelledPly(path, spotted);
  const out = join(workDir, 'spotted-torus.kdm');
  execFileSync(cli, ['encode', path, '-o', out, '--exact', '--chunk-bytes', '256', '-q']);
  const { header, levels } = await workerLevels(readFileSync(out));
  assert.deepEqual(Array.from(header.labels), [-50, -1, 10, 20, 30]);
  const shows = levels.map((model) => model.groups.some((g) => g.label === -50));
  assert.equal(shows[0], false, 'the coarsest level lacks label -50');
  assert.equal(shows.at(-1), true);
  for (const [i, model] of levels.entries()) assertLabelGroups(model, header.labels, `level ${i}`);
});

test('the boundary of labelled tetrahedra is grouped by the tetrahedra\'s labels', async () => {
  const block = labelledBlock();
  const path = join(workDir, 'labelled-block.ply');
  writeLabelledPly(path, block);
  const out = join(workDir, 'labelled-block.kdm');
  execFileSync(cli, ['encode', path, '-o', out, '--chunk-bytes', '256', '-q']);
  // 2.6 kB: paced so that the worker decodes each piece before the next.
  const { header, levels } = await workerLevels(readFileSync(out), { pause: 25 });
  assert.deepEqual(Array.from(header.labels), [-3, 7]);
  assert.ok(levels.length >= 3, `levels: ${levels.length}`);
  // Coarse levels may list triangles besides tetrahedra (collapsed ones).
  for (const [i, model] of levels.entries()) assertLabelGroups(model, header.labels, `level ${i}`);
  const last = levels.at(-1);
  assert.equal(last.triangles.length, 0);
  assert.deepEqual(last.groups.map((g) => g.label), [-3, 7]);
  // 6 × 6 squares on each of the six sides, two triangles each.
  assert.equal(last.surface.length, 3 * 6 * 36 * 2);
});

test('the worker gives streams without labels no groups', async () => {
  const plain = join(workDir, 'unlabelled-torus.ply');
  writeLabelledPly(plain, shape, false);
  const out = join(workDir, 'unlabelled-torus-worker.kdm');
  execFileSync(cli, ['encode', plain, '-o', out, '--chunk-bytes', '256', '-q']);
  const { header, levels } = await workerLevels(readFileSync(out));
  assert.deepEqual(header.labels, new Int32Array(0));
  assert.ok(levels.length >= 3, `levels: ${levels.length}`);
  for (const [i, model] of levels.entries()) assertLabelGroups(model, header.labels, `level ${i}`);
});
