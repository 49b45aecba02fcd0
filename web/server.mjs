#!/usr/bin/env node
// The viewer's development server, for local development and demos, not for
// hosting on a network: static files, .kdm models paced to a simulated
// bandwidth, and on-the-fly encoding of mesh files with the native CLI. Any
// static host serves the viewer too (see README): only pacing and encoding
// need this server.
//
//   node web/server.mjs [--port 8080] [--root out] [--host 127.0.0.1]
//                       [--max-upload-bytes N] [--max-encoders N] [--encode-timeout-ms N]
//
// Routes: /            the viewer (web/index.html) and its modules
//         /vendor/three/...   three.js from node_modules
//         /models/            JSON list of the .kdm, .glb and .gltf files in --root
//         /models/NAME?throttle=KBPS   a model, paced to KBPS kilobits per second
//         POST /encode?name=FILE.obj   encodes the body with build/kdmesh, returns .kdm
//                  (same-origin pages on this machine only; limited size, time and count)
// Static files are served with `send` (Range, conditional GET); no path or
// link leads out of a served folder, and no request ends the process.
import { createServer, STATUS_CODES } from 'node:http';
import { spawn } from 'node:child_process';
import { createReadStream, createWriteStream, promises as fs } from 'node:fs';
import { hostname, networkInterfaces, tmpdir } from 'node:os';
import { basename, dirname, extname, join, relative, resolve, sep } from 'node:path';
import { Transform } from 'node:stream';
import { pipeline } from 'node:stream/promises';
import { fileURLToPath } from 'node:url';
import send from 'send';

const here = dirname(fileURLToPath(import.meta.url));
const repo = resolve(here, '..');

// Limits of the encoder route and of pacing; startServer's options override
// the first three.
export const defaults = {
  maxUploadBytes: 256 * 1024 * 1024,
  maxEncoders: 2,
  encodeTimeoutMs: 120_000,
};
const minKbps = 1; // 1 kbit/s
const maxKbps = 10_000_000; // 10 Gbit/s
const maxPacedRead = 1024 * 1024; // bytes read from a paced file at a time

function parseArguments(argv) {
  const args = { port: 8080, root: join(repo, 'out'), host: '127.0.0.1' };
  const numbers = { '--max-upload-bytes': 'maxUploadBytes', '--max-encoders': 'maxEncoders', '--encode-timeout-ms': 'encodeTimeoutMs' };
  for (let i = 0; i < argv.length; ++i) {
    const [key, inline] = argv[i].split('=');
    const value = () => inline ?? argv[++i];
    if (key === '--port') args.port = Number(value());
    else if (key === '--root') args.root = resolve(value());
    else if (key === '--host') args.host = value();
    else if (key in numbers) args[numbers[key]] = Number(value());
    else if (key === '--help' || key === '-h') {
      console.log('usage: node web/server.mjs [--port 8080] [--root DIR] [--host 127.0.0.1]\n' +
        '         [--max-upload-bytes 268435456] [--max-encoders 2] [--encode-timeout-ms 120000]');
      process.exit(0);
    } else throw new Error(`unknown option ${argv[i]}`);
  }
  return args;
}

class HttpError extends Error {
  constructor(status, message) { super(message); this.status = status; }
}

const inside = (base, path) => path === base || path.startsWith(base.endsWith(sep) ? base : base + sep);

// The regular file a URL path names under `base`, as a path relative to the
// real `base`, after every symbolic link is resolved: null when the path or a
// link in it leads out of `base`, when nothing is there, or when it is not a
// regular file (a directory, a FIFO, a device). Malformed % escapes and NUL
// bytes are HttpError 400.
async function regularFileWithin(base, urlPath) {
  let decoded;
  try { decoded = decodeURIComponent(urlPath); } catch { throw new HttpError(400, 'malformed URL escape'); }
  if (decoded.includes('\0')) throw new HttpError(400, 'NUL in path');
  const full = resolve(base, '.' + sep + decoded);
  if (!inside(base, full)) return null;
  let realBase, real, stats;
  try {
    realBase = await fs.realpath(base);
    real = await fs.realpath(full);
    stats = await fs.stat(real);
  } catch { return null; }
  if (!inside(realBase, real) || !stats.isFile()) return null;
  return { root: realBase, relativePath: relative(realBase, real), size: stats.size };
}

