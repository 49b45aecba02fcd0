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
import { createServer } from 'node:http';
import { spawn } from 'node:child_process';
import { createReadStream, existsSync, mkdtempSync, promises as fs, readdirSync, statSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { basename, dirname, extname, join, normalize, resolve, sep } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const repo = resolve(here, '..');

function parseArguments(argv) {
  const args = { port: 8080, root: join(repo, 'out'), host: '127.0.0.1' };
  for (let i = 0; i < argv.length; ++i) {
    const [key, inline] = argv[i].split('=');
    const value = () => inline ?? argv[++i];
    if (key === '--port') args.port = Number(value());
    else if (key === '--root') args.root = resolve(value());
    else if (key === '--host') args.host = value();
    else if (key === '--help' || key === '-h') {
      console.log('usage: node web/server.mjs [--port 8080] [--root DIR] [--host 127.0.0.1]');
      process.exit(0);
    } else throw new Error(`unknown option ${argv[i]}`);
  }
  return args;
}

const types = {
  '.html': 'text/html; charset=utf-8', '.js': 'text/javascript; charset=utf-8', '.mjs': 'text/javascript; charset=utf-8',
  '.css': 'text/css; charset=utf-8', '.json': 'application/json', '.wasm': 'application/wasm',
  '.kdm': 'application/octet-stream', '.drc': 'application/octet-stream', '.png': 'image/png',
};

// A file under `base`, or null when the path escapes it or does not exist.
function within(base, path) {
  const full = normalize(join(base, decodeURIComponent(path)));
  if (full !== base && !full.startsWith(base + sep)) return null;
  return existsSync(full) && statSync(full).isFile() ? full : null;
}

function sendFile(response, file) {
  response.writeHead(200, { 'content-type': types[extname(file)] ?? 'application/octet-stream', 'content-length': statSync(file).size, 'cache-control': 'no-cache' });
  createReadStream(file).pipe(response);
}

// Sends a file at `kbps` kilobits per second, in slices of 1 KiB or, at
// rates where 1 KiB takes less than 20 ms, of 20 ms of transfer: a small
// model reaches the page in enough pieces to refine step by step.
async function sendPaced(response, file, kbps) {
  const bytes = await fs.readFile(file);
  response.writeHead(200, { 'content-type': 'application/octet-stream', 'content-length': bytes.length, 'cache-control': 'no-cache' });
  const bytesPerMs = kbps / 8;
  const slice = Math.max(1024, Math.floor(20 * bytesPerMs));
  const start = Date.now();
  for (let at = 0; at < bytes.length && !response.destroyed; at += slice) {
    const due = start + Math.min(bytes.length, at + slice) / bytesPerMs;
    await new Promise((r) => setTimeout(r, Math.max(0, due - Date.now())));
    response.write(bytes.subarray(at, Math.min(bytes.length, at + slice)));
  }
  response.end();
}

// The encoder's error for the page: the uploaded file's name instead of its
// temporary path, without the CLI's prefix, and printable: the message may
// quote bytes of a binary file.
function encoderError(stderr, input, name) {
  return stderr.split(input).join(name).replace(/kdmesh: error: /g, '')
    .replace(/[^\x20-\x7e\n\u00a0-\ufffc]+/g, ' ').trim();
}

async function encode(request, response, name) {
  const cli = join(repo, 'build', 'kdmesh');
  const extension = extname(name).toLowerCase();
  if (!['.obj', '.ply', '.off', '.stl', '.mesh', '.vtk', '.xyz'].includes(extension)) {
    response.writeHead(400, { 'content-type': 'text/plain' }).end(`cannot encode ${extension} files`);
    return;
  }
  const chunks = [];
  for await (const chunk of request) chunks.push(chunk);
  const work = mkdtempSync(join(tmpdir(), 'kdmesh-encode-'));
  const input = join(work, `input${extension}`);
  const output = join(work, 'output.kdm');
  writeFileSync(input, Buffer.concat(chunks));
  const child = spawn(cli, ['encode', input, '-o', output, '-q'], { stdio: ['ignore', 'ignore', 'pipe'] });
  let stderr = '';
  child.stderr.on('data', (d) => (stderr += d));
  child.on('close', async (code) => {
    if (code === 0) sendFile(response, output);
    else response.writeHead(422, { 'content-type': 'text/plain; charset=utf-8' }).end(encoderError(stderr, input, basename(name)) || `kdmesh exited with ${code}`);
    response.on('close', () => fs.rm(work, { recursive: true, force: true }));
  });
}

export function startServer({ port, root, host }) {
  const server = createServer(async (request, response) => {
    try {
      const url = new URL(request.url, 'http://localhost');
      const path = url.pathname;
      if (request.method === 'POST' && path === '/encode') return await encode(request, response, url.searchParams.get('name') ?? '');
      if (path === '/models/' || path === '/models') {
        const names = existsSync(root) ? readdirSync(root).filter((n) => n.endsWith('.kdm')).sort() : [];
        const list = names.map((name) => ({ name, bytes: statSync(join(root, name)).size }));
        response.writeHead(200, { 'content-type': 'application/json' }).end(JSON.stringify(list));
        return;
      }
      if (path.startsWith('/models/')) {
        const file = within(root, path.slice('/models/'.length));
        if (!file) return response.writeHead(404).end('no such model');
        const throttle = Number(url.searchParams.get('throttle') ?? 0);
        return throttle > 0 ? await sendPaced(response, file, throttle) : sendFile(response, file);
      }
      if (path.startsWith('/vendor/three/')) {
        const file = within(join(repo, 'node_modules', 'three'), path.slice('/vendor/three/'.length));
        return file ? sendFile(response, file) : response.writeHead(404).end();
      }
      const file = within(here, path === '/' ? 'index.html' : path.slice(1));
      return file ? sendFile(response, file) : response.writeHead(404).end('not found');
    } catch (error) {
      if (!response.headersSent) response.writeHead(500, { 'content-type': 'text/plain' });
      response.end(String(error));
    }
  });
  return new Promise((resolveListen) => server.listen(port, host, () => resolveListen(server)));
}

if (process.argv[1] && resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const args = parseArguments(process.argv.slice(2));
  const server = await startServer(args);
  const { port } = server.address();
  console.log(`kdmesh viewer: http://${args.host === '0.0.0.0' ? 'localhost' : args.host}:${port}/  (models from ${args.root})`);
}
