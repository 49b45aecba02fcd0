// The development server under hostile requests: paths out of its folders,
// links, unreadable files and files that change while served, malformed
// escapes, foreign pages posting to the encoder, oversized, aborted, slow
// and concurrent uploads, Range requests and slow clients that leave. Every
// server listens on 127.0.0.1, port 0; the encoder is a small shell script
// standing in for the CLI.
import { test, before, after, mock } from 'node:test';
import assert from 'node:assert/strict';
import http from 'node:http';
import net from 'node:net';
import fs from 'node:fs';
import { syncBuiltinESMExports } from 'node:module';
import { execFileSync } from 'node:child_process';
import { hostname, tmpdir } from 'node:os';
import { join } from 'node:path';
import { Readable } from 'node:stream';
import { setTimeout as sleep } from 'node:timers/promises';
import { startServer, paceKbps } from '../../web/server.mjs';

const work = fs.mkdtempSync(join(tmpdir(), 'kdmesh-server-test-'));
const root = join(work, 'root');
const temp = join(work, 'tmp');
const secret = 'SECRET-OUTSIDE-ROOT';
const model = Buffer.from(Array.from({ length: 200_000 }, (_, i) => (i * 7919) & 255));
const uploadLimit = 64 * 1024;
const originalCreateReadStream = fs.createReadStream;
let server, port, slowServer, slowPort;
const savedTmpdir = process.env.TMPDIR;

// An encoder that copies its input, and one that sleeps; each appends its
// pid to a file, so that the test knows whether it ran and can check that
// it was killed.
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
  fs.mkdirSync(join(root, 'sub'));
  fs.writeFileSync(join(root, 'sub', 'b.kdm'), model);
  fs.symlinkSync(join(root, 'sub'), join(root, 'in'));
  fs.mkdirSync(join(root, 'folder.kdm'));
  execFileSync('mkfifo', [join(root, 'pipe.kdm')]);
  const copy = script('copy-encoder', 'echo $$ >> "$(dirname "$0")/copy-pids"\ncp "$2" "$4"');
  const slow = script('slow-encoder', 'echo $$ >> "$(dirname "$0")/slow-pids"\nexec sleep 30');
  server = await startServer({ port: 0, root, host: '127.0.0.1', encoder: copy, maxUploadBytes: uploadLimit });
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
// status, headers and body, rejects when the response is cut short.
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

// A GET that never rejects: its status, the bytes received, whether the
// response came whole, the error that ended it if any, and its time.
function download(path, { agent = false, to = port } = {}) {
  return new Promise((resolveDownload) => {
    const started = Date.now();
    const result = { status: null, bytes: 0, complete: false, error: null, ms: 0 };
    let settled = false;
    const done = (error) => {
      if (settled) return;
      settled = true;
      resolveDownload({ ...result, error: error ? error.code ?? error.message : null, ms: Date.now() - started });
    };
    const req = http.get({ host: '127.0.0.1', port: to, path, agent }, (res) => {
      result.status = res.statusCode;
      res.on('data', (c) => (result.bytes += c.length));
      res.on('end', () => { result.complete = res.complete; done(); });
      res.on('error', done);
    });
    req.on('error', done);
    req.setTimeout(15_000, () => req.destroy(new Error('no answer in 15 s')));
  });
}

const same = (to = port) => ({ origin: `http://127.0.0.1:${to}`, host: `127.0.0.1:${to}` });
// The headers chromium sends with the viewer's fetch() to /encode.
const fromViewer = (to = port) => ({ ...same(to), 'sec-fetch-site': 'same-origin', 'sec-fetch-mode': 'cors', 'sec-fetch-dest': 'empty', referer: `http://127.0.0.1:${to}/?model=a.kdm` });
const mesh = 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n';
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

// Runs `body` with fs.createReadStream replaced (for `send` and for the
// server's paced downloads alike).
async function withReadStream(replacement, body) {
  mock.method(fs, 'createReadStream', replacement);
  syncBuiltinESMExports();
  try {
    return await body();
  } finally {
    mock.restoreAll();
    syncBuiltinESMExports();
  }
}

