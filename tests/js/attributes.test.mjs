// Vertex attributes through the WebAssembly decoder: PLY files with
// colours, normals, texture coordinates and other properties, encoded by
// the native CLI, decode whole and in pieces to the native decoder's
// attributes bit for bit, and every prefix gives each vertex an input
// vertex's values. Run with `node --test tests/js/`.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { decode, createDecoder } from 'kdmesh';
import { cli, colouredCloud, colouredTorus, nativeDecode, workDir, writePly } from './fixtures.mjs';

const typeNames = { uchar: 'uint8', short: 'int16', float: 'float32' };
const arrayTypes = { uint8: Uint8Array, int16: Int16Array, float32: Float32Array };

// Each shape encoded quantized and exact, in small chunks (many levels).
const shapes = { torus: colouredTorus(), cloud: colouredCloud() };
const fixtures = {};
for (const [name, shape] of Object.entries(shapes)) {
  const ply = join(workDir, `${name}-attributes.ply`);
  writePly(ply, shape);
  for (const mode of [['--bits', '12'], ['--exact']]) {
    const kdm = join(workDir, `${name}-attributes${mode[0]}.kdm`);
    execFileSync(cli, ['encode', ply, '-o', kdm, '--chunk-bytes', '256', '-q', ...mode]);
    fixtures[`${name} ${mode.join(' ')}`] = { shape, kdm, bytes: readFileSync(kdm) };
  }
}

// One vertex's values of every attribute, as a string.
function vertexKey(attributes, vertex) {
  return attributes.map(({ array, itemSize }) => Array.from(array.subarray(vertex * itemSize, (vertex + 1) * itemSize)).join(' ')).join('|');
}

// The input's vertices, as vertexKey() gives them, in the stream's attribute order.
function inputKeys(shape) {
  const attributes = shape.attributes.map(({ type, properties, values }) =>
    ({ array: arrayTypes[typeNames[type]].from(values), itemSize: properties.length }));
  const keys = new Set();
  for (let v = 0; v < shape.positions.length / 3; ++v) keys.add(vertexKey(attributes, v));
  return keys;
}

// The native decode's vertex properties of `shape`'s attributes, each as
// { array, itemSize } of the attribute's type.
function nativeAttributes(native, shape) {
  const out = {};
  for (const { name, type, properties } of shape.attributes) {
    const columns = properties.map((property) => native.properties[property]);
    const array = new arrayTypes[typeNames[type]](columns[0].length * columns.length);
    columns.forEach((column, k) => column.forEach((value, v) => (array[v * columns.length + k] = value)));
    out[name] = { array, itemSize: columns.length };
  }
  return out;
}

const bits = (array) => new Uint8Array(array.buffer, array.byteOffset, array.byteLength);

function assertSameAttributes(wasm, native, what) {
  assert.deepEqual(Object.keys(wasm), Object.keys(native), `${what}: names`);
  for (const [name, { array, itemSize }] of Object.entries(native)) {
    assert.equal(wasm[name].itemSize, itemSize, `${what}: ${name} item size`);
    assert.equal(wasm[name].array.constructor, array.constructor, `${what}: ${name} type`);
    assert.deepEqual(bits(wasm[name].array), bits(array), `${what}: ${name} bits`);
  }
}

// Lengths, types and values of a snapshot's attributes: every vertex has
// the values of one input vertex. The attributes' table comes before the
// first chunk: until it has arrived (`applied` false), a snapshot may have
// none.
function assertValidAttributes(model, shape, keys, applied, what) {
  const names = Object.keys(model.attributes);
  if (applied || names.length) assert.deepEqual(names, shape.attributes.map((a) => a.name), `${what}: names`);
  for (const { name, type, properties } of shape.attributes) {
    const attribute = model.attributes[name];
    if (!attribute) continue;
    assert.equal(attribute.itemSize, properties.length, `${what}: ${name} item size`);
    assert.ok(attribute.array instanceof arrayTypes[typeNames[type]], `${what}: ${name} type`);
    assert.equal(attribute.array.length, model.vertexCount * properties.length, `${what}: ${name} length`);
  }
  if (!names.length) return;
  const attributes = shape.attributes.map((a) => model.attributes[a.name]);
  for (let v = 0; v < model.vertexCount; ++v)
    assert.ok(keys.has(vertexKey(attributes, v)), `${what}: vertex ${v} has values no input vertex has`);
}

test('kdmesh info lists the attributes, and the header counts them', async () => {
  const { kdm, bytes } = fixtures['torus --bits 12'];
  const info = JSON.parse(execFileSync(cli, ['info', kdm, '--json'], { encoding: 'utf8' }));
  assert.deepEqual(info.attributes.map(({ name, type, components }) => [name, type, components]),
    [['color', 'uint8', 3], ['normal', 'float32', 3], ['uv', 'float32', 2], ['label', 'int16', 1]]);
  const decoder = await createDecoder();
  decoder.push(bytes.subarray(0, 200));
  assert.equal(decoder.header.attributeCount, 4);
  decoder.dispose();
});

test('whole streams: every attribute equals the native decode bit for bit', async () => {
  for (const [what, { shape, kdm, bytes }] of Object.entries(fixtures)) {
    const model = await decode(bytes);
    assert.equal(model.vertexCount, shape.positions.length / 3, `${what}: every input vertex`);
    assertSameAttributes(model.attributes, nativeAttributes(nativeDecode(kdm), shape), what);
    assertValidAttributes(model, shape, inputKeys(shape), true, what);
  }
});

