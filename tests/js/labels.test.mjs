// Simplex labels through the WebAssembly decoder: a torus whose triangles
// carry region labels (a PLY face property), encoded by the native CLI,
// decodes with every triangle's label, and every prefix snapshot has one
// label per listed simplex. Run with `node --test tests/js/`.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { decode, createDecoder } from 'kdmesh';
import { cli, workDir } from './fixtures.mjs';

// A torus of rows × columns quads, two triangles each, labelled by the
// quarter of the ring they lie in (labels -1, 10, 20, 30).
function labelledTorus(rows = 20, columns = 36) {
  const positions = [], triangles = [], labels = [];
  for (let j = 0; j < rows; ++j)
    for (let i = 0; i < columns; ++i) {
      const a = (2 * Math.PI * i) / columns, b = (2 * Math.PI * j) / rows;
      positions.push(Math.fround((3 + Math.cos(b)) * Math.cos(a)), Math.fround((3 + Math.cos(b)) * Math.sin(a)),
        Math.fround(Math.sin(b)));
    }
  const id = (i, j) => (j % rows) * columns + (i % columns);
  const regions = [-1, 10, 20, 30];
  for (let j = 0; j < rows; ++j)
    for (let i = 0; i < columns; ++i) {
      triangles.push(id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1));
      const region = regions[Math.floor((4 * i) / columns)];
      labels.push(region, region);
    }
  return { positions, triangles, labels };
}

// The shape as an ascii PLY file, with its labels as a face property or without.
function writeLabelledPly(path, { positions, triangles, labels }, withLabels = true) {
  const lines = ['ply', 'format ascii 1.0', `element vertex ${positions.length / 3}`, 'property float x',
    'property float y', 'property float z', `element face ${triangles.length / 3}`,
    'property list uchar int vertex_indices', ...(withLabels ? ['property int label'] : []), 'end_header'];
  for (let i = 0; i < positions.length; i += 3) lines.push(positions.slice(i, i + 3).join(' '));
  for (let t = 0; t < labels.length; ++t)
    lines.push(`3 ${triangles.slice(3 * t, 3 * t + 3).join(' ')}${withLabels ? ` ${labels[t]}` : ''}`);
  writeFileSync(path, lines.join('\n') + '\n');
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

test('every prefix snapshot has one label per simplex, of the input labels', async () => {
  const decoder = await createDecoder();
  const inputLabels = new Set(shape.labels);
  for (let at = 0; at < bytes.length; at += 97) {
    decoder.push(bytes.subarray(at, at + 97));
    assert.equal(decoder.header?.labelled ?? true, true);
    const model = decoder.snapshot({ copy: false });
    if (!decoder.header) continue;
    assert.equal(model.labels.triangles.length, model.triangles.length / 3, `at ${at} bytes`);
    assert.equal(model.labels.edges.length, model.edges.length / 2, `at ${at} bytes`);
    for (const label of model.labels.triangles) assert.ok(inputLabels.has(label), `label ${label} at ${at} bytes`);
  }
  decoder.finish();
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
  assert.equal(decoder.snapshot().labels, undefined);
  decoder.dispose();
});
