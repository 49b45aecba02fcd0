#!/usr/bin/env node
// The viewer's development server: static files, .kdm models paced to a
// simulated bandwidth, and on-the-fly encoding of mesh files with the native
// CLI. Any static host serves the viewer too (see README): only pacing and
// encoding need this server.
//
//   node web/server.mjs [--port 8080] [--root out] [--host 127.0.0.1]
//
// Routes: /            the viewer (web/index.html) and its modules
//         /vendor/three/...   three.js from node_modules
//         /models/            JSON list of the .kdm files in --root
//         /models/NAME?throttle=KBPS   a model, paced to KBPS kilobits per second
//         POST /encode?name=FILE.obj   encodes the body with build/kdmesh, returns .kdm
//                  (same-origin pages on this machine only; limited size, time and count)
// Static files are served with `send` (Range, conditional GET); no path or
// link leads out of a served folder.
import { createServer } from 'node:http';
import { spawn } from 'node:child_process';
import { createReadStream, createWriteStream, promises as fs } from 'node:fs';
import { tmpdir } from 'node:os';
import { basename, dirname, extname, join, relative, resolve, sep } from 'node:path';
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

// Serves a checked file with `send` (Range, conditional requests, types):
// read errors after the headers end the connection, before them are a 500.
function sendFile(request, response, file) {
  const path = '/' + file.relativePath.split(sep).map(encodeURIComponent).join('/');
  send(request, path, { root: file.root, dotfiles: 'allow', index: false, etag: true, lastModified: true, cacheControl: false })
    .on('headers', (res) => res.setHeader('cache-control', 'no-cache'))
    .on('error', (error) => {
      const status = error.status ?? error.statusCode ?? 500;
      if (status >= 500) console.error(`kdmesh server: ${request.url}: ${error.code ?? error.message}`);
      if (response.headersSent) response.destroy();
      else response.writeHead(status === 404 ? 404 : status >= 500 ? 500 : status, { 'content-type': 'text/plain' }).end(status === 404 ? 'not found' : 'cannot read file');
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

const sleep = (ms, signal) => new Promise((resolveSleep) => {
  const timer = setTimeout(done, ms);
  function done() { clearTimeout(timer); signal.removeEventListener('abort', done); resolveSleep(); }
  signal.addEventListener('abort', done, { once: true });
});

// Sends a file at `kbps` kilobits per second, in slices of 1 KiB or, at
// rates where 1 KiB takes less than 20 ms, of 20 ms of transfer (at most
// 1 MiB read at a time): a small model reaches the page in enough pieces to
// refine step by step. The file is streamed, a slice at a time, waiting for
// the socket to drain; everything stops when the client leaves.
async function sendPaced(response, file, kbps) {
  const bytesPerMs = kbps / 8;
  const slice = Math.min(maxPacedRead, Math.max(1024, Math.floor(20 * bytesPerMs)));
  const stream = createReadStream(join(file.root, file.relativePath), { highWaterMark: slice });
  const gone = new AbortController();
  response.on('close', () => { gone.abort(); stream.destroy(); });
  const ready = new Promise((resolveOpen, rejectOpen) => { stream.once('open', resolveOpen); stream.once('error', rejectOpen); });
  try {
    await ready;
  } catch (error) {
    console.error(`kdmesh server: ${file.relativePath}: ${error.code ?? error.message}`);
    if (!response.headersSent) response.writeHead(500, { 'content-type': 'text/plain' }).end('cannot read file');
    return;
  }
  response.writeHead(200, { 'content-type': 'application/octet-stream', 'content-length': file.size, 'cache-control': 'no-cache' });
  const start = Date.now();
  let sent = 0;
  try {
    for await (const chunk of stream) {
      if (gone.signal.aborted) break;
      sent += chunk.length;
      const due = start + sent / bytesPerMs;
      await sleep(Math.max(0, due - Date.now()), gone.signal);
      if (gone.signal.aborted) break;
      if (!response.write(chunk)) await new Promise((r) => { response.once('drain', r); gone.signal.addEventListener('abort', r, { once: true }); });
    }
    if (sent !== file.size) throw new Error(`file changed while served (${sent} of ${file.size} bytes)`);
    if (!gone.signal.aborted) response.end();
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

const loopbackNames = new Set(['localhost', '127.0.0.1', '[::1]']);

// Whether a request may use the encoder: its Host is a loopback name or the
// host the server listens on (a DNS-rebinding page has its own name there),
// and its Origin, when a browser sends one, is that same host over http.
export function sameOriginLocal(request, listenHost) {
  const host = String(request.headers.host ?? '').toLowerCase();
  const name = host.replace(/:\d+$/, '');
  const allowed = loopbackNames.has(name) || name.endsWith('.localhost') ||
    (listenHost && !['0.0.0.0', '::', ''].includes(listenHost) && name === (listenHost.includes(':') ? `[${listenHost}]` : listenHost).toLowerCase());
  if (!allowed) return false;
  const origin = request.headers.origin;
  if (origin !== undefined && origin.toLowerCase() !== `http://${host}`) return false;
  if (request.headers['sec-fetch-site'] && !['same-origin', 'none'].includes(request.headers['sec-fetch-site'])) return false;
  return true;
}

function plain(response, status, text, headers = {}) {
  if (response.headersSent || response.destroyed) return;
  response.writeHead(status, { 'content-type': 'text/plain; charset=utf-8', ...headers }).end(text);
}

// POST /encode: the body, at most `maxUploadBytes`, streamed to a temporary
// folder and encoded by the CLI; at most `maxEncoders` uploads and encodes at
// once (others 503), each killed after `encodeTimeoutMs` (504). When the
// client leaves, the upload stops, the encoder is killed and the folder is
// removed; the folder is removed after every request.
async function encode(request, response, name, state) {
  const { options } = state;
  if (!sameOriginLocal(request, options.host)) return plain(response, 403, 'encoding is for pages of this server on this machine');
  const extension = extname(name).toLowerCase();
  if (!['.obj', '.ply', '.off', '.stl', '.mesh', '.vtk', '.xyz'].includes(extension)) return plain(response, 400, `cannot encode ${extension} files`);
  const declared = Number(request.headers['content-length']);
  if (declared > options.maxUploadBytes) {
    request.resume();
    return plain(response, 413, `uploads are limited to ${options.maxUploadBytes} bytes`, { connection: 'close' });
  }
  if (state.encoders >= options.maxEncoders) {
    request.resume();
    return plain(response, 503, 'the encoder is busy; try again', { 'retry-after': '5', connection: 'close' });
  }
  state.encoders += 1;
  let child = null;
  let work = null;
  let finished = false;
  const cleanup = () => {
    if (finished) return;
    finished = true;
    state.encoders -= 1;
    if (child && child.exitCode === null && child.signalCode === null) child.kill('SIGKILL');
    if (work) fs.rm(work, { recursive: true, force: true }).catch(() => {});
  };
  response.on('close', cleanup);
  try {
    work = await fs.mkdtemp(join(tmpdir(), 'kdmesh-encode-'));
    if (finished) return cleanup();
    const input = join(work, `input${extension}`);
    const output = join(work, 'output.kdm');
    let received = 0;
    try {
      await pipeline(request, async function* limit(source) {
        for await (const chunk of source) {
          received += chunk.length;
          if (received > options.maxUploadBytes) throw new HttpError(413, `uploads are limited to ${options.maxUploadBytes} bytes`);
          yield chunk;
        }
      }, createWriteStream(input));
    } catch (error) {
      if (error instanceof HttpError) return plain(response, error.status, error.message, { connection: 'close' });
      return response.destroy();
    }
    if (finished) return;
    child = spawn(state.encoder, ['encode', input, '-o', output, '-q'], { stdio: ['ignore', 'ignore', 'pipe'] });
    let stderr = '';
    child.stderr.on('data', (d) => { if (stderr.length < 65536) stderr += d; });
    const timer = setTimeout(() => child.kill('SIGKILL'), options.encodeTimeoutMs);
    const [code, signal] = await new Promise((resolveExit) => {
      child.on('error', (error) => { stderr += String(error.message); resolveExit([-1, null]); });
      child.on('close', (c, s) => resolveExit([c, s]));
    });
    clearTimeout(timer);
    if (finished) return;
    if (code === 0) {
      const file = { root: work, relativePath: 'output.kdm' };
      sendFile(request, response, file);
    } else if (signal === 'SIGKILL') plain(response, 504, `encoding took longer than ${options.encodeTimeoutMs} ms`);
    else plain(response, 422, encoderError(stderr, input, basename(name)) || `kdmesh exited with ${code ?? signal}`);
  } catch (error) {
    console.error(`kdmesh server: encode: ${error.code ?? error.message}`);
    plain(response, 500, 'internal error');
    cleanup();
  }
}

// The .kdm files directly in `root` with their sizes: regular files only,
// links followed only when they stay inside `root`.
async function listModels(root) {
  let names;
  try { names = (await fs.readdir(root)).filter((n) => n.endsWith('.kdm')).sort(); } catch { return []; }
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
  const state = { options, encoders: 0, encoder: options.encoder ?? join(repo, 'build', 'kdmesh') };
  const three = join(repo, 'node_modules', 'three');
  const server = createServer(async (request, response) => {
    try {
      const url = new URL(request.url, 'http://localhost');
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
