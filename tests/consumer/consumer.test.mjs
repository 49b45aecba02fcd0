// The npm package as an application meets it: `npm pack`, installed into a
// fresh folder with the lowest supported three.js, a page importing
// `kdmesh`, `kdmesh/three` and `kdmesh/gltf` bundled for production by vite, esbuild,
// webpack and Rollup, served by vite's dev server, and copied as plain
// files with an import map; each is served statically and loads a model in
// headless chromium, which must decode it exactly as Node does.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { copyFileSync, mkdirSync, mkdtempSync, readdirSync, readFileSync, rmSync, statSync, writeFileSync } from 'node:fs';
import { createServer } from 'node:http';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { launchChromium } from '../browser/chromium.mjs';
import sirv from 'sirv';
import { decode } from 'kdmesh';
import { modelChecksum } from '../../web/model-checksum.js';
import { root, cli } from '../js/fixtures.mjs';

// The oldest three.js the package supports (package.json peerDependencies).
const lowestThree = JSON.parse(readFileSync(join(root, 'package.json'), 'utf8')).peerDependencies.three.replace('>=', '');
const work = mkdtempSync(join(tmpdir(), 'kdmesh-consumer-'));
const app = join(work, 'app');
let browser, expected, decoded;

const run = (command, args, cwd) => execFileSync(command, args, { cwd, encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });

before(async () => {
  const [{ filename }] = JSON.parse(run('npm', ['pack', '--json', '--pack-destination', work], root));
  mkdirSync(join(app, 'src'), { recursive: true });
  mkdirSync(join(app, 'public'));
  writeFileSync(join(app, 'package.json'), JSON.stringify({
    name: 'kdmesh-consumer', private: true, type: 'module',
    dependencies: { kdmesh: `file:${join(work, filename)}`, three: lowestThree },
  }));
  run('npm', ['install', '--no-audit', '--no-fund', '--prefer-offline'], app);
  copyFileSync(join(root, 'tests', 'consumer', 'page.js'), join(app, 'src', 'main.js'));
  copyFileSync(join(root, 'web', 'model-checksum.js'), join(app, 'src', 'model-checksum.js'));
  run(cli, ['encode', join(root, 'build', 'models', 'fandisk.off'), '-o', join(app, 'public', 'model.kdm'), '--bits', '12', '-q'], root);
  // The same model as a glTF scene whose one primitive is a kdmesh stream.
  run(cli, ['decode', join(app, 'public', 'model.kdm'), '-o', join(work, 'model.glb'), '-q'], root);
  run(cli, ['encode', join(work, 'model.glb'), '-o', join(app, 'public', 'model.kdm.glb'), '--bits', '12', '-q'], root);
  decoded = await decode(readFileSync(join(app, 'public', 'model.kdm')));
  expected = modelChecksum(decoded);
  browser = await launchChromium();
});

after(async () => {
  await browser?.close();
  rmSync(work, { recursive: true, force: true });
});

const page = (script) => `<!doctype html><meta charset="utf-8"><link rel="icon" href="data:,"><title>kdmesh consumer</title>${script}`;

// An output folder laid out for a static host: the page, the bundle, the model.
function staticSite(dir, script) {
  writeFileSync(join(dir, 'index.html'), page(script));
  copyFileSync(join(app, 'public', 'model.kdm'), join(dir, 'model.kdm'));
  copyFileSync(join(app, 'public', 'model.kdm.glb'), join(dir, 'model.kdm.glb'));
}

function listen(handler) {
  const server = createServer(handler);
  return new Promise((resolve) => server.listen(0, '127.0.0.1', () => resolve(server)));
}

// Bytes of the files a bundler wrote, and whether it emitted a .wasm file.
function outputSize(dir) {
  let bytes = 0;
  const files = [];
  for (const name of readdirSync(dir, { recursive: true })) {
    const path = join(dir, name);
    if (statSync(path).isFile() && !name.endsWith('.kdm') && !name.endsWith('.glb') && !name.endsWith('.html')) {
      bytes += statSync(path).size;
      files.push(name);
    }
  }
  return { bytes, files };
}

// Opens `url` in a fresh context and returns the page's result.
async function load(url) {
  const context = await browser.newContext();
  const tab = await context.newPage();
  const errors = [];
  tab.on('pageerror', (error) => errors.push(error.message));
  // Requests that got no response. (Chromium sometimes reports a fetch whose
  // body was read to the end as aborted: the page saw it complete.)
  tab.on('requestfailed', async (request) => {
    if (!(await request.response())) errors.push(`${request.url()}: ${request.failure()?.errorText}`);
  });
  tab.on('response', (response) => response.status() >= 400 && errors.push(`${response.url()}: HTTP ${response.status()}`));
  await tab.goto(url);
  await tab.waitForFunction(() => window.result, null, { timeout: 60000 });
  const result = await tab.evaluate(() => window.result);
  const seen = [...errors];  // closing the page may cut requests short
  await context.close();
  return { result, errors: seen };
}