// A read stream of the file's bytes that fails with EIO once `good` bytes
// have been read: a disk error in the middle of a file (0: at its start).
const failingAfter = (good) => (path, options = {}) => {
  const bytes = fs.readFileSync(path).subarray(options.start ?? 0, options.end === undefined ? undefined : options.end + 1);
  let offset = 0;
  return new Readable({
    read() {
      if (offset >= good || offset >= bytes.length) return this.destroy(Object.assign(new Error('i/o error'), { code: 'EIO' }));
      const end = Math.min(good, bytes.length, offset + 16384);
      this.push(bytes.subarray(offset, end));
      offset = end;
    },
  });
};

test('paths with .., encoded or not, and absolute paths do not leave the served folders', async () => {
  const secretPath = encodeURIComponent(join(work, 'secret.txt'));
  for (const path of ['/../secret.txt', '/models/../secret.txt', '/models/..%2fsecret.txt', '/models/%2e%2e/secret.txt',
    '/models/%2E%2E%2Fsecret.txt', '/models/..%5csecret.txt', '/models/..\\secret.txt',
    '/models/..%2f..%2f..%2f..%2fetc%2fpasswd', '/%2e%2e/%2e%2e/package.json', '/vendor/three/..%2f..%2fpackage.json',
    '/vendor/three/%2e%2e/%2e%2e/package.json',
    `/models/${secretPath}`, `/${secretPath}`, `/vendor/three/${secretPath}`, '/models/%2Fetc%2Fpasswd',
    '//etc/passwd', '/models//etc/passwd', `http://127.0.0.1:${port}/models/../../secret.txt`]) {
    const { status, body } = await request(path);
    assert.equal(status, 404, path);
    assert.ok(!body.includes(secret) && !body.includes('"devDependencies"') && !body.includes('root:'), path);
    assert.ok(!body.includes(work), `${path}: the answer names a path`);
  }
});

test('links out of the root, to a file or a folder, are not followed; links inside it are', async () => {
  for (const path of ['/models/leak.kdm', '/models/leak2.kdm', '/models/up/secret.txt',
    '/models/leak.kdm?throttle=100', '/models/up/secret.txt?throttle=100']) {
    const { status, body } = await request(path);
    assert.equal(status, 404, path);
    assert.ok(!body.includes(secret), path);
  }
  // up/root/a.kdm leaves the root through a link and comes back into it.
  for (const path of ['/models/alias.kdm', '/models/in/b.kdm', '/models/sub/b.kdm', '/models/up/root/a.kdm', '/models/alias.kdm?throttle=1e9']) {
    const { status, body } = await request(path);
    assert.equal(status, 200, path);
    assert.ok(body.equals(model), path);
  }
});

test('the model list has regular files in the root only, with no 500 for a dangling link', async () => {
  const { status, body } = await request('/models/');
  assert.equal(status, 200);
  const list = JSON.parse(body);
  assert.deepEqual(list.map((m) => m.name), ['a.kdm', 'alias.kdm']);
  assert.equal(list[0].bytes, model.length);
  assert.ok(!body.includes(work));
  const dead = await request('/models/dead.kdm');
  assert.equal(dead.status, 404);
  assert.ok(!dead.body.includes(work));
});

test('a FIFO or a folder is not served, and does not hang the server', async () => {
  for (const path of ['/models/pipe.kdm', '/models/folder.kdm', '/models/pipe.kdm?throttle=100', '/models/sub']) {
    assert.equal((await request(path)).status, 404, path);
  }
});

test('malformed % escapes and requests are 400', async () => {
  for (const path of ['/%E0%A4%A', '/models/%zz.kdm', '/models/%', '/vendor/three/%C0%AF', '/models/a%00.kdm']) {
    assert.equal((await request(path)).status, 400, path);
  }
  const answer = await new Promise((resolveAnswer, reject) => {
    const socket = net.connect(port, '127.0.0.1', () => socket.end('NOT HTTP AT ALL\r\n\r\n'));
    let text = '';
    socket.on('data', (d) => (text += d));
    socket.on('end', () => resolveAnswer(text));
    socket.on('error', reject);
  });
  assert.match(answer, /^HTTP\/1\.1 400/);
});

test('an unreadable file is 500 and the server stays up', {
  skip: process.getuid?.() === 0 ? 'running as root, whom chmod 000 does not keep from reading: run as another user to test EACCES' : false,
}, async () => {
  const locked = join(root, 'locked.kdm');
  fs.writeFileSync(locked, model);
  fs.chmodSync(locked, 0o000);
  try {
    for (const path of ['/models/locked.kdm', '/models/locked.kdm?throttle=100000']) {
      const { status, body } = await request(path);
      assert.equal(status, 500, path);
      assert.equal(body.toString(), 'cannot read file', path);
    }
    assert.equal((await request('/models/')).status, 200);
  } finally {
    fs.rmSync(locked);
  }
  assert.ok((await request('/models/a.kdm')).body.equals(model));
});

