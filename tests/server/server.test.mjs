// The development server under hostile requests: paths out of its folders,
// links, unreadable files, malformed escapes, foreign pages posting to the
// encoder, oversized, aborted and concurrent uploads, Range requests and slow
// clients that leave. Every server listens on 127.0.0.1, port 0; the encoder
// is a small shell script standing in for the CLI.
import { test, before, after, mock } from 'node:test';
import assert from 'node:assert/strict';
import http from 'node:http';
import fs from 'node:fs';
import { syncBuiltinESMExports } from 'node:module';
import { execFileSync } from 'node:child_process';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { setTimeout as sleep } from 'node:timers/promises';
import { startServer, paceKbps } from '../../web/server.mjs';

const work = fs.mkdtempSync(join(tmpdir(), 'kdmesh-server-test-'));
const root = join(work, 'root');
const temp = join(work, 'tmp');
const secret = 'SECRET-OUTSIDE-ROOT';
const model = Buffer.from(Array.from({ length: 200_000 }, (_, i) => (i * 7919) & 255));
let server, port, slowServer, slowPort;
const savedTmpdir = process.env.TMPDIR;

// An encoder that copies its input, and one that records its pid and sleeps.
function script(name, body) {
  const path = join(work, name);
  fs.writeFileSync(path, `#!/bin/sh\n${body}\n`, { mode: 0o755 });
  return path;
}

before(async () => {
  fs.mkdirSync(root);
  fs.mkdirSync(temp);
  process.env.TMPDIR = temp; // the encoder's folders go here, to be counted
  fs.writeFileSync(join(work, 'secret.txt'), secret);
  fs.writeFileSync(join(root, 'a.kdm'), model);
  fs.symlinkSync(join(work, 'secret.txt'), join(root, 'leak.kdm'));
  fs.symlinkSync('../secret.txt', join(root, 'leak2.kdm'));
  fs.symlinkSync(join(root, 'a.kdm'), join(root, 'alias.kdm'));
  fs.symlinkSync(join(work, 'missing'), join(root, 'dead.kdm'));
  fs.symlinkSync(work, join(root, 'up'));
  fs.mkdirSync(join(root, 'folder.kdm'));
  execFileSync('mkfifo', [join(root, 'pipe.kdm')]);
  const copy = script('copy-encoder', 'echo $$ >> "$(dirname "$0")/copy-pids"\ncp "$2" "$4"');
  const slow = script('slow-encoder', 'echo $$ >> "$(dirname "$0")/slow-pids"\nexec sleep 30');
  server = await startServer({ port: 0, root, host: '127.0.0.1', encoder: copy, maxUploadBytes: 64 * 1024 });
  port = server.address().port;
  slowServer = await startServer({ port: 0, root, host: '127.0.0.1', encoder: slow, maxEncoders: 2, encodeTimeoutMs: 20_000 });
  slowPort = slowServer.address().port;
});

after(async () => {
  server.closeAllConnections();
  slowServer.closeAllConnections();
  await Promise.all([new Promise((r) => server.close(r)), new Promise((r) => slowServer.close(r))]);
  if (savedTmpdir === undefined) delete process.env.TMPDIR; else process.env.TMPDIR = savedTmpdir;
  fs.rmSync(work, { recursive: true, force: true });
});

// One request with a literal path (no URL normalization); resolves with the
// status, headers and body.
function request(path, { method = 'GET', headers = {}, body, to = port } = {}) {
  return new Promise((resolveRequest, reject) => {
    const req = http.request({ host: '127.0.0.1', port: to, path, method, headers, agent: false }, (res) => {
      const chunks = [];
      res.on('data', (c) => chunks.push(c));
      res.on('end', () => resolveRequest({ status: res.statusCode, headers: res.headers, body: Buffer.concat(chunks) }));
      res.on('error', reject);
    });
    req.on('error', reject);
    req.setTimeout(15_000, () => req.destroy(new Error(`${path}: no answer in 15 s`)));
    req.end(body);
  });
}

const same = (to = port) => ({ origin: `http://127.0.0.1:${to}`, host: `127.0.0.1:${to}` });
const tempFolders = () => fs.readdirSync(temp).filter((n) => n.startsWith('kdmesh-encode-'));
const pids = (name) => (fs.existsSync(join(work, name)) ? fs.readFileSync(join(work, name), 'utf8').split('\n').filter(Boolean).map(Number) : []);
const alive = (pid) => { try { process.kill(pid, 0); return true; } catch { return false; } };
const openDescriptors = () => fs.readdirSync('/proc/self/fd').length;
async function until(condition, ms, what) {
  const end = Date.now() + ms;
  while (!condition()) {
    if (Date.now() > end) assert.fail(`${what}: not within ${ms} ms`);
    await sleep(25);
  }
}

