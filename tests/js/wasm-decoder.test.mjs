// The WebAssembly decoder against the native one, streaming, errors and
// memory. Run with `node --test tests/js/`.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { decode, createDecoder, KdmeshError, memoryInUse } from 'kdmesh';
import { execFileSync } from 'node:child_process';
import { readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { cli, makeFixtures, nativeDecode, workDir } from './fixtures.mjs';

const fixtures = makeFixtures();

function isolatedVertices(model, vertexCount) {
  const used = new Uint8Array(vertexCount);
  for (const list of [model.edges, model.triangles, model.tetrahedra]) for (const v of list) used[v] = 1;
  const isolated = [];
  for (let v = 0; v < vertexCount; ++v) if (!used[v]) isolated.push(v);
  return isolated;
}

function assertSameModel(wasm, native, what) {
  assert.equal(wasm.vertexCount, native.positions.length / 3, `${what}: vertex count`);
  assert.deepEqual(new Uint32Array(wasm.positions.buffer.slice(0)), new Uint32Array(native.positions.buffer.slice(0)), `${what}: position bits`);
  assert.deepEqual(Array.from(wasm.edges), native.edges, `${what}: edges`);
  assert.deepEqual(Array.from(wasm.triangles), native.triangles, `${what}: triangles`);
  assert.deepEqual(Array.from(wasm.tetrahedra), native.tetrahedra, `${what}: tetrahedra`);
  if (native.edges.length + native.triangles.length + native.tetrahedra.length > 0)
    assert.deepEqual(Array.from(wasm.points), isolatedVertices(native, wasm.vertexCount), `${what}: isolated points`);
}

test('whole streams decode exactly as the native decoder does', async () => {
  // push() hands the decoder 16 KiB per call: some stream spans several.
  assert.ok(Object.values(fixtures).some(({ bytes }) => bytes.length > 2 * 16384));
  for (const [name, { kdm, bytes }] of Object.entries(fixtures)) {
    const model = await decode(bytes);
    assert.equal(model.complete, true);
    assertSameModel(model, nativeDecode(kdm), name);
  }
});

test('the header says whether a stream is coded for fast decoding', async () => {
  for (const [name, expected] of [['torus-12', false], ['torus-fast', true], ['tetrahedra-fast', true]]) {
    const decoder = await createDecoder();
    decoder.push(fixtures[name].bytes.subarray(0, 200));
    assert.equal(decoder.header.fastDecode, expected, name);
    decoder.dispose();
  }
});

test('prefixes decode exactly as the native decoder does', async () => {
  for (const name of ['torus-12', 'tetrahedra-exact', 'mixed-12', 'cloud-12', 'triceratops.off', 'torus-fast', 'tetrahedra-fast']) {
    const { kdm, bytes } = fixtures[name];
    for (const fraction of [0.02, 0.1, 0.35, 0.7]) {
      const cut = Math.max(100, Math.floor(bytes.length * fraction));
      const decoder = await createDecoder();
      decoder.push(bytes.subarray(0, cut));
      const model = decoder.snapshot();
      decoder.dispose();
      assert.equal(model.complete, false);
      assertSameModel(model, nativeDecode(kdm, cut), `${name} at ${cut} bytes`);
    }
  }
});

test('streaming in random pieces, down to single bytes, gives the snapshots of the same prefixes', async () => {
  let seed = 12345;
  const random = () => (seed = (Math.imul(seed, 1103515245) + 12345) >>> 0) / 2 ** 32;
  for (const name of ['torus-12', 'mixed-exact', 'cloud-12']) {
    const { bytes } = fixtures[name];
    const streaming = await createDecoder();
    for (let at = 0; at < bytes.length;) {
      const size = random() < 0.3 ? 1 : 1 + Math.floor(random() * 700);
      streaming.push(bytes.subarray(at, at + size));
      at = Math.min(bytes.length, at + size);
      if (random() < 0.15 || at === bytes.length) {
        const once = await createDecoder();
        once.push(bytes.subarray(0, at));
        assert.deepEqual(streaming.snapshot(), once.snapshot(), `${name} at ${at} bytes`);
        assert.deepEqual(streaming.progress, once.progress);
        once.dispose();
      }
    }
    streaming.finish();
    streaming.dispose();
  }
});

test('one byte at a time works', async () => {
  const { bytes } = fixtures['mixed-12'];
  const decoder = await createDecoder();
  for (let i = 0; i < bytes.length; ++i) decoder.push(bytes.subarray(i, i + 1));
  decoder.finish();
  assert.deepEqual(decoder.snapshot(), await decode(bytes));
  decoder.dispose();
});

async function rejection(bytes, options) {
  try {
    await decode(bytes, options);
  } catch (error) {
    assert.ok(error instanceof KdmeshError, `${error}`);
    assert.ok(error.message.length > 0);
    return error.code;
  }
  assert.fail('decoding should have failed');
}

test('bad streams reject with the documented codes', async () => {
  const { bytes } = fixtures['torus-12'];
  const copy = () => Uint8Array.from(bytes);
  const badMagic = copy();
  badMagic[1] ^= 0xff;
  assert.equal(await rejection(badMagic), 'bad-magic');
  const badHeader = copy();
  badHeader[20] ^= 1;
  assert.equal(await rejection(badHeader), 'corrupt-header');
  const badChunk = copy();
  badChunk[bytes.length - 3] ^= 0x10;
  assert.equal(await rejection(badChunk), 'corrupt-chunk');
  assert.equal(await rejection(bytes.subarray(0, bytes.length - 1)), 'truncated');
  assert.equal(await rejection(Buffer.concat([bytes, Buffer.from([0])])), 'trailing-bytes');
  assert.equal(await rejection(bytes, { limits: { maxVertices: 10 } }), 'limit-exceeded');
  assert.equal(await rejection(new Uint8Array(0)), 'truncated');
});

test('a failed decoder stays failed and can still be disposed; a disposed one refuses work', async () => {
  const { bytes } = fixtures['cloud-12'];
  const decoder = await createDecoder();
  const bad = Uint8Array.from(bytes);
  bad[0] = 0;
  assert.throws(() => decoder.push(bad), (e) => e.code === 'bad-magic');
  assert.throws(() => decoder.push(bytes), (e) => e.code === 'bad-magic');
  decoder.dispose();
  decoder.dispose();
  assert.throws(() => decoder.snapshot(), (e) => e.code === 'disposed');
});

test('views without copies read the same data', async () => {
  const { bytes } = fixtures['torus-12'];
  const decoder = await createDecoder();
  decoder.push(bytes);
  // Views are read before the next call on the decoder, which may reuse
  // their memory.
  const view = decoder.snapshot({ copy: false });
  const viewed = { positions: Array.from(view.positions), triangles: Array.from(view.triangles) };
  const copied = decoder.snapshot();
  assert.deepEqual(viewed.triangles, Array.from(copied.triangles));
  assert.deepEqual(viewed.positions, Array.from(copied.positions));
  assert.equal(decoder.parents().length, copied.vertexCount);
  decoder.dispose();
});

test('memory stays flat across 1,000 decode/dispose cycles', async () => {
  const { bytes } = fixtures['torus-12'];
  for (let i = 0; i < 20; ++i) await decode(bytes);
  const before = await memoryInUse();
  for (let i = 0; i < 1000; ++i) {
    const decoder = await createDecoder();
    decoder.push(bytes.subarray(0, bytes.length >> 1));
    decoder.snapshot({ copy: false });
    decoder.dispose();
    await decode(bytes);
  }
  assert.equal(await memoryInUse(), before);
});

function crc32(bytes) {
  let crc = 0xffffffff;
  for (const byte of bytes) {
    crc ^= byte;
    for (let k = 0; k < 8; ++k) crc = (crc >>> 1) ^ (0xedb88320 & -(crc & 1));
  }
  return (crc ^ 0xffffffff) >>> 0;
}

// The header's fields (docs/FORMAT.md): after the 10 fixed bytes, varints for
// the vertex count, four simplex counts, three grid extents, the body size
// and the chunk count, then the quantization parameters and a CRC-32.
function readVarints(bytes, at, count) {
  const values = [];
  for (let i = 0; i < count; ++i) {
    let value = 0n, shift = 0n, byte;
    do {
      byte = bytes[at++];
      value |= BigInt(byte & 0x7f) << shift;
      shift += 7n;
    } while (byte & 0x80);
    values.push(value);
  }
  return { values, at };
}

function writeVarint(out, value) {
  for (value = BigInt(value); value >= 0x80n; value >>= 7n) out.push(Number(value & 0x7fn) | 0x80);
  out.push(Number(value));
}

function forgeHeader(honest, change) {
  const size = honest[6];
  const { values, at } = readVarints(honest, 10, 10);
  change(values);
  const out = [...honest.subarray(0, 10)];
  for (const value of values) writeVarint(out, value);
  out.push(...honest.subarray(at, size - 4));
  out[6] = out.length + 4;
  const header = Uint8Array.from([...out, 0, 0, 0, 0]);
  new DataView(header.buffer).setUint32(out.length, crc32(header.subarray(0, out.length)), true);
  return header;
}

test('a hostile header announcing 10^8 vertices costs no memory up front', async () => {
  const { bytes } = fixtures['torus-12'];
  const honestSize = bytes[6];
  const header = forgeHeader(bytes, (values) => {
    values[0] = 100_000_000n;      // vertex count
    values[3] = 200_000_000n;      // triangles
    values[8] = 1n << 40n;         // body bytes
  });
  const hostile = Uint8Array.from([...header, ...bytes.subarray(honestSize, 140)]);
  // A decoder's model state is about 1 MB whatever the header says; what a
  // hostile header must not add is memory in proportion to its counts, so
  // it is measured against the honest header of the same bytes.
  const heapAfterHeader = async (header) => {
    const before = await memoryInUse();
    const decoder = await createDecoder();
    decoder.push(header);
    const grown = (await memoryInUse()) - before;
    const { vertexCount } = decoder.header;
    decoder.dispose();
    return { grown, vertexCount };
  };
  const honest = await heapAfterHeader(bytes.subarray(0, 140));
  const forged = await heapAfterHeader(hostile);
  assert.equal(forged.vertexCount, 100_000_000);
  assert.ok(forged.grown <= honest.grown + (16 << 10),
            `heap grew by ${forged.grown} bytes against ${honest.grown} for the honest header`);
  assert.ok(forged.grown < 4 << 20, `heap grew by ${forged.grown} bytes`);
});

test('a download that drops mid-chunk keeps the last whole chunk, reports truncation, and a retry completes', async () => {
  const { bytes } = fixtures['torus-12'];
  const decoder = await createDecoder();
  const cut = Math.floor(bytes.length * 0.6);
  decoder.push(bytes.subarray(0, cut));
  const { bytesConsumed, chunksApplied } = decoder.progress;
  assert.ok(bytesConsumed < cut && chunksApplied > 0, 'the cut falls inside a chunk');
  const lastGood = decoder.snapshot();
  assert.throws(() => decoder.finish(), (e) => e.code === 'truncated');
  const atBoundary = await createDecoder();
  atBoundary.push(bytes.subarray(0, bytesConsumed));
  assert.deepEqual(lastGood, atBoundary.snapshot());
  atBoundary.dispose();
  decoder.dispose();
  const retry = await decode(bytes);
  assert.equal(retry.complete, true);
});

test('a stream announcing more vertices per byte than the limit is refused unless the limit is raised', async () => {
  // 200,000 identical points code in a few dozen bytes: honest, but past the
  // default of 1,024 vertices per byte, the bound that stops decompression bombs.
  const input = join(workDir, 'coincident.xyz');
  writeFileSync(input, '0.5 0.25 1\n'.repeat(200_000));
  const kdm = join(workDir, 'coincident.kdm');
  execFileSync(cli, ['encode', input, '-o', kdm, '-q']);
  const bytes = readFileSync(kdm);
  assert.ok(bytes.length * 1024 < 200_000, `${bytes.length} bytes`);
  await assert.rejects(decode(bytes), (e) => e instanceof KdmeshError && e.code === 'limit-exceeded');
  const raised = await decode(bytes, { limits: { maxVerticesPerByte: 1 << 20 } });
  assert.equal(raised.positions.length, 3 * 200_000);
});

test('limits and pushed bytes of the wrong kind are errors, not made-up values', async () => {
  for (const limits of [{ maxVertices: -1 }, { maxVertices: 2 ** 32 }, { maxChunkBytes: 1.5 }, { maxSimplices: '9' },
                        { maxVerticesPerByte: 0 }])
    await assert.rejects(createDecoder({ limits }), RangeError, JSON.stringify(limits));
  await assert.rejects(createDecoder({ limits: { maxVertex: 5 } }), TypeError);
  await assert.rejects(createDecoder({ limits: 5 }), TypeError);
  const decoder = await createDecoder();
  for (const wrong of [5, 'abc', null, {}, [1, 2]]) assert.throws(() => decoder.push(wrong), TypeError, String(wrong));
  assert.equal(decoder.progress.bytesReceived, 0);
  // Any view of the bytes will do: a DataView of a stream decodes as its bytes.
  const { bytes } = fixtures['torus-12'];
  const copy = new ArrayBuffer(bytes.length + 16);
  new Uint8Array(copy, 8, bytes.length).set(bytes);
  decoder.push(new DataView(copy, 8, bytes.length));
  decoder.finish();
  assert.deepEqual(decoder.snapshot(), await decode(bytes));
  decoder.dispose();
});

test('coarsePlacement: predicted vertices differ from cell centres before the end, complete models are equal', async () => {
  const { bytes } = fixtures['torus-12'];
  const predicted = await createDecoder();
  const centres = await createDecoder({ coarsePlacement: 'centre' });
  const half = bytes.subarray(0, Math.floor(bytes.length / 2));
  predicted.push(half);
  centres.push(half);
  const p = predicted.snapshot(), c = centres.snapshot();
  assert.equal(p.vertexCount, c.vertexCount);
  assert.deepEqual(p.triangles, c.triangles);
  assert.notDeepEqual(p.positions, c.positions);
  // The native decoder's default is the predicted placement too.
  assertSameModel(p, nativeDecode(fixtures['torus-12'].kdm, half.length), 'predicted prefix');
  predicted.push(bytes.subarray(half.length));
  centres.push(bytes.subarray(half.length));
  assert.deepEqual(predicted.snapshot(), centres.snapshot());
  predicted.dispose();
  centres.dispose();
  await assert.rejects(createDecoder({ coarsePlacement: 'center' }), RangeError);
});
