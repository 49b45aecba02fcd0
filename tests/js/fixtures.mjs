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

// An ascii PLY of any complex (vertex, edge, face and tetra elements), with
// vertex attributes: each { name, type (a PLY type), properties (the PLY
// names of its components), values (properties.length per vertex) }.
export function writePly(path, { positions, edges = [], triangles = [], tetrahedra = [], attributes = [] }) {
  const n = positions.length / 3;
  const lines = ['ply', 'format ascii 1.0', `element vertex ${n}`, 'property float x', 'property float y', 'property float z'];
  for (const { type, properties } of attributes) for (const name of properties) lines.push(`property ${type} ${name}`);
  if (edges.length) lines.push(`element edge ${edges.length / 2}`, 'property int vertex1', 'property int vertex2');
  if (triangles.length) lines.push(`element face ${triangles.length / 3}`, 'property list uchar int vertex_indices');
  if (tetrahedra.length) lines.push(`element tetra ${tetrahedra.length / 4}`, 'property list uchar int vertex_indices');
  lines.push('end_header');
  for (let i = 0; i < n; ++i) {
    const values = attributes.flatMap(({ properties, values }) => values.slice(i * properties.length, (i + 1) * properties.length));
    lines.push([positions[3 * i], positions[3 * i + 1], positions[3 * i + 2], ...values].join(' '));
  }
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

// A torus with the attributes three.js draws: 'color' (uchar red green
// blue: red on one side, blue on the other), 'normal' (float nx ny nz: the
// torus's own normals, which differ from those of its triangles), 'uv'
// (float u v) and 'label' (short, negative values too). Float values are
// float32 numbers, so that the PLY's text holds them exactly.
export function colouredTorus(rows = 24, columns = 40) {
  const { positions, triangles } = torus(rows, columns);
  const color = [], normal = [], uv = [], label = [];
  for (let j = 0; j < rows; ++j)
    for (let i = 0; i < columns; ++i) {
      const a = (2 * Math.PI * i) / columns, b = (2 * Math.PI * j) / rows;
      const red = Math.round(127.5 + 127.5 * Math.cos(a));
      color.push(red, Math.round(60 + 40 * Math.sin(b)), 255 - red);
      normal.push(...[Math.cos(b) * Math.cos(a), Math.cos(b) * Math.sin(a), Math.sin(b)].map(Math.fround));
      uv.push(Math.fround(i / columns), Math.fround(j / rows));
      label.push(((37 * j + 11 * i) % 700) - 350);
    }
  return {
    positions, triangles, attributes: [
      { name: 'color', type: 'uchar', properties: ['red', 'green', 'blue'], values: color },
      { name: 'normal', type: 'float', properties: ['nx', 'ny', 'nz'], values: normal },
      { name: 'uv', type: 'float', properties: ['u', 'v'], values: uv },
      { name: 'label', type: 'short', properties: ['label'], values: label },
    ],
  };
}

// A torus of rows × columns quads, two triangles each, labelled by the
// quarter of the ring they lie in (labels -1, 10, 20, 30).
export function labelledTorus(rows = 20, columns = 36) {
  const positions = [], triangles = [], labels = [];
  for (let j = 0; j < rows; ++j)
    for (let i = 0; i < columns; ++i) {
      const a = (2 * Math.PI * i) / columns, b = (2 * Math.PI * j) / rows;
      positions.push(Math.fround((3 + Math.cos(b)) * Math.cos(a)), Math.fround((3 + Math.cos(b)) * Math.sin(a)),
        Math.fround(Math.sin(b)));
    }
  const id = (i, j) => (j % rows) * columns + (i % columns);
  const regions = [-1, 10, 20, 30];
  for (let j = 0; j < rows; ++j)
    for (let i = 0; i < columns; ++i) {
      triangles.push(id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1));
      const region = regions[Math.floor((4 * i) / columns)];
      labels.push(region, region);
    }
  return { positions, triangles, labels };
}