// Serves a checked file with `send` (Range, conditional requests, types).
// An error before the first byte is a clean response (404 when the file has
// gone, 500 for a read error) without the headers `send` had set for the
// file; after it, or when the file ends short of its length (truncated while
// served), the connection is closed, so that the client sees an incomplete
// download instead of waiting for the missing bytes.
function sendFile(request, response, file) {
  const path = '/' + file.relativePath.split(sep).map(encodeURIComponent).join('/');
  const fail = (status, error, headers = {}) => {
    if (status >= 500) console.error(`kdmesh server: ${request.url}: ${error.code ?? error.message}`);
    if (response.headersSent) return response.destroy();
    for (const name of response.getHeaderNames()) response.removeHeader(name);
    plain(response, status, status >= 500 ? 'cannot read file' : STATUS_CODES[status] ?? 'error', headers);
  };
  send(request, path, { root: file.root, dotfiles: 'allow', index: false, etag: true, lastModified: true, cacheControl: false })
    .on('headers', (res) => res.setHeader('cache-control', 'no-cache'))
    .on('stream', (stream) => stream.on('end', () => {
      const length = Number(response.getHeader('content-length'));
      if (stream.bytesRead < length) fail(500, new Error(`file changed while served (${stream.bytesRead} of ${length} bytes)`));
    }))
    .on('error', (error) => {
      const status = error.status ?? error.statusCode ?? 500;
      fail(status >= 500 ? 500 : status, error, status === 416 ? error.headers : {});
    })
    .pipe(response);
}

// The pace of a throttle value, kilobits per second, clamped to 1 kbit/s ..
// 10 Gbit/s; 0, a negative or a non-number value is no pacing (null).
export function paceKbps(value) {
  const kbps = Number(value);
  if (!(kbps > 0)) return null;
  return Math.min(maxKbps, Math.max(minKbps, kbps));
}

// Resolves once `response` drains or the client is gone; either way its
// listeners go, so that a long paced download does not pile them up.
const whenDrainedOrGone = (response, signal) => new Promise((resolveWait) => {
  function done() {
    response.off('drain', done);
    signal.removeEventListener('abort', done);
    resolveWait();
  }
  response.once('drain', done);
  signal.addEventListener('abort', done, { once: true });
});

const sleep = (ms, signal) => new Promise((resolveSleep) => {
  const timer = setTimeout(done, ms);
  function done() { clearTimeout(timer); signal.removeEventListener('abort', done); resolveSleep(); }
  signal.addEventListener('abort', done, { once: true });
});

// Sends a file at `kbps` kilobits per second, in slices of 1 KiB or, at
// rates where 1 KiB takes less than 20 ms, of 20 ms of transfer (at most
// 1 MiB read at a time): a small model reaches the page in enough pieces to
// refine step by step. Each slice leaves when the pace allows it, so the
// whole file takes its size over the rate; the headers leave at once.
// The file is read a slice at a time, each written only once the socket has
// drained, so a slow client holds one slice in memory, not the file; when
// the client leaves, reading stops. A read error before the headers is 500
// (404 when the file has gone); after them, or when the file changes size
// while served, the connection is closed.
async function sendPaced(response, file, kbps) {
  const bytesPerMs = kbps / 8;
  const slice = Math.min(maxPacedRead, Math.max(1024, Math.floor(20 * bytesPerMs)));
  const stream = createReadStream(join(file.root, file.relativePath), { highWaterMark: slice });
  const gone = new AbortController();
  response.on('close', () => { gone.abort(); stream.destroy(); });
  const slices = stream[Symbol.asyncIterator]();
  let next;
  try {
    next = await slices.next();
  } catch (error) {
    if (gone.signal.aborted) return;
    const missing = error.code === 'ENOENT' || error.code === 'ENOTDIR';
    if (!missing) console.error(`kdmesh server: ${file.relativePath}: ${error.code ?? error.message}`);
    return plain(response, missing ? 404 : 500, missing ? 'no such model' : 'cannot read file');
  }
  response.writeHead(200, { 'content-type': 'application/octet-stream', 'content-length': file.size, 'cache-control': 'no-cache' });
  response.flushHeaders();
  const start = Date.now();
  let sent = 0;
  try {
    for (; !next.done; next = await slices.next()) {
      const chunk = next.value;
      sent += chunk.length;
      if (sent > file.size) break;
      await sleep(Math.max(0, start + sent / bytesPerMs - Date.now()), gone.signal);
      if (gone.signal.aborted) return;
      if (!response.write(chunk)) await whenDrainedOrGone(response, gone.signal);
      if (gone.signal.aborted) return;
    }
    if (sent !== file.size) throw new Error(`file changed while served (${sent} bytes read of ${file.size})`);
    response.end();
  } catch (error) {
    if (!gone.signal.aborted) console.error(`kdmesh server: ${file.relativePath}: ${error.code ?? error.message}`);
    response.destroy();
  } finally {
    stream.destroy();
  }
}