test('in pieces: every prefix snapshot has whole attributes of input values, cuts equal the native decode', async () => {
  let seed = 777;
  const random = () => (seed = (Math.imul(seed, 1103515245) + 12345) >>> 0) / 2 ** 32;
  for (const [what, { shape, kdm, bytes }] of Object.entries(fixtures)) {
    const keys = inputKeys(shape);
    const decoder = await createDecoder();
    let compared = 0;
    for (let at = 0; at < bytes.length;) {
      const size = random() < 0.2 ? 1 : 1 + Math.floor(random() * 400);
      const applied = decoder.push(bytes.subarray(at, at + size)).chunksApplied > 0;
      at = Math.min(bytes.length, at + size);
      const model = decoder.snapshot({ copy: false });
      assertValidAttributes(model, shape, keys, applied, `${what} at ${at} bytes`);
      if (applied && random() < 0.1) {
        assertSameAttributes(model.attributes, nativeAttributes(nativeDecode(kdm, at), shape), `${what} at ${at} bytes`);
        ++compared;
      }
    }
    decoder.finish();
    const whole = decoder.snapshot();
    decoder.dispose();
    assert.equal(whole.complete, true);
    assert.ok(compared >= 2, `${what}: ${compared} prefixes compared with the native decode`);
    assertSameAttributes(whole.attributes, nativeAttributes(nativeDecode(kdm), shape), `${what} whole`);
  }
});

test('normals coded after the positions: prefixes show unit normals as the native decoder does', async () => {
  const shape = shapes.torus;
  const ply = join(workDir, 'torus-normals.ply');
  writePly(ply, shape);
  const kdm = join(workDir, 'torus-normals.kdm');
  execFileSync(cli, ['encode', ply, '-o', kdm, '--bits', '12', '--normal-bits', '10', '--chunk-bytes', '256', '-q']);
  const bytes = readFileSync(kdm);
  const decoder = await createDecoder();
  let compared = 0;
  for (let at = 0; at < bytes.length;) {
    const end = Math.min(bytes.length, at + 700);
    const applied = decoder.push(bytes.subarray(at, end)).chunksApplied > 0;
    at = end;
    const model = decoder.snapshot();
    const normal = model.attributes.normal;
    if (!normal) continue;
    assert.equal(normal.coding, 'geometric-octahedral');
    for (let v = 0; v < model.vertexCount; ++v) {
      const [x, y, z] = normal.array.subarray(3 * v, 3 * v + 3);
      assert.ok(Math.abs(x * x + y * y + z * z - 1) < 1e-5, `vertex ${v} at ${at} bytes: a unit normal`);
    }
    if (applied) {
      assertSameAttributes(model.attributes, nativeAttributes(nativeDecode(kdm, at), shape), `at ${at} bytes`);
      ++compared;
    }
  }
  decoder.finish();
  decoder.dispose();
  assert.ok(compared >= 3, `${compared} prefixes compared`);
});

test('each attribute says how the stream codes it, as kdmesh info does, at every prefix', async () => {
  const codings = (attributes) => Object.entries(attributes).map(([name, { coding, codingBits }]) => [name, coding, codingBits]);
  const cases = [
    [shapes.torus, ['--attr-bits', '12', '--normal-bits', '10'],
      [['color', 'exact', 0], ['normal', 'geometric-octahedral', 10], ['uv', 'uniform', 12], ['label', 'exact', 0]]],
    [shapes.torus, ['--attr-bits', '7'],  // without --normal-bits, normals are quantized like any float32
      [['color', 'exact', 0], ['normal', 'uniform', 7], ['uv', 'uniform', 7], ['label', 'exact', 0]]],
    [shapes.torus, ['--normal-bits', '8'],
      [['color', 'exact', 0], ['normal', 'geometric-octahedral', 8], ['uv', 'exact', 0], ['label', 'exact', 0]]],
    [shapes.cloud, ['--normal-bits', '8'], [['color', 'exact', 0], ['intensity', 'exact', 0]]],
    [shapes.cloud, ['--attr-bits', '9'], [['color', 'exact', 0], ['intensity', 'uniform', 9]]],
  ];
  for (const [shape, options, expected] of cases) {
    const ply = join(workDir, 'coding.ply');
    writePly(ply, shape);
    const kdm = join(workDir, 'coding.kdm');
    execFileSync(cli, ['encode', ply, '-o', kdm, '--bits', '12', '--chunk-bytes', '256', '-q', ...options]);
    const what = `${shape === shapes.torus ? 'torus' : 'cloud'} ${options.join(' ')}`;
    const info = JSON.parse(execFileSync(cli, ['info', kdm, '--json'], { encoding: 'utf8' }));
    assert.deepEqual(info.attributes.map(({ name, coding, codingBits }) => [name, coding, codingBits]), expected, `${what}: info`);
    const bytes = readFileSync(kdm);
    assert.deepEqual(codings((await decode(bytes)).attributes), expected, `${what}: decode()`);
    const decoder = await createDecoder();
    for (let at = 0; at < bytes.length; at += 300) {
      decoder.push(bytes.subarray(at, at + 300));
      const { attributes } = decoder.snapshot({ copy: false });
      if (Object.keys(attributes).length) assert.deepEqual(codings(attributes), expected, `${what} at ${at} bytes`);
    }
    decoder.dispose();
  }
});