async function checkSite(t, dir, path = '/') {
  const server = await listen(sirv(dir, { dev: true }));
  try {
    const { result, errors } = await load(`http://127.0.0.1:${server.address().port}${path}`);
    assert.equal(result.error, undefined, result.error);
    assert.deepEqual(errors, []);
    assert.equal(result.revision, lowestThree.split('.')[1]);
    assert.equal(result.group, expected, 'the Group holds the model Node decodes');
    assert.equal(result.decode, expected, 'decode() on the main thread');
    assert.deepEqual(result.geometry, { vertices: decoded.vertexCount, indices: decoded.triangles.length, primitive: 'triangles' });
    assert.deepEqual(result.events, ['start', 'load', 'start', 'load'], 'LoadingManager events of the two loads');
    assert.deepEqual(result.gltf, { streams: 1, vertices: decoded.vertexCount, indices: decoded.triangles.length }, 'the glTF scene');
  } finally {
    server.close();
  }
}

function reportSize(t, name, dir) {
  const { bytes, files } = outputSize(dir);
  t.diagnostic(`${name}: ${files.length} files, ${bytes} bytes`);
  assert.ok(!files.some((file) => file.endsWith('.wasm')), `${name} emitted no second copy of the wasm: ${files}`);
}

test('vite build', async (t) => {
  const { build } = await import('vite');
  writeFileSync(join(app, 'index.html'), page('<script type="module" src="./src/main.js"></script>'));
  const out = join(work, 'vite');
  await build({ root: app, logLevel: 'error', configFile: false, build: { outDir: out, emptyOutDir: true } });
  reportSize(t, 'vite', out);
  await checkSite(t, out);
});

test('vite dev server', async () => {
  const { createServer: createViteServer } = await import('vite');
  writeFileSync(join(app, 'index.html'), page('<script type="module" src="./src/main.js"></script>'));
  const server = await createViteServer({ root: app, logLevel: 'error', configFile: false, server: { port: 0, host: '127.0.0.1' } });
  await server.listen();
  try {
    const { result, errors } = await load(server.resolvedUrls.local[0]);
    assert.equal(result.error, undefined, result.error);
    assert.deepEqual(errors, []);
    assert.equal(result.group, expected);
    assert.equal(result.decode, expected);
  } finally {
    await server.close();
  }
});

test('esbuild', async (t) => {
  const { build } = await import('esbuild');
  const out = join(work, 'esbuild');
  await build({
    entryPoints: [join(app, 'src', 'main.js')], absWorkingDir: app, bundle: true, format: 'esm', splitting: true,
    minify: true, outdir: out, logLevel: 'error',
  });
  staticSite(out, '<script type="module" src="./main.js"></script>');
  reportSize(t, 'esbuild', out);
  await checkSite(t, out);
});

test('webpack 5', async (t) => {
  const { default: webpack } = await import('webpack');
  const out = join(work, 'webpack');
  const stats = await new Promise((resolve, reject) => webpack({
    mode: 'production', context: app, entry: './src/main.js', output: { path: out, filename: 'main.js' },
  }, (error, result) => (error ? reject(error) : resolve(result))));
  assert.ok(!stats.hasErrors(), stats.toString('errors-only'));
  staticSite(out, '<script src="./main.js"></script>');
  reportSize(t, 'webpack', out);
  await checkSite(t, out);
});

test('Rollup', async (t) => {
  const { rollup } = await import('rollup');
  const { nodeResolve } = await import('@rollup/plugin-node-resolve');
  const out = join(work, 'rollup');
  const bundle = await rollup({ input: join(app, 'src', 'main.js'), plugins: [nodeResolve({ browser: true, rootDir: app })] });
  await bundle.write({ dir: out, format: 'es' });
  await bundle.close();
  staticSite(out, '<script type="module" src="./main.js"></script>');
  reportSize(t, 'rollup', out);
  await checkSite(t, out);
});

// The package's files served as they are, with an import map: the worker
// from the bundled source, and with ?selfhost=1 from kdmesh/worker and the
// .wasm file.
test('a plain static copy, with and without self-hosting', async (t) => {
  const site = join(app, 'static');
  mkdirSync(site, { recursive: true });
  copyFileSync(join(app, 'src', 'main.js'), join(site, 'main.js'));
  copyFileSync(join(app, 'src', 'model-checksum.js'), join(site, 'model-checksum.js'));
  staticSite(site, `<script type="importmap">${JSON.stringify({
    imports: {
      three: '/node_modules/three/build/three.module.js',
      'three/examples/jsm/': '/node_modules/three/examples/jsm/',
      kdmesh: '/node_modules/kdmesh/web/kdmesh.js',
      'kdmesh/three': '/node_modules/kdmesh/web/three.js',
      'kdmesh/gltf': '/node_modules/kdmesh/web/gltf.js',
    },
  })}</script><script type="module" src="./main.js"></script>`);
  await checkSite(t, app, '/static/');
  await checkSite(t, app, '/static/?selfhost=1');
});
