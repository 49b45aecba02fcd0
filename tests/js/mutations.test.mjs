// The mutation suite in WebAssembly: 600 streams of a mesh, each with one
// kind of change and valid checksums (tests/native/mutations.h, written by
// build/kdmesh_write_mutations with the native decoder's verdicts). The
// WebAssembly decoder must reach the native verdict on every one, whole
// and pushed in pieces: the same error code, or a model of the same size;
// never a crash, and within a time and memory budget per stream that a
// decoder doing work or allocating out of proportion to the bytes would
// exceed.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { createDecoder, memoryInUse } from 'kdmesh';
import { execFileSync } from 'node:child_process';
import { mkdirSync, readFileSync } from 'node:fs';
import { join } from 'node:path';
import { root, workDir } from './fixtures.mjs';

const kStreamMs = 2000;             // per stream; a honest one takes milliseconds
const kStreamHeapBytes = 32 << 20;  // per decoder; the honest stream takes about 1 MB

function verdictOf(bytes, pieces) {
  return createDecoder().then(async (decoder) => {
    const began = performance.now();
    let heap = 0;
    try {
      for (let at = 0, i = 0; at < bytes.length; ++i) {
        const size = pieces ? 1 + ((i * 97 + 13) % 300) : bytes.length;
        decoder.push(bytes.subarray(at, at + size));
        at += size;
        heap = Math.max(heap, await memoryInUse());
      }
      decoder.finish();
      const model = decoder.snapshot();
      return { code: 'ok', vertices: model.vertexCount, triangles: model.triangles.length / 3, heap, ms: performance.now() - began };
    } catch (error) {
      assert.ok(error.code && error.code !== 'error', `an undocumented error: ${error}`);
      return { code: error.code, vertices: 0, triangles: 0, heap, ms: performance.now() - began };
    } finally {
      decoder.dispose();
    }
  });
}

test('mutated streams with valid checksums get the native verdicts', async () => {
  const dir = join(workDir, 'mutations');
  mkdirSync(dir, { recursive: true });
  execFileSync(join(root, 'build', 'kdmesh_write_mutations'), [dir, '600']);
  const verdicts = JSON.parse(readFileSync(join(dir, 'verdicts.json'), 'utf8'));
  assert.equal(verdicts.length, 600);
  const before = await memoryInUse();
  const codes = new Set();
  for (const [i, expected] of verdicts.entries()) {
    const bytes = new Uint8Array(readFileSync(join(dir, expected.file)));
    // Every stream whole; every fourth also in pieces of 1 to 300 bytes.
    for (const pieces of i % 4 === 0 ? [false, true] : [false]) {
      const got = await verdictOf(bytes, pieces);
      const what = `${expected.file} (${expected.kind}${pieces ? ', in pieces' : ''})`;
      assert.equal(got.code, expected.code, what);
      assert.equal(got.vertices, expected.vertices, `${what}: vertices`);
      assert.equal(got.triangles, expected.triangles, `${what}: triangles`);
      assert.ok(got.ms < kStreamMs, `${what}: ${got.ms.toFixed(0)} ms`);
      assert.ok(got.heap - before < kStreamHeapBytes, `${what}: ${got.heap - before} bytes of heap`);
      codes.add(got.code);
    }
  }
  // The suite reaches both outcomes and several kinds of refusal.
  assert.ok(codes.has('ok') && codes.has('corrupt-chunk') && codes.has('corrupt-header'), [...codes].join(' '));
  assert.equal(await memoryInUse(), before);
});