test('paths with .. do not leave the served folders', async () => {
  for (const path of ['/../secret.txt', '/models/../secret.txt', '/models/..%2fsecret.txt', '/models/%2e%2e/secret.txt',
    '/models/..%2f..%2f..%2f..%2fetc%2fpasswd', '/%2e%2e/%2e%2e/package.json', '/vendor/three/..%2f..%2fpackage.json']) {
    const { status, body } = await request(path);
    assert.equal(status, 404, path);
    assert.ok(!body.includes(secret) && !body.includes('"devDependencies"'), path);
  }
});

test('links out of the root are not followed; links inside it are', async () => {
  for (const path of ['/models/leak.kdm', '/models/leak2.kdm', '/models/up/secret.txt']) {
    const { status, body } = await request(path);
    assert.equal(status, 404, path);
    assert.ok(!body.includes(secret), path);
  }
  const alias = await request('/models/alias.kdm');
  assert.equal(alias.status, 200);
  assert.ok(alias.body.equals(model));
});

test('the model list has regular files in the root only, with no 500 for a dangling link', async () => {
  const { status, body } = await request('/models/');
  assert.equal(status, 200);
  const list = JSON.parse(body);
  assert.deepEqual(list.map((m) => m.name), ['a.kdm', 'alias.kdm']);
  assert.equal(list[0].bytes, model.length);
  assert.ok(!body.includes(work));
  assert.equal((await request('/models/dead.kdm')).status, 404);
});

test('a FIFO or a folder is not served, and does not hang the server', async () => {
  for (const path of ['/models/pipe.kdm', '/models/folder.kdm', '/models/pipe.kdm?throttle=100']) {
    assert.equal((await request(path)).status, 404, path);
  }
});

test('malformed % escapes are 400', async () => {
  for (const path of ['/%E0%A4%A', '/models/%zz.kdm', '/models/%', '/vendor/three/%C0%AF', '/models/a%00.kdm']) {
    assert.equal((await request(path)).status, 400, path);
  }
});

test('a read error is an error response and the server stays up', async (t) => {
  const original = fs.createReadStream;
  // EIO when the file is opened, for plain and paced downloads.
  mock.method(fs, 'createReadStream', (path, options) => {
    const stream = original(path, options);
    process.nextTick(() => stream.destroy(Object.assign(new Error('i/o error'), { code: 'EIO' })));
    return stream;
  });
  syncBuiltinESMExports();
  try {
    // The error may come after the headers: then the connection is reset.
    const plain = await request('/models/a.kdm').catch((e) => ({ status: e.code }));
    assert.ok(plain.status >= 500 || plain.status === 'ECONNRESET', `plain: ${plain.status}`);
    const paced = await request('/models/a.kdm?throttle=100000').catch((e) => ({ status: e.code }));
    assert.ok(paced.status === 500 || paced.status === 'ECONNRESET', `paced: ${paced.status}`);
  } finally {
    fs.createReadStream.mock.restore();
    syncBuiltinESMExports();
  }
  // The file is renamed between the server's check and its read.
  t.after(() => fs.existsSync(join(work, 'moved.kdm')) && fs.renameSync(join(work, 'moved.kdm'), join(root, 'a.kdm')));
  mock.method(fs, 'createReadStream', (path, options) => {
    if (String(path).endsWith('a.kdm') && fs.existsSync(join(root, 'a.kdm'))) fs.renameSync(join(root, 'a.kdm'), join(work, 'moved.kdm'));
    return original(path, options);
  });
  syncBuiltinESMExports();
  try {
    assert.equal((await request('/models/a.kdm')).status, 404);
    fs.renameSync(join(work, 'moved.kdm'), join(root, 'a.kdm'));
    assert.equal((await request('/models/a.kdm?throttle=100000')).status, 500);
  } finally {
    fs.createReadStream.mock.restore();
    syncBuiltinESMExports();
    if (fs.existsSync(join(work, 'moved.kdm'))) fs.renameSync(join(work, 'moved.kdm'), join(root, 'a.kdm'));
  }
  const again = await request('/models/a.kdm');
  assert.equal(again.status, 200);
  assert.ok(again.body.equals(model));
});