test('a read error before the first byte is 500; after it, the connection is closed', async () => {
  await withReadStream(failingAfter(0), async () => {
    for (const path of ['/models/a.kdm', '/models/a.kdm?throttle=100000']) {
      const { status, headers, body } = await request(path);
      assert.equal(status, 500, path);
      assert.equal(body.toString(), 'cannot read file', path);
      assert.equal(Number(headers['content-length']), body.length, path);
      assert.equal(headers.etag, undefined, `${path}: headers of the file left on the error`);
    }
  });
  await withReadStream(failingAfter(65536), async () => {
    for (const path of ['/models/a.kdm', '/models/a.kdm?throttle=100000']) {
      const cut = await download(path);
      assert.equal(cut.status, 200, path);
      assert.equal(cut.complete, false, path);
      assert.ok(cut.error, path);
      assert.ok(cut.bytes <= 65536, `${path}: ${cut.bytes} bytes`);
    }
  });
  const again = await request('/models/a.kdm');
  assert.equal(again.status, 200);
  assert.ok(again.body.equals(model));
});

test('a file that vanishes or shrinks while served: 404 or a closed connection, and the server stays up', async (t) => {
  const shrinking = join(root, 'shrinking.kdm');
  const moved = join(work, 'moved.kdm');
  t.after(() => fs.rmSync(shrinking, { force: true }));
  // Moved away between the server's check and its opening of the file.
  fs.writeFileSync(shrinking, model);
  await withReadStream((path, options) => {
    if (String(path).endsWith('shrinking.kdm') && fs.existsSync(shrinking)) fs.renameSync(shrinking, moved);
    return originalCreateReadStream(path, options);
  }, async () => {
    assert.equal((await request('/models/shrinking.kdm')).status, 404);
    fs.renameSync(moved, shrinking);
    assert.equal((await request('/models/shrinking.kdm?throttle=100000')).status, 404);
  });
  // Truncated once opened: the client, on a kept-alive connection, sees the
  // download end short at once instead of waiting for the missing bytes.
  const keepAlive = server.keepAliveTimeout;
  server.keepAliveTimeout = 60_000;
  const agent = new http.Agent({ keepAlive: true });
  t.after(() => { server.keepAliveTimeout = keepAlive; agent.destroy(); });
  await withReadStream((path, options) => {
    const stream = originalCreateReadStream(path, options);
    if (String(path).endsWith('shrinking.kdm')) stream.once('open', () => fs.truncateSync(path, 50_000));
    return stream;
  }, async () => {
    for (const path of ['/models/shrinking.kdm', '/models/shrinking.kdm?throttle=1000000']) {
      fs.writeFileSync(shrinking, model);
      const cut = await download(path, { agent });
      assert.equal(cut.status, 200, path);
      assert.equal(cut.complete, false, path);
      assert.ok(cut.bytes <= 50_000, `${path}: ${cut.bytes} bytes`);
      assert.ok(cut.ms < 10_000, `${path}: ${cut.ms} ms, ${cut.error}`);
    }
  });
  const again = await request('/models/a.kdm');
  assert.equal(again.status, 200);
  assert.ok(again.body.equals(model));
});

test('Range requests get the bytes asked for; conditional requests get 304', async () => {
  const middle = await request('/models/a.kdm', { headers: { range: 'bytes=10-19' } });
  assert.equal(middle.status, 206);
  assert.equal(middle.headers['content-range'], `bytes 10-19/${model.length}`);
  assert.ok(middle.body.equals(model.subarray(10, 20)));
  const first = await request('/models/a.kdm', { headers: { range: 'bytes=0-0' } });
  assert.equal(first.status, 206);
  assert.ok(first.body.equals(model.subarray(0, 1)));
  const tail = await request('/models/a.kdm', { headers: { range: 'bytes=-5' } });
  assert.equal(tail.status, 206);
  assert.ok(tail.body.equals(model.subarray(model.length - 5)));
  const beyond = await request('/models/a.kdm', { headers: { range: `bytes=${model.length}-` } });
  assert.equal(beyond.status, 416);
  assert.equal(beyond.headers['content-range'], `bytes */${model.length}`);
  const page = await request('/index.html', { headers: { range: 'bytes=0-14' } });
  assert.equal(page.status, 206);
  assert.equal(page.body.length, 15);
  const whole = await request('/models/a.kdm');
  assert.ok(whole.headers.etag);
  assert.equal((await request('/models/a.kdm', { headers: { 'if-none-match': whole.headers.etag } })).status, 304);
});