// The encoder's error for the page: the uploaded file's name instead of its
// temporary path, without the CLI's prefix, and printable: the message may
// quote bytes of a binary file.
function encoderError(stderr, input, name) {
  return stderr.split(input).join(name).replace(/kdmesh: error: /g, '')
    .replace(/[^\x20-\x7e\n\u00a0-\ufffc]+/g, ' ').trim();
}

const wildcardHosts = new Set(['', '0.0.0.0', '::', '[::]']);
const bracketed = (address) => (address.includes(':') && !address.startsWith('[') ? `[${address}]` : address).toLowerCase();

// The host names that name this machine in a Host header: the loopback
// names, *.localhost, the host the server listens on, the machine's own
// host name and the addresses of its interfaces (for a server listening on
// every interface and opened by address from another machine).
function isThisMachine(name, listenHost) {
  if (name === 'localhost' || name.endsWith('.localhost') || name === '127.0.0.1' || name === '[::1]') return true;
  if (listenHost && !wildcardHosts.has(listenHost) && name === bracketed(listenHost)) return true;
  if (name === hostname().toLowerCase()) return true;
  return Object.values(networkInterfaces()).flat().some((entry) => entry && name === bracketed(entry.address));
}

// Whether a request may use the encoder. Its Host must name this machine: a
// page of another site that had its DNS name rebound to this machine sends
// its own name there, and is the same origin as itself, so Origin alone
// does not tell it apart. Origin, when a browser sends one, must be this
// same host over http, and Sec-Fetch-Site, when sent, same-origin or none
// (typed in the address bar): a page of another origin is refused.
export function sameOriginLocal(request, listenHost) {
  const hostHeader = String(request.headers.host ?? '');
  if (!/^[\w.:\[\]-]+$/.test(hostHeader)) return false;
  let host;
  try { host = new URL(`http://${hostHeader}`); } catch { return false; }
  if (!isThisMachine(host.hostname.replace(/\.$/, ''), listenHost)) return false;
  const origin = request.headers.origin;
  if (origin !== undefined) {
    let from;
    try { from = new URL(origin); } catch { return false; }
    if (from.protocol !== 'http:' || from.host !== host.host) return false;
  }
  const site = request.headers['sec-fetch-site'];
  return site === undefined || site === 'same-origin' || site === 'none';
}

function plain(response, status, text, headers = {}) {
  if (response.headersSent || response.destroyed) return;
  response.writeHead(status, { 'content-type': 'text/plain; charset=utf-8', 'content-length': Buffer.byteLength(text), ...headers }).end(text);
}

// How long the rest of a refused upload is read and dropped before its
// connection is closed. Closing a socket with unread bytes makes the kernel
// reset the connection, and the client may then lose the answer; reading the
// rest lets it see the refusal (and keeps the connection usable).
const dropBodyMs = 5000;

// Answers `status` before the body has been read, reads the rest of the body
// and drops it, for at most `dropBodyMs`.
function refuse(request, response, status, text, headers = {}) {
  plain(response, status, text, headers);
  if (request.complete) return;
  request.resume();
  const timer = setTimeout(() => request.socket?.destroy(), dropBodyMs);
  const stop = () => clearTimeout(timer);
  request.once('end', stop);
  request.once('close', stop);
}

