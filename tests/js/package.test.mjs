// What `npm pack` ships: every file package.json's exports, types and bin
// name, and every file the shipped Markdown links to.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import { dirname, join, normalize } from 'node:path';
import { root } from './fixtures.mjs';

const [pack] = JSON.parse(execFileSync('npm', ['pack', '--dry-run', '--json'], { cwd: root, encoding: 'utf8', stdio: ['ignore', 'pipe', 'ignore'] }));
const shipped = new Set(pack.files.map((file) => file.path));

test('every export, type declaration and bin of package.json is in the package', () => {
  const manifest = JSON.parse(readFileSync(join(root, 'package.json'), 'utf8'));
  const targets = [manifest.types, ...Object.values(manifest.bin)];
  for (const entry of Object.values(manifest.exports)) targets.push(...(typeof entry === 'string' ? [entry] : Object.values(entry)));
  for (const target of targets) assert.ok(shipped.has(normalize(target)), `${target} is shipped`);
  assert.ok(targets.length >= 8);
});

test('the links of the shipped Markdown files resolve inside the package', () => {
  const markdown = [...shipped].filter((path) => path.endsWith('.md'));
  assert.ok(markdown.includes('README.md'));
  let links = 0;
  for (const file of markdown) {
    for (const [, target] of readFileSync(join(root, file), 'utf8').matchAll(/\]\(([^)#\s]+)(?:#[^)]*)?\)/g)) {
      if (/^[a-z]+:/.test(target)) continue;
      ++links;
      assert.ok(shipped.has(normalize(join(dirname(file), target))), `${file} links to ${target}, which is not shipped`);
    }
  }
  assert.ok(links >= 5, `relative links checked: ${links}`);
});

test('the bundled worker is built from the current sources', async () => {
  const { bundleWorker, workerSourcePath } = await import('../../scripts/bundle-worker.mjs');
  assert.ok(readFileSync(workerSourcePath, 'utf8') === await bundleWorker(),
    'web/dist/kdmesh-worker-source.js is older than web/kdmesh-worker.js or web/kdmesh.js: run sh scripts/build-wasm.sh');
});