test('the encoder route takes the page\'s own requests and refuses other sites and host names', async () => {
  const before = pids('copy-pids').length;
  for (const headers of [{ origin: 'http://evil.example', host: `127.0.0.1:${port}` },
    { origin: 'null', host: `127.0.0.1:${port}` },
    { origin: `https://127.0.0.1:${port}`, host: `127.0.0.1:${port}` },
    { origin: `http://127.0.0.1:${port + 1}`, host: `127.0.0.1:${port}` },
    { origin: `http://localhost:${port}`, host: `127.0.0.1:${port}` },
    { origin: `http://evil.example:${port}`, host: `evil.example:${port}` }, // a rebound DNS name
    { host: `evil.example:${port}` },
    { host: `localhost.evil.example:${port}` },
    { host: `127.0.0.1@evil.example:${port}` },
    { ...fromViewer(), 'sec-fetch-site': 'cross-site' },
    { ...fromViewer(), 'sec-fetch-site': 'same-site' }]) {
    const { status } = await request('/encode?name=m.obj', { method: 'POST', headers, body: mesh });
    assert.equal(status, 403, JSON.stringify(headers));
  }
  assert.equal(pids('copy-pids').length, before, 'no encoder ran');
  const own = [fromViewer(), same(), { host: `localhost:${port}` },
    { origin: `http://localhost:${port}`, host: `localhost:${port}`, 'sec-fetch-site': 'same-origin' },
    { origin: `http://[::1]:${port}`, host: `[::1]:${port}` },
    { origin: `http://${hostname().toLowerCase()}:${port}`, host: `${hostname()}:${port}` }];
  for (const headers of own) {
    const ok = await request('/encode?name=m.obj', { method: 'POST', headers, body: mesh });
    assert.equal(ok.status, 200, JSON.stringify(headers));
    assert.equal(ok.body.toString(), mesh);
  }
  assert.equal(pids('copy-pids').length, before + own.length);
  assert.equal((await request('/encode?name=m.exe', { method: 'POST', headers: same(), body: mesh })).status, 400);
  assert.equal((await request('/encode?name=m.obj', { headers: same() })).status, 405);
  await until(() => tempFolders().length === 0, 5000, 'temporary folders removed');
});

test('uploads over the size limit are 413, declared or not, and run no encoder', async () => {
  const before = pids('copy-pids').length;
  // A declared length over the limit is refused before any of the body.
  const declared = await new Promise((resolveRequest, reject) => {
    const req = http.request({ host: '127.0.0.1', port, path: '/encode?name=m.obj', method: 'POST',
      headers: { ...same(), 'content-length': 10 * 1024 ** 3 }, agent: false }, (res) => {
      resolveRequest(res.statusCode);
      req.destroy();
    });
    req.on('error', (e) => (e.code === 'ECONNRESET' ? null : reject(e)));
    req.flushHeaders();
  });
  assert.equal(declared, 413);
  const sent = await request('/encode?name=m.obj', { method: 'POST', headers: same(), body: Buffer.alloc(uploadLimit + 1, 0x20) });
  assert.equal(sent.status, 413);
  assert.match(sent.body.toString(), new RegExp(`limited to ${uploadLimit} bytes`));
  // A chunked body (no declared length) is refused once it passes the
  // limit; the client still reads the answer.
  for (const total of [uploadLimit + 1, 20 * uploadLimit]) {
    const chunked = await new Promise((resolveRequest, reject) => {
      const req = http.request({ host: '127.0.0.1', port, path: '/encode?name=m.obj', method: 'POST', headers: same(), agent: false }, (res) => {
        res.resume();
        resolveRequest(res.statusCode);
      });
      req.on('error', reject);
      for (let left = total; left > 0; left -= 8192) req.write(Buffer.alloc(Math.min(8192, left), 0x20));
      req.end();
    });
    assert.equal(chunked, 413, `${total} bytes chunked`);
  }
  const fits = await request('/encode?name=m.obj', { method: 'POST', headers: same(), body: Buffer.alloc(uploadLimit, 0x20) });
  assert.equal(fits.status, 200);
  assert.equal(fits.body.length, uploadLimit);
  assert.equal(pids('copy-pids').length, before + 1, 'only the upload within the limit was encoded');
  await until(() => tempFolders().length === 0, 5000, 'temporary folders removed');
});