const meshExtensions = ['.obj', '.ply', '.off', '.stl', '.mesh', '.vtk', '.xyz'];

// POST /encode: the body, at most `maxUploadBytes` (413 otherwise, as soon as
// the limit is passed), streamed to a temporary folder and encoded by the
// CLI. At most `maxEncoders` requests upload or encode at once (others 503),
// each for at most `encodeTimeoutMs` from its start (408 while uploading, 504
// while encoding; the encoder is killed). When the client leaves, the upload
// stops and the encoder is killed. The folder is removed when the response
// ends, whichever way.
async function encode(request, response, name, state) {
  const { options } = state;
  if (!sameOriginLocal(request, options.host)) return refuse(request, response, 403, 'encoding is for pages of this server on this machine');
  const extension = extname(name).toLowerCase();
  if (!meshExtensions.includes(extension)) return refuse(request, response, 400, `cannot encode ${extension || 'extensionless'} files`);
  const tooBig = `uploads are limited to ${options.maxUploadBytes} bytes`;
  if (Number(request.headers['content-length']) > options.maxUploadBytes) return refuse(request, response, 413, tooBig);
  if (state.encoders >= options.maxEncoders) return refuse(request, response, 503, 'the encoder is busy; try again', { 'retry-after': '5' });
  state.encoders += 1;
  let child = null;
  let work = null;
  let finished = false;
  let timedOut = false;
  const removeWork = () => {
    if (work) fs.rm(work, { recursive: true, force: true }).catch(() => {});
    work = null;
  };
  const cleanup = () => {
    if (finished) return;
    finished = true;
    state.encoders -= 1;
    clearTimeout(deadline);
    if (child && child.exitCode === null && child.signalCode === null) child.kill('SIGKILL');
    removeWork();
  };
  const deadline = setTimeout(() => {
    timedOut = true;
    if (child) return child.kill('SIGKILL');
    // Node closes the connection once the answer is written, which ends the
    // upload.
    plain(response, 408, `the upload took longer than ${options.encodeTimeoutMs} ms`, { connection: 'close' });
  }, options.encodeTimeoutMs);
  response.on('close', cleanup);
  try {
    const folder = await fs.mkdtemp(join(tmpdir(), 'kdmesh-encode-'));
    work = folder;
    if (finished) return removeWork(); // the client left meanwhile
    const input = join(folder, `input${extension}`);
    const output = join(folder, 'output.kdm');
    let received = 0;
    let over = false;
    const limit = new Transform({
      transform(chunk, _encoding, done) {
        received += chunk.length;
        if (received <= options.maxUploadBytes) return done(null, chunk);
        if (!over) { over = true; refuse(request, response, 413, tooBig); }
        done();
      },
    });
    try {
      await pipeline(request, limit, createWriteStream(input));
    } catch (error) {
      if (!finished && error.code !== 'ECONNRESET') console.error(`kdmesh server: encode: upload: ${error.code ?? error.message}`);
      return response.destroy();
    }
    if (finished || over) return;
    child = spawn(state.encoder, ['encode', input, '-o', output, '-q'], { stdio: ['ignore', 'ignore', 'pipe'] });
    let stderr = '';
    child.stderr.on('data', (d) => { if (stderr.length < 65536) stderr += d; });
    const [code, signal, spawnError] = await new Promise((resolveExit) => {
      child.on('error', (error) => resolveExit([null, null, error]));
      child.on('close', (c, s) => resolveExit([c, s, null]));
    });
    if (finished) return;
    if (spawnError) {
      console.error(`kdmesh server: encode: cannot run ${state.encoder}: ${spawnError.code ?? spawnError.message}`);
      plain(response, 500, 'cannot run the encoder (build it with npm run build)');
    } else if (code === 0) sendFile(request, response, { root: folder, relativePath: 'output.kdm' });
    else if (timedOut) plain(response, 504, `encoding took longer than ${options.encodeTimeoutMs} ms`);
    else plain(response, 422, encoderError(stderr, input, basename(name)) || `kdmesh exited with ${code ?? signal}`);
  } catch (error) {
    console.error(`kdmesh server: encode: ${error.code ?? error.message}`);
    plain(response, 500, 'internal error');
    cleanup();
  }
}

