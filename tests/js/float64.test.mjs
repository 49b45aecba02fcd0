// Float64 streams through the WebAssembly decoder: a PLY with double
// coordinates below float32 precision, encoded exactly by the native CLI,
// decodes with every double in `positions64` (and their float32 roundings
// in `positions`); a prefix has positions64 too, and float32 streams have
// none. Run with `node --test tests/js/`.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { decode, createDecoder } from 'kdmesh';
import { cli, workDir } from './fixtures.mjs';

// A grid of points whose doubles float32 does not hold, in an ascii PLY.
const doubles = [];
for (let i = 0; i < 300; ++i) doubles.push(i * 0.1, Math.sqrt(i), -1 / (i + 3));
const ply = join(workDir, 'doubles.ply');
writeFileSync(ply, ['ply', 'format ascii 1.0', `element vertex ${doubles.length / 3}`, 'property double x',
  'property double y', 'property double z', 'end_header',
  ...Array.from({ length: doubles.length / 3 }, (_, i) => doubles.slice(3 * i, 3 * i + 3).join(' '))].join('\n') + '\n');
const kdm = join(workDir, 'doubles.kdm');
execFileSync(cli, ['encode', ply, '-o', kdm, '--exact', '--chunk-bytes', '256', '-q']);
const bytes = readFileSync(kdm);

const sortedTriples = (values) =>
  Array.from({ length: values.length / 3 }, (_, i) => Array.from(values.slice(3 * i, 3 * i + 3)).join(',')).sort();

test('a float64 stream decodes to every double', async () => {
  const model = await decode(bytes);
  assert.ok(model.positions64 instanceof Float64Array);
  assert.deepEqual(sortedTriples(model.positions64), sortedTriples(doubles));
  assert.deepEqual(sortedTriples(model.positions), sortedTriples(doubles.map(Math.fround)));
});

test('a prefix of a float64 stream has positions64 of its vertices', async () => {
  const decoder = await createDecoder();
  decoder.push(bytes.subarray(0, Math.floor(bytes.length / 2)));
  const model = decoder.snapshot();
  assert.equal(model.positions64.length, 3 * model.vertexCount);
  decoder.dispose();
});

test('float32 streams have no positions64', async () => {
  const floats = join(workDir, 'floats.kdm');
  execFileSync(cli, ['encode', ply, '-o', floats, '-q']);
  const model = await decode(readFileSync(floats));
  assert.equal(model.positions64, undefined);
});