test('an aborted upload or encode removes its folder and kills its encoder', async () => {
  // Upload cut before its end: no encoder runs.
  const before = pids('slow-pids').length;
  const upload = http.request({ host: '127.0.0.1', port: slowPort, path: '/encode?name=m.obj', method: 'POST', headers: { ...same(slowPort), 'content-length': 100_000 }, agent: false });
  upload.on('error', () => {});
  upload.write(Buffer.alloc(1000, 0x20));
  await until(() => tempFolders().length === 1, 5000, 'upload folder made');
  await until(() => tempFolders().length === 1 && fs.readdirSync(join(temp, tempFolders()[0])).length === 1, 5000, 'upload file made');
  upload.destroy();
  await until(() => tempFolders().length === 0, 5000, 'upload folder removed');
  assert.equal(pids('slow-pids').length, before, 'no encoder ran for a cut upload');
  // Client leaves while the folder is being made.
  const mkdtemp = fs.promises.mkdtemp;
  let made = false;
  mock.method(fs.promises, 'mkdtemp', async (...args) => {
    await sleep(300);
    const folder = await mkdtemp.apply(fs.promises, args);
    made = true;
    return folder;
  });
  try {
    const early = http.request({ host: '127.0.0.1', port: slowPort, path: '/encode?name=m.obj', method: 'POST', headers: same(slowPort), agent: false });
    early.on('error', () => {});
    early.write('v 0 0 0\n');
    await sleep(50);
    early.destroy();
    await until(() => made, 5000, 'folder made');
  } finally {
    mock.restoreAll();
  }
  await until(() => tempFolders().length === 0, 5000, 'folder made after the client left removed');
  assert.equal(pids('slow-pids').length, before, 'no encoder ran for a client that left');
  // Client leaves while the encoder runs.
  const encode = http.request({ host: '127.0.0.1', port: slowPort, path: '/encode?name=m.obj', method: 'POST', headers: same(slowPort), agent: false });
  encode.on('error', () => {});
  encode.end('v 0 0 0\n');
  await until(() => pids('slow-pids').length === before + 1, 5000, 'encoder started');
  const pid = pids('slow-pids').at(-1);
  assert.ok(alive(pid));
  encode.destroy();
  await until(() => !alive(pid), 5000, 'encoder killed');
  await until(() => tempFolders().length === 0, 5000, 'encode folder removed');
  // The two encoder slots are free again.
  const busy = await request('/encode?name=m.obj', { method: 'POST', headers: same(slowPort), body: 'x', to: slowPort }).catch((e) => e);
  assert.notEqual(busy.status, 503);
});

