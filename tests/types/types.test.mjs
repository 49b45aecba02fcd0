// The TypeScript declarations of kdmesh, kdmesh/three and kdmesh/gltf: a program using
// every export compiles with tsc --strict, a wrong use does not, and every
// runtime export has a declaration.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import * as kdmesh from 'kdmesh';

const here = dirname(fileURLToPath(import.meta.url));
const root = join(here, '..', '..');
const tsc = (project) => spawnSync(process.execPath, [join(root, 'node_modules', 'typescript', 'bin', 'tsc'), '-p', project], { encoding: 'utf8' });

test('a program using every export compiles with tsc --strict', () => {
  const result = tsc(here);
  assert.equal(result.status, 0, result.stdout + result.stderr);
});

test('wrong uses of the declarations are type errors', (t) => {
  // Inside the repository, so that `kdmesh` resolves to this package.
  mkdirSync(join(root, 'build'), { recursive: true });
  const dir = mkdtempSync(join(root, 'build', 'types-'));
  t.after(() => rmSync(dir, { recursive: true, force: true }));
  writeFileSync(join(dir, 'wrong.ts'), [
    "import { decode } from 'kdmesh';",
    "import { KDMeshLoader } from 'kdmesh/three';",
    'export const count: string = (await decode(new Uint8Array(1))).vertexCount;',
    "new KDMeshLoader().setWorkerLimit('4');",
    "new KDMeshLoader().loadProgressive('a.kdm', { tetrahedra: 'solid' });",
    "export const coding: 'lossy' = (await decode(new Uint8Array(1))).attributes.normal.coding;",
    "new KDMeshLoader().loadProgressive('a.kdm', { materials: ['red'] });",
  ].join('\n'));
  writeFileSync(join(dir, 'tsconfig.json'), JSON.stringify({ extends: join(here, 'tsconfig.json'), files: ['wrong.ts'] }));
  const result = tsc(dir);
  assert.notEqual(result.status, 0);
  for (const line of [3, 4, 5, 6, 7]) assert.match(result.stdout, new RegExp(`wrong\\.ts\\(${line},`), result.stdout);
});

test('every runtime export is declared', () => {
  const declared = (file) => new Set([...readFileSync(join(root, 'web', file), 'utf8')
    .matchAll(/^export (?:class|function|interface|type|const) (\w+)/gm)].map((m) => m[1]));
  const kdmeshTypes = declared('kdmesh.d.ts');
  for (const name of Object.keys(kdmesh)) assert.ok(kdmeshTypes.has(name), `kdmesh: ${name}`);
  // kdmesh/three and kdmesh/gltf need three's module graph, so their exports are read from the source.
  for (const entry of ['three', 'gltf']) {
    const types = declared(`${entry}.d.ts`);
    for (const [, name] of readFileSync(join(root, 'web', `${entry}.js`), 'utf8').matchAll(/^export (?:class|function|const) (\w+)/gm))
      assert.ok(types.has(name), `kdmesh/${entry}: ${name}`);
  }
});