// The .kdm files and glTF scenes (.glb, .gltf) directly in `root` with
// their sizes: regular files only, links followed only when they stay
// inside `root`.
async function listModels(root) {
  let names;
  try { names = (await fs.readdir(root)).filter((n) => /\.(kdm|glb|gltf)$/.test(n)).sort(); } catch { return []; }
  const list = [];
  for (const name of names) {
    const file = await regularFileWithin(root, encodeURIComponent(name));
    if (file) list.push({ name, bytes: file.size });
  }
  return list;
}

// Starts the server. Options: port, root (the .kdm models), host, and the
// encoder's limits (see `defaults`); `encoder` is the CLI to run.
export function startServer({ port, root, host, ...limits } = {}) {
  root = resolve(root ?? join(repo, 'out'));
  const options = { ...defaults, host, ...Object.fromEntries(Object.entries(limits).filter(([, v]) => v !== undefined)) };
  for (const key of Object.keys(defaults)) {
    if (!(Number.isSafeInteger(options[key]) && options[key] > 0)) throw new Error(`${key} must be a positive integer, not ${options[key]}`);
  }
  const state = { options, encoders: 0, encoder: options.encoder ?? join(repo, 'build', 'kdmesh') };
  const three = join(repo, 'node_modules', 'three');
  const server = createServer(async (request, response) => {
    try {
      // A path (origin form) or a whole URL (absolute form); `new URL` also
      // resolves . and .. segments, %2e%2e included.
      let url;
      try { url = request.url.startsWith('/') ? new URL(`http://localhost${request.url}`) : new URL(request.url); } catch { throw new HttpError(400, 'malformed URL'); }
      const path = url.pathname;
      if (path === '/encode') {
        if (request.method !== 'POST') return plain(response, 405, 'POST a mesh file', { allow: 'POST' });
        return await encode(request, response, url.searchParams.get('name') ?? '', state);
      }
      if (request.method !== 'GET' && request.method !== 'HEAD') return plain(response, 405, 'method not allowed', { allow: 'GET, HEAD' });
      if (path === '/models/' || path === '/models') {
        response.writeHead(200, { 'content-type': 'application/json', 'cache-control': 'no-cache' }).end(JSON.stringify(await listModels(root)));
        return;
      }
      if (path.startsWith('/models/')) {
        const file = await regularFileWithin(root, path.slice('/models/'.length));
        if (!file) return plain(response, 404, 'no such model');
        const kbps = paceKbps(url.searchParams.get('throttle'));
        return kbps && request.method === 'GET' ? await sendPaced(response, file, kbps) : sendFile(request, response, file);
      }
      const [base, rest] = path.startsWith('/vendor/three/') ? [three, path.slice('/vendor/three/'.length)] : [here, path === '/' ? 'index.html' : path.slice(1)];
      const file = await regularFileWithin(base, rest);
      return file ? sendFile(request, response, file) : plain(response, 404, 'not found');
    } catch (error) {
      if (error instanceof HttpError) return plain(response, error.status, error.message);
      console.error(`kdmesh server: ${request.url}: ${error.stack ?? error}`);
      if (!response.headersSent) plain(response, 500, 'internal error');
      else response.destroy();
    }
  });
  server.on('clientError', (error, socket) => {
    if (socket.writable && !socket.destroyed) socket.end('HTTP/1.1 400 Bad Request\r\nconnection: close\r\n\r\n');
    else socket.destroy();
  });
  return new Promise((resolveListen, rejectListen) => {
    server.once('error', rejectListen);
    server.listen(port, host, () => { server.off('error', rejectListen); resolveListen(server); });
  });
}

if (process.argv[1] && resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const args = parseArguments(process.argv.slice(2));
  const server = await startServer(args);
  const { port } = server.address();
  console.log(`kdmesh viewer: http://${args.host === '0.0.0.0' ? 'localhost' : args.host}:${port}/  (models from ${args.root})`);
}
