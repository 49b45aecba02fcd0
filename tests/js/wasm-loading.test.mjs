// How the WebAssembly decoder is found and what its C API reports: the
// header and progress records against the native CLI, the sources
// setWasmSource and compileWasm accept, and a failed download.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { createServer } from 'node:http';
import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { compileWasm, createDecoder, KdmeshError } from 'kdmesh';
import { cli, root, workDir } from './fixtures.mjs';

const wasmPath = join(root, 'web', 'dist', 'kdmesh-wasm.wasm');

test('the header and progress records read as the native CLI reports them', async () => {
  const kdm = join(workDir, 'fandisk.kdm');
  execFileSync(cli, ['encode', join(root, 'build', 'models', 'fandisk.off'), '-o', kdm, '--bits', '12', '-q']);
  const info = JSON.parse(execFileSync(cli, ['info', kdm, '--json'], { encoding: 'utf8' }));
  const bytes = readFileSync(kdm);
  const decoder = await createDecoder();
  assert.equal(decoder.header, null);
  const early = decoder.push(bytes.subarray(0, 2000));
  assert.deepEqual(decoder.header, {
    vertexCount: info.vertexCount, maxDimension: info.maxDimension, simplexCounts: info.simplexCounts,
    quantization: info.quantization, bits: info.bits, step: info.step, totalBytes: info.bytes, chunkCount: info.chunks.length,
    depth: info.axisBits.reduce((sum, bits) => sum + bits), attributeCount: info.attributes.length,
    labelled: info.labels.distinct > 0, fastDecode: info.fastDecode, labels: new Int32Array(0),
  });
  assert.equal(early.bytesReceived, 2000);
  assert.equal(early.bytesExpected, info.bytes);
  assert.equal(early.complete, false);
  assert.ok(early.chunksApplied > 0 && early.chunksApplied < info.chunks.length);
  assert.ok(early.vertexCount > 1 && early.vertexCount < info.vertexCount);
  assert.ok(Number.isFinite(early.errorBound) && early.errorBound > 0);
  // The bound shrinks as chunks arrive and is the same on every read between them.
  const later = decoder.push(bytes.subarray(2000, 6000));
  assert.ok(later.errorBound < early.errorBound, `${later.errorBound} < ${early.errorBound}`);
  assert.deepEqual(decoder.progress, later);
  const final = decoder.push(bytes.subarray(6000));
  assert.equal(final.complete, true);
  assert.equal(final.vertexCount, info.vertexCount);
  assert.equal(final.chunksApplied, info.chunks.length);
  assert.equal(final.level, decoder.header.depth);
  assert.ok(final.errorBound <= info.step, `${final.errorBound} <= ${info.step}`);
  decoder.dispose();
});

test('compileWasm takes a URL, bytes or a module, and a failed download rejects with wasm-unavailable', async () => {
  const wasm = readFileSync(wasmPath);
  const server = createServer((request, response) => {
    if (request.url === '/kdmesh-wasm.wasm') response.writeHead(200, { 'content-type': 'application/wasm' }).end(wasm);
    else if (request.url === '/plain.wasm') response.writeHead(200, { 'content-type': 'application/octet-stream' }).end(wasm);
    else response.writeHead(404).end('no');
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  const base = `http://127.0.0.1:${server.address().port}`;
  try {
    const fromUrl = await compileWasm(`${base}/kdmesh-wasm.wasm`);
    assert.ok(fromUrl instanceof WebAssembly.Module);
    assert.ok(WebAssembly.Module.exports(fromUrl).length > 10);
    assert.ok((await compileWasm(new URL(`${base}/plain.wasm`))) instanceof WebAssembly.Module);
    assert.ok((await compileWasm(wasm)) instanceof WebAssembly.Module);
    assert.equal(await compileWasm(fromUrl), fromUrl);
    assert.ok((await compileWasm()) instanceof WebAssembly.Module, 'the embedded copy');
    for (const bad of [`${base}/missing.wasm`, 'http://127.0.0.1:1/kdmesh-wasm.wasm', new Uint8Array([0, 97, 115, 109, 9])]) {
      await assert.rejects(compileWasm(bad), (error) => error instanceof KdmeshError && error.code === 'wasm-unavailable');
    }
  } finally {
    server.close();
  }
});

test('createDecoder rejects with wasm-unavailable, not hangs, when setWasmSource points nowhere', () => {
  // A fresh process: the wasm source is set once per process.
  const script = `
    import { setWasmSource, createDecoder } from 'kdmesh';
    setWasmSource('http://127.0.0.1:1/kdmesh-wasm.wasm');
    const outcome = await Promise.race([
      createDecoder().then(() => 'created', (error) => error.code),
      new Promise((resolve) => setTimeout(() => resolve('timed out'), 10000)),
    ]);
    console.log(outcome);`;
  const out = execFileSync(process.execPath, ['--input-type=module', '-e', script], { cwd: root, encoding: 'utf8' });
  assert.equal(out.trim(), 'wasm-unavailable');
});