// The shape as an ascii PLY file (its triangles as faces, or its
// tetrahedra as tetras), with its labels as a property of those or without.
export function writeLabelledPly(path, { positions, triangles, tetrahedra, labels }, withLabels = true) {
  const [element, corners, list] = triangles ? ['face', 3, triangles] : ['tetra', 4, tetrahedra];
  const lines = ['ply', 'format ascii 1.0', `element vertex ${positions.length / 3}`, 'property float x',
    'property float y', 'property float z', `element ${element} ${list.length / corners}`,
    'property list uchar int vertex_indices', ...(withLabels ? ['property int label'] : []), 'end_header'];
  for (let i = 0; i < positions.length; i += 3) lines.push(positions.slice(i, i + 3).join(' '));
  for (let t = 0; t < labels.length; ++t)
    lines.push(`${corners} ${list.slice(corners * t, corners * t + corners).join(' ')}${withLabels ? ` ${labels[t]}` : ''}`);
  writeFileSync(path, lines.join('\n') + '\n');
}

// A point cloud with RGBA colours and a float 'intensity'; every tenth point
// repeats the previous one's position with other values.
export function colouredCloud(count = 2000, seed = 5) {
  const rand = random(seed);
  const positions = [], color = [], intensity = [];
  for (let i = 0; i < count; ++i) {
    if (i % 10 === 9) positions.push(...positions.slice(-3));
    else positions.push(rand() * 10 - 5, rand() * 10 - 5, rand() * 10 - 5);
    color.push(...[0, 1, 2, 3].map(() => Math.floor(256 * rand())));
    intensity.push(Math.fround(rand() * 1000 - 500));
  }
  return {
    positions, attributes: [
      { name: 'color', type: 'uchar', properties: ['red', 'green', 'blue', 'alpha'], values: color },
      { name: 'intensity', type: 'float', properties: ['intensity'], values: intensity },
    ],
  };
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
    const modes = { '-12': ['--bits', '12'], '-exact': ['--exact'], '-fast': ['--bits', '12', '--fast-decode'] };
    for (const [suffix, mode] of Object.entries(modes)) {
      const key = `${name}${suffix}`;
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

// PLY scalar types by name: the typed array that holds one.
const plyTypes = {
  char: Int8Array, int8: Int8Array, uchar: Uint8Array, uint8: Uint8Array, short: Int16Array, int16: Int16Array,
  ushort: Uint16Array, uint16: Uint16Array, int: Int32Array, int32: Int32Array, uint: Uint32Array, uint32: Uint32Array,
  float: Float32Array, float32: Float32Array, double: Float64Array, float64: Float64Array,
};

// Reads the binary PLY that `kdmesh decode` writes: positions, the lists of
// simplices, and `properties`, the vertex properties besides x, y and z by
// name, each a typed array of its own type.
function parsePly(buffer) {
  const end = buffer.indexOf('end_header\n') + 'end_header\n'.length;
  const header = buffer.subarray(0, end).toString('latin1').split('\n');
  const elements = [];
  for (const line of header) {
    const words = line.trim().split(/\s+/);
    if (words[0] === 'element') elements.push({ name: words[1], count: Number(words[2]), properties: [] });
    else if (words[0] === 'property') elements.at(-1).properties.push(words);
  }
  const model = { positions: null, points: [], edges: [], triangles: [], tetrahedra: [], properties: {} };
  const data = new DataView(buffer.buffer, buffer.byteOffset, buffer.byteLength);
  let at = end;
  for (const element of elements) {
    if (element.name === 'vertex') {
      const columns = element.properties.map(([, type, name]) => {
        const Type = plyTypes[type];
        const values = new Type(element.count);
        if (!'xyz'.includes(name)) model.properties[name] = values;
        return { values, bytes: Type.BYTES_PER_ELEMENT };
      });
      for (let i = 0; i < element.count; ++i) {
        for (const { values, bytes } of columns) {
          // Little-endian bytes into the value's own type, bit for bit.
          new Uint8Array(values.buffer, i * bytes, bytes).set(buffer.subarray(at, at + bytes));
          at += bytes;
        }
      }
      const [x, y, z] = ['x', 'y', 'z'].map((name) => columns[element.properties.findIndex((p) => p[2] === name)].values);
      model.positions = new Float32Array(3 * element.count);
      for (let i = 0; i < element.count; ++i) model.positions.set([x[i], y[i], z[i]], 3 * i);
      continue;
    }
    const list = element.name === 'edge' ? model.edges : element.name === 'face' ? model.triangles : model.tetrahedra;
    for (let i = 0; i < element.count; ++i) {
      if (element.properties[0][1] === 'list') {
        const count = buffer[at++];
        for (let k = 0; k < count; ++k, at += 4) list.push(data.getUint32(at, true));
      } else {
        for (let k = 0; k < element.properties.length; ++k, at += 4) list.push(data.getUint32(at, true));
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
