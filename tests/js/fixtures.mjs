// Inputs for the JavaScript tests, made with the native CLI (build/kdmesh)
// from complexes generated here, so that the WebAssembly decoder can be
// compared with the native one on the same streams.
import { execFileSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';

export const root = join(dirname(fileURLToPath(import.meta.url)), '..', '..');
export const cli = join(root, 'build', 'kdmesh');
export const workDir = mkdtempSync(join(tmpdir(), 'kdmesh-js-'));
process.on('exit', () => rmSync(workDir, { recursive: true, force: true }));

function random(seed) {
  let state = seed >>> 0;
  return () => {
    state = (Math.imul(state, 1664525) + 1013904223) >>> 0;
    return state / 2 ** 32;
  };
}

// An ascii PLY of any complex (vertex, edge, face and tetra elements).
function writePly(path, { positions, edges = [], triangles = [], tetrahedra = [] }) {
  const n = positions.length / 3;
  const lines = ['ply', 'format ascii 1.0', `element vertex ${n}`, 'property float x', 'property float y', 'property float z'];
  if (edges.length) lines.push(`element edge ${edges.length / 2}`, 'property int vertex1', 'property int vertex2');
  if (triangles.length) lines.push(`element face ${triangles.length / 3}`, 'property list uchar int vertex_indices');
  if (tetrahedra.length) lines.push(`element tetra ${tetrahedra.length / 4}`, 'property list uchar int vertex_indices');
  lines.push('end_header');
  for (let i = 0; i < n; ++i) lines.push(`${positions[3 * i]} ${positions[3 * i + 1]} ${positions[3 * i + 2]}`);
  for (let i = 0; i < edges.length; i += 2) lines.push(`${edges[i]} ${edges[i + 1]}`);
  for (let i = 0; i < triangles.length; i += 3) lines.push(`3 ${triangles[i]} ${triangles[i + 1]} ${triangles[i + 2]}`);
  for (let i = 0; i < tetrahedra.length; i += 4) lines.push(`4 ${tetrahedra.slice(i, i + 4).join(' ')}`);
  writeFileSync(path, lines.join('\n') + '\n');
}

function torus(rows, columns) {
  const positions = [];
  const triangles = [];
  for (let j = 0; j < rows; ++j)
    for (let i = 0; i < columns; ++i) {
      const a = (2 * Math.PI * i) / columns, b = (2 * Math.PI * j) / rows;
      positions.push((3 + Math.cos(b)) * Math.cos(a), (3 + Math.cos(b)) * Math.sin(a), Math.sin(b));
    }
  const id = (i, j) => (j % rows) * columns + (i % columns);
  for (let j = 0; j < rows; ++j)
    for (let i = 0; i < columns; ++i)
      triangles.push(id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1));
  return { positions, triangles };
}

function tetrahedralBlock(n, seed) {
  const rand = random(seed);
  const m = n + 1;
  const positions = [];
  for (let k = 0; k < m; ++k)
    for (let j = 0; j < m; ++j)
      for (let i = 0; i < m; ++i) positions.push(i + 0.4 * rand() - 0.2, j + 0.4 * rand() - 0.2, k + 0.4 * rand() - 0.2);
  const id = (p) => (p[2] * m + p[1]) * m + p[0];
  const tetrahedra = [];
  const orders = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
  for (let k = 0; k < n; ++k)
    for (let j = 0; j < n; ++j)
      for (let i = 0; i < n; ++i)
        for (const order of orders) {
          const p = [i, j, k];
          const t = [id(p)];
          for (const axis of order) {
            ++p[axis];
            t.push(id(p));
          }
          tetrahedra.push(...t);
        }
  return { positions, tetrahedra };
}

function mixed(seed) {
  const rand = random(seed);
  const positions = [];
  for (let i = 0; i < 120; ++i) positions.push(Math.floor(8 * rand()), Math.floor(8 * rand()), Math.floor(8 * rand()));
  const pick = () => Math.floor(120 * rand());
  const edges = [], triangles = [], tetrahedra = [];
  for (let s = 0; s < 90; ++s) {
    const d = 1 + (s % 3);
    const list = d === 1 ? edges : d === 2 ? triangles : tetrahedra;
    for (let k = 0; k <= d; ++k) list.push(pick());
  }
  return { positions, edges, triangles, tetrahedra };
}

function cloud(count, seed) {
  const rand = random(seed);
  const positions = [];
  for (let i = 0; i < 3 * count; ++i) positions.push(rand() * 10 - 5);
  return { positions };
}

/** name -> { kdm: path, bytes: Buffer } for every fixture, encoded at `bits` or exactly. */
export function makeFixtures() {
  const shapes = {
    torus: torus(24, 40),
    tetrahedra: tetrahedralBlock(4, 3),
    mixed: mixed(7),
    cloud: cloud(5000, 9),
  };
  const fixtures = {};
  for (const [name, complex] of Object.entries(shapes)) {
    const input = join(workDir, `${name}.ply`);
    writePly(input, complex);
    for (const mode of [['--bits', '12'], ['--exact']]) {
      const key = `${name}${mode.length === 1 ? '-exact' : '-12'}`;
      const kdm = join(workDir, `${key}.kdm`);
      execFileSync(cli, ['encode', input, '-o', kdm, '--chunk-bytes', '256', '-q', ...mode]);
      fixtures[key] = { kdm, bytes: readFileSync(kdm) };
    }
  }
  for (const model of ['triceratops.off', 'fandisk.off']) {
    const input = join(root, 'build', 'models', model);
    if (!existsSync(input)) throw new Error(`${input} is missing: run scripts/models.sh`);
    const kdm = join(workDir, `${model}.kdm`);
    execFileSync(cli, ['encode', input, '-o', kdm, '--bits', '12', '-q']);
    fixtures[model] = { kdm, bytes: readFileSync(kdm) };
  }
  return fixtures;
}

// Reads the binary PLY that `kdmesh decode` writes.
function parsePly(buffer) {
  const end = buffer.indexOf('end_header\n') + 'end_header\n'.length;
  const header = buffer.subarray(0, end).toString('latin1').split('\n');
  const elements = [];
  for (const line of header) {
    const words = line.trim().split(/\s+/);
    if (words[0] === 'element') elements.push({ name: words[1], count: Number(words[2]), properties: [] });
    else if (words[0] === 'property') elements.at(-1).properties.push(words);
  }
  const model = { positions: null, points: [], edges: [], triangles: [], tetrahedra: [] };
  let at = end;
  for (const element of elements) {
    if (element.name === 'vertex') {
      model.positions = new Float32Array(buffer.buffer.slice(buffer.byteOffset + at, buffer.byteOffset + at + 12 * element.count));
      at += 12 * element.count;
      continue;
    }
    const list = element.name === 'edge' ? model.edges : element.name === 'face' ? model.triangles : model.tetrahedra;
    for (let i = 0; i < element.count; ++i) {
      if (element.properties[0][1] === 'list') {
        const count = buffer[at++];
        for (let k = 0; k < count; ++k, at += 4) list.push(buffer.readUInt32LE(at));
      } else {
        for (let k = 0; k < element.properties.length; ++k, at += 4) list.push(buffer.readUInt32LE(at));
      }
    }
  }
  return model;
}

/** The native decoder's output for a stream, or for its first `bytes` bytes. */
export function nativeDecode(kdm, bytes = 0) {
  const out = join(workDir, 'native-out.ply');
  execFileSync(cli, ['decode', kdm, '-o', out, '-q', ...(bytes ? ['--bytes', String(bytes)] : [])]);
  return parsePly(readFileSync(out));
}
