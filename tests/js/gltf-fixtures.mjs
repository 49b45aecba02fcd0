// glTF scenes for the JavaScript tests, written as .glb here: the inputs
// that the native CLI encodes with KDMESH_progressive_compression.
import { writeFileSync } from 'node:fs';
import { colouredTorus } from './fixtures.mjs';

const FLOAT = 5126, UNSIGNED_BYTE = 5121, UNSIGNED_SHORT = 5123;

// Builds the JSON and binary chunk of a scene, accessor by accessor.
class GlbBuilder {
  constructor() {
    this.json = { asset: { version: '2.0', generator: 'kdmesh tests' }, buffers: [{ byteLength: 0 }], bufferViews: [], accessors: [] };
    this.chunks = [];
    this.length = 0;
  }

  view(bytes, target) {
    const padding = (4 - (this.length % 4)) % 4;
    if (padding) this.chunks.push(new Uint8Array(padding));
    this.length += padding;
    this.json.bufferViews.push({ buffer: 0, byteOffset: this.length, byteLength: bytes.byteLength, ...(target && { target }) });
    this.chunks.push(new Uint8Array(bytes.buffer, bytes.byteOffset, bytes.byteLength));
    this.length += bytes.byteLength;
    return this.json.bufferViews.length - 1;
  }

  accessor(array, componentType, type, { normalized = false, target, bounds = false } = {}) {
    const size = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 }[type];
    const accessor = { bufferView: this.view(array, target), componentType, count: array.length / size, type };
    if (normalized) accessor.normalized = true;
    if (bounds) {
      accessor.min = Array.from({ length: size }, (_, c) => Math.min(...array.filter((_, i) => i % size === c)));
      accessor.max = Array.from({ length: size }, (_, c) => Math.max(...array.filter((_, i) => i % size === c)));
    }
    this.json.accessors.push(accessor);
    return this.json.accessors.length - 1;
  }

  glb() {
    const bin = new Uint8Array((this.length + 3) & ~3);
    let offset = 0;
    for (const chunk of this.chunks) {
      bin.set(chunk, offset);
      offset += chunk.length;
    }
    this.json.buffers[0].byteLength = this.length;
    let text = JSON.stringify(this.json);
    text += ' '.repeat((4 - (text.length % 4)) % 4);
    const json = new TextEncoder().encode(text);
    const out = new Uint8Array(12 + 8 + json.length + 8 + bin.length);
    const view = new DataView(out.buffer);
    view.setUint32(0, 0x46546c67, true);
    view.setUint32(4, 2, true);
    view.setUint32(8, out.length, true);
    view.setUint32(12, json.length, true);
    view.setUint32(16, 0x4e4f534a, true);
    out.set(json, 20);
    view.setUint32(20 + json.length, bin.length, true);
    view.setUint32(24 + json.length, 0x004e4942, true);
    out.set(bin, 28 + json.length);
    return out;
  }
}

// A scene of three meshes under a node hierarchy: a torus with normals,
// texture coordinates and vertex colours (indexed triangles), a mesh with
// a line loop and a point cloud, and a quad with a morph target, which
// stays uncompressed (a scene mixing compressed and plain primitives).
export function writeTestScene(path, { rows = 24, columns = 40 } = {}) {
  const b = new GlbBuilder();
  const torus = colouredTorus(rows, columns);
  const byName = Object.fromEntries(torus.attributes.map((a) => [a.name, a.values]));
  const colours = new Uint8Array(torus.positions.length / 3 * 4);
  for (let v = 0; v < colours.length / 4; ++v) colours.set([...byName.color.slice(3 * v, 3 * v + 3), 255], 4 * v);
  const torusPrimitive = {
    attributes: {
      POSITION: b.accessor(Float32Array.from(torus.positions), FLOAT, 'VEC3', { bounds: true, target: 34962 }),
      NORMAL: b.accessor(Float32Array.from(byName.normal), FLOAT, 'VEC3', { target: 34962 }),
      TEXCOORD_0: b.accessor(Float32Array.from(byName.uv), FLOAT, 'VEC2', { target: 34962 }),
      COLOR_0: b.accessor(colours, UNSIGNED_BYTE, 'VEC4', { normalized: true, target: 34962 }),
    },
    indices: b.accessor(Uint16Array.from(torus.triangles), UNSIGNED_SHORT, 'SCALAR', { target: 34963 }),
    material: 0,
  };
  const ring = [];
  for (let i = 0; i < 16; ++i) ring.push(Math.cos(i / 16 * 2 * Math.PI) * 5, Math.sin(i / 16 * 2 * Math.PI) * 5, 0);
  const cloud = [];
  for (let i = 0; i < 300; ++i) cloud.push(Math.fround((i * 37 % 101) / 10), Math.fround((i * 53 % 97) / 10), Math.fround((i % 7) - 3));
  const quad = Float32Array.from([0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0]);
  Object.assign(b.json, {
    scene: 0,
    scenes: [{ nodes: [0] }],
    nodes: [
      { name: 'root', children: [1, 2, 3], translation: [0, 0, -2], extras: { note: 'kept' } },
      { name: 'torus', mesh: 0 },
      { name: 'wire and cloud', mesh: 1, scale: [0.5, 0.5, 0.5] },
      { name: 'quad', mesh: 2, translation: [6, 0, 0] },
    ],
    materials: [{ name: 'coloured', pbrMetallicRoughness: { roughnessFactor: 0.4 } }, { name: 'flat', pbrMetallicRoughness: { baseColorFactor: [1, 0.5, 0, 1] } }],
    meshes: [
      { name: 'torus', primitives: [torusPrimitive] },
      {
        name: 'wire and cloud', primitives: [
          { attributes: { POSITION: b.accessor(Float32Array.from(ring), FLOAT, 'VEC3', { bounds: true }) }, mode: 2, material: 1 },
          { attributes: { POSITION: b.accessor(Float32Array.from(cloud), FLOAT, 'VEC3', { bounds: true }) }, mode: 0 },
        ],
      },
      {
        name: 'quad', weights: [0], primitives: [{
          attributes: { POSITION: b.accessor(quad, FLOAT, 'VEC3', { bounds: true }) },
          indices: b.accessor(Uint16Array.from([0, 1, 2, 0, 2, 3]), UNSIGNED_SHORT, 'SCALAR'),
          targets: [{ POSITION: b.accessor(Float32Array.from([0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1]), FLOAT, 'VEC3', { bounds: true }) }],
          material: 1,
        }],
      },
    ],
  });
  writeFileSync(path, b.glb());
  return b.json;
}

// The JSON chunk of a .glb and its binary chunk.
export function readGlb(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const jsonLength = view.getUint32(12, true);
  const json = JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + jsonLength)));
  const binLength = bytes.length > 28 + jsonLength ? view.getUint32(20 + jsonLength, true) : 0;
  return { json, bin: bytes.subarray(28 + jsonLength, 28 + jsonLength + binLength) };
}