test('Range requests get the bytes asked for', async () => {
  const middle = await request('/models/a.kdm', { headers: { range: 'bytes=10-19' } });
  assert.equal(middle.status, 206);
  assert.equal(middle.headers['content-range'], `bytes 10-19/${model.length}`);
  assert.ok(middle.body.equals(model.subarray(10, 20)));
  const first = await request('/models/a.kdm', { headers: { range: 'bytes=0-0' } });
  assert.ok(first.body.equals(model.subarray(0, 1)));
  const tail = await request('/models/a.kdm', { headers: { range: 'bytes=-5' } });
  assert.ok(tail.body.equals(model.subarray(model.length - 5)));
  assert.equal((await request('/models/a.kdm', { headers: { range: `bytes=${model.length}-` } })).status, 416);
});

test('the encoder route refuses other sites and other host names', async () => {
  const before = pids('copy-pids').length;
  const mesh = 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n';
  for (const headers of [{ origin: 'http://evil.example', host: `127.0.0.1:${port}` },
    { origin: 'null', host: `127.0.0.1:${port}` },
    { origin: `http://evil.example:${port}`, host: `evil.example:${port}` }, // a rebound DNS name
    { host: `evil.example:${port}` },
    { ...same(), 'sec-fetch-site': 'cross-site' }]) {
    const { status } = await request('/encode?name=m.obj', { method: 'POST', headers, body: mesh });
    assert.equal(status, 403, JSON.stringify(headers));
  }
  assert.equal(pids('copy-pids').length, before, 'no encoder ran');
  const ok = await request('/encode?name=m.obj', { method: 'POST', headers: same(), body: mesh });
  assert.equal(ok.status, 200);
  assert.equal(ok.body.toString(), mesh);
  const local = await request('/encode?name=m.obj', { method: 'POST', headers: { host: `localhost:${port}` }, body: mesh });
  assert.equal(local.status, 200);
  await until(() => tempFolders().length === 0, 5000, 'temporary folders removed');
});

test('uploads over the size limit are 413, declared or not', async () => {
  const big = Buffer.alloc(64 * 1024 + 1, 0x20);
  assert.equal((await request('/encode?name=m.obj', { method: 'POST', headers: same(), body: big })).status, 413);
  const chunked = await new Promise((resolveRequest, reject) => {
    const req = http.request({ host: '127.0.0.1', port, path: '/encode?name=m.obj', method: 'POST', headers: same(), agent: false }, (res) => {
      res.resume();
      resolveRequest(res.statusCode);
    });
    req.on('error', (e) => (e.code === 'EPIPE' || e.code === 'ECONNRESET' ? resolveRequest('reset') : reject(e)));
    for (let i = 0; i < 20; ++i) req.write(Buffer.alloc(8192, 0x20));
    req.end();
  });
  assert.ok(chunked === 413 || chunked === 'reset', String(chunked));
  await until(() => tempFolders().length === 0, 5000, 'temporary folders removed');
});

test('an aborted upload or encode removes its folder and kills its encoder', async () => {
  // Upload cut before its end.
  const upload = http.request({ host: '127.0.0.1', port: slowPort, path: '/encode?name=m.obj', method: 'POST', headers: { ...same(slowPort), 'content-length': 100_000 }, agent: false });
  upload.on('error', () => {});
  upload.write(Buffer.alloc(1000, 0x20));
  await until(() => tempFolders().length === 1, 5000, 'upload folder made');
  upload.destroy();
  await until(() => tempFolders().length === 0, 5000, 'upload folder removed');
  // Client leaves while the encoder runs.
  const before = pids('slow-pids').length;
  const encode = http.request({ host: '127.0.0.1', port: slowPort, path: '/encode?name=m.obj', method: 'POST', headers: same(slowPort), agent: false });
  encode.on('error', () => {});
  encode.end('v 0 0 0\n');
  await until(() => pids('slow-pids').length === before + 1, 5000, 'encoder started');
  const pid = pids('slow-pids').at(-1);
  assert.ok(alive(pid));
  encode.destroy();
  await until(() => !alive(pid), 5000, 'encoder killed');
  await until(() => tempFolders().length === 0, 5000, 'encode folder removed');
});