test('at most two encoders run; the third request is 503; a slow upload is 408, a slow encode 504', async () => {
  const before = pids('slow-pids').length;
  const running = [0, 1].map(() => request('/encode?name=m.obj', { method: 'POST', headers: same(slowPort), body: 'v 0 0 0\n', to: slowPort }).catch((e) => e));
  await until(() => pids('slow-pids').length === before + 2, 5000, 'two encoders started');
  const third = await request('/encode?name=m.obj', { method: 'POST', headers: same(slowPort), body: 'v 0 0 0\n', to: slowPort });
  assert.equal(third.status, 503);
  assert.equal(pids('slow-pids').length, before + 2);
  // The time limit: a server with 300 ms.
  const quick = await startServer({ port: 0, root, host: '127.0.0.1', encoder: join(work, 'slow-encoder'), encodeTimeoutMs: 300 });
  const quickPort = quick.address().port;
  try {
    const started = Date.now();
    const timedOut = await request('/encode?name=m.obj', { method: 'POST', headers: same(quickPort), body: 'v 0 0 0\n', to: quickPort });
    assert.equal(timedOut.status, 504);
    assert.ok(Date.now() - started < 5000);
    await until(() => !alive(pids('slow-pids').at(-1)), 5000, 'timed-out encoder killed');
    // An upload that never ends holds its slot no longer than the limit.
    const encoders = pids('slow-pids').length;
    const stalled = await new Promise((resolveRequest, reject) => {
      const req = http.request({ host: '127.0.0.1', port: quickPort, path: '/encode?name=m.obj', method: 'POST',
        headers: { ...same(quickPort), 'content-length': 1000 }, agent: false }, (res) => { res.resume(); resolveRequest(res.statusCode); });
      req.on('error', reject);
      req.write('v 0 0 0\n');
    });
    assert.equal(stalled, 408);
    assert.equal(pids('slow-pids').length, encoders, 'no encoder ran for the stalled upload');
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
  assert.equal(paceKbps('0.5'), 1);
  assert.equal(paceKbps('1e300'), 10_000_000);
  assert.equal(paceKbps('Infinity'), 10_000_000);
  assert.equal(paceKbps('0'), null);
  assert.equal(paceKbps('NaN'), null);
  assert.equal(paceKbps('-5'), null);
  assert.equal(paceKbps('-Infinity'), null);
  assert.equal(paceKbps('abc'), null);
  assert.equal(paceKbps(null), null);
  assert.equal(paceKbps('800'), 800);
  // 125 bytes at 1 kbit/s take 1 s: none of them in the first half second
  // (unclamped, 1e-300 would be due after a timer's longest wait, which
  // Node shortens to 1 ms), all of them in a few seconds (not never); the
  // headers leave at once.
  fs.writeFileSync(join(root, 'tiny.kdm'), model.subarray(0, 125));
  try {
    const timeline = await new Promise((resolveRead, reject) => {
      const started = Date.now();
      const seen = { headers: null, byHalf: 0, bytes: 0, end: null };
      const req = http.get({ host: '127.0.0.1', port, path: '/models/tiny.kdm?throttle=1e-300', agent: false }, (res) => {
        seen.headers = Date.now() - started;
        res.on('data', (c) => (seen.bytes += c.length));
        res.on('end', () => { seen.end = Date.now() - started; resolveRead(seen); });
      });
      setTimeout(() => (seen.byHalf = seen.bytes), 500);
      req.on('error', reject);
      req.setTimeout(15_000, () => req.destroy(new Error('no answer in 15 s')));
    });
    assert.ok(timeline.headers < 800, `headers after ${timeline.headers} ms`);
    assert.equal(timeline.byHalf, 0);
    assert.equal(timeline.bytes, 125);
    assert.ok(timeline.end >= 900 && timeline.end < 5000, `125 bytes in ${timeline.end} ms`);
  } finally {
    fs.rmSync(join(root, 'tiny.kdm'));
  }
  for (const throttle of ['1e300', 'Infinity', 'abc', '-1']) {
    const started = Date.now();
    const fast = await request(`/models/a.kdm?throttle=${throttle}`);
    assert.ok(fast.body.equals(model), throttle);
    assert.ok(Date.now() - started < 2000, `${throttle}: ${Date.now() - started} ms`);
  }
});

test('paced downloads keep their pace and their bytes', async () => {
  const started = Date.now();
  const paced = await request('/models/a.kdm?throttle=8000'); // 1000 bytes per ms: 200 ms
  const ms = Date.now() - started;
  assert.ok(paced.body.equals(model));
  assert.ok(ms >= 180 && ms < 5000, `${ms} ms`);
});

test('slow clients hold little memory, and those that leave stop being served', async () => {
  const big = Buffer.alloc(8 * 1024 * 1024, 7);
  fs.writeFileSync(join(root, 'big.kdm'), big);
  await request('/'); // warm up
  const descriptors = openDescriptors();
  const heap = process.memoryUsage().arrayBuffers;
  // 30 paced clients, and 10 unpaced ones that read nothing after their
  // first bytes.
  const open = (path) => new Promise((resolveClient) => {
    const req = http.get({ host: '127.0.0.1', port, path, agent: false }, (res) => {
      res.once('data', () => { res.pause(); resolveClient(req); });
    });
    req.on('error', () => {});
  });
  const clients = await Promise.all([
    ...Array.from({ length: 30 }, () => open('/models/big.kdm?throttle=80')),
    ...Array.from({ length: 10 }, () => open('/models/big.kdm')),
  ]);
  await sleep(500);
  const during = process.memoryUsage().arrayBuffers - heap;
  assert.ok(during < clients.length * big.length / 8, `${during} bytes held for ${clients.length} clients of an 8 MiB file`);
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
  await until(() => tempFolders().length === 0, 5000, 'temporary folders removed');
});