test('at most two encoders run; the third request is 503; a slow encode is 504', async () => {
  const before = pids('slow-pids').length;
  const running = [0, 1].map(() => request('/encode?name=m.obj', { method: 'POST', headers: same(slowPort), body: 'v 0 0 0\n', to: slowPort }).catch((e) => e));
  await until(() => pids('slow-pids').length === before + 2, 5000, 'two encoders started');
  const third = await request('/encode?name=m.obj', { method: 'POST', headers: same(slowPort), body: 'v 0 0 0\n', to: slowPort });
  assert.equal(third.status, 503);
  assert.equal(pids('slow-pids').length, before + 2);
  // The time limit: a server with 300 ms.
  const quick = await startServer({ port: 0, root, host: '127.0.0.1', encoder: join(work, 'slow-encoder'), encodeTimeoutMs: 300 });
  try {
    const started = Date.now();
    const timedOut = await request('/encode?name=m.obj', { method: 'POST', headers: same(quick.address().port), body: 'v 0 0 0\n', to: quick.address().port });
    assert.equal(timedOut.status, 504);
    assert.ok(Date.now() - started < 5000);
    assert.ok(!alive(pids('slow-pids').at(-1)));
  } finally {
    quick.closeAllConnections();
    await new Promise((r) => quick.close(r));
  }
  slowServer.closeAllConnections(); // ends the two running encodes
  await Promise.all(running);
  for (const pid of pids('slow-pids').slice(before)) await until(() => !alive(pid), 5000, `encoder ${pid} killed`);
  await until(() => tempFolders().length === 0, 5000, 'temporary folders removed');
});

test('throttle values are clamped to 1 kbit/s .. 10 Gbit/s', async () => {
  assert.equal(paceKbps('1e-300'), 1);
  assert.equal(paceKbps('1e300'), 10_000_000);
  assert.equal(paceKbps('Infinity'), 10_000_000);
  assert.equal(paceKbps('0'), null);
  assert.equal(paceKbps('NaN'), null);
  assert.equal(paceKbps('-5'), null);
  assert.equal(paceKbps('800'), 800);
  // 1e-300 is 1 kbit/s: the first KiB takes 8 s, so nothing of it in 1 s.
  const received = await new Promise((resolveRead) => {
    const req = http.get({ host: '127.0.0.1', port, path: '/models/a.kdm?throttle=1e-300', agent: false }, (res) => {
      let bytes = 0;
      res.on('data', (c) => (bytes += c.length));
      setTimeout(() => { req.destroy(); resolveRead(bytes); }, 1000);
    });
    req.on('error', () => {});
  });
  assert.equal(received, 0);
  const fast = await request('/models/a.kdm?throttle=1e300');
  assert.ok(fast.body.equals(model));
});

test('paced downloads keep their pace and their bytes', async () => {
  const started = Date.now();
  const paced = await request('/models/a.kdm?throttle=8000'); // 1000 bytes per ms: 200 ms
  const ms = Date.now() - started;
  assert.ok(paced.body.equals(model));
  assert.ok(ms >= 180 && ms < 5000, `${ms} ms`);
});

test('slow clients that leave release their files and memory', async () => {
  const big = Buffer.alloc(8 * 1024 * 1024, 7);
  fs.writeFileSync(join(root, 'big.kdm'), big);
  await request('/'); // warm up
  const descriptors = openDescriptors();
  const heap = process.memoryUsage().arrayBuffers;
  const clients = await Promise.all(Array.from({ length: 30 }, () => new Promise((resolveClient) => {
    const req = http.get({ host: '127.0.0.1', port, path: '/models/big.kdm?throttle=80', agent: false }, (res) => {
      res.once('data', () => resolveClient(req));
    });
    req.on('error', () => {});
  })));
  const during = process.memoryUsage().arrayBuffers - heap;
  assert.ok(during < 30 * big.length / 4, `${during} bytes held for 30 clients of an 8 MiB file`);
  for (const req of clients) req.destroy();
  await until(() => openDescriptors() <= descriptors, 5000, `descriptors back to ${descriptors}`);
  fs.rmSync(join(root, 'big.kdm'));
});

test('the server still answers after all of this', async () => {
  const page = await request('/');
  assert.equal(page.status, 200);
  assert.match(page.headers['content-type'], /text\/html/);
  const list = await request('/models/');
  assert.equal(list.status, 200);
  const encoded = await request('/encode?name=m.obj', { method: 'POST', headers: same(), body: 'v 0 0 0\n' });
  assert.equal(encoded.status, 200);
});
