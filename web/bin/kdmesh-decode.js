#!/usr/bin/env node
// kdmesh-decode: decodes a .kdm file with the WebAssembly decoder, for
// machines without the native build.
//
//   npx kdmesh-decode IN.kdm -o OUT.(ply|obj|json) [--bytes N]
import { readFileSync, writeFileSync } from 'node:fs';
import { decode, createDecoder, KdmeshError } from '../kdmesh.js';

const usage = 'usage: kdmesh-decode IN.kdm -o OUT.(ply|obj|json) [--bytes N]';

function parseArguments(argv) {
  const args = { input: null, output: null, bytes: 0 };
  for (let i = 0; i < argv.length; ++i) {
    const arg = argv[i];
    if (arg === '-h' || arg === '--help') {
      console.log(usage);
      process.exit(0);
    } else if (arg === '-o' || arg === '--output') {
      args.output = argv[++i];
    } else if (arg === '--bytes') {
      args.bytes = Number(argv[++i]);
      if (!Number.isInteger(args.bytes) || args.bytes <= 0) throw new Error('--bytes needs a positive integer');
    } else if (!args.input) {
      args.input = arg;
    } else {
      throw new Error(`unexpected argument ${arg}`);
    }
  }
  if (!args.input || !args.output) throw new Error(usage);
  return args;
}

// Binary little-endian PLY: every float32 bit is kept.
function toPly(model) {
  const header = ['ply', 'format binary_little_endian 1.0', 'comment written by kdmesh-decode',
    `element vertex ${model.vertexCount}`, 'property float x', 'property float y', 'property float z'];
  const lists = [['edge', model.edges, 2], ['face', model.triangles, 3], ['tetra', model.tetrahedra, 4]];
  for (const [name, list, arity] of lists) {
    if (list.length) header.push(`element ${name} ${list.length / arity}`, 'property list uchar uint vertex_indices');
  }
  const text = Buffer.from(header.join('\n') + '\nend_header\n');
  let size = text.length + model.positions.byteLength;
  for (const [, list, arity] of lists) size += (list.length / arity) * (1 + 4 * arity);
  const out = Buffer.alloc(size);
  text.copy(out);
  let at = text.length;
  Buffer.from(model.positions.buffer, model.positions.byteOffset, model.positions.byteLength).copy(out, at);
  at += model.positions.byteLength;
  for (const [, list, arity] of lists) {
    for (let i = 0; i < list.length; i += arity) {
      out[at++] = arity;
      for (let k = 0; k < arity; ++k, at += 4) out.writeUInt32LE(list[i + k], at);
    }
  }
  return out;
}

function toObj(model) {
  if (model.tetrahedra.length) throw new Error('OBJ cannot hold tetrahedra: write .ply or .json');
  const lines = ['# written by kdmesh-decode'];
  const p = model.positions;
  // 9 significant digits give back every float32.
  for (let i = 0; i < p.length; i += 3) lines.push(`v ${p[i].toPrecision(9)} ${p[i + 1].toPrecision(9)} ${p[i + 2].toPrecision(9)}`);
  for (const v of model.points) lines.push(`p ${v + 1}`);
  for (let i = 0; i < model.edges.length; i += 2) lines.push(`l ${model.edges[i] + 1} ${model.edges[i + 1] + 1}`);
  const t = model.triangles;
  for (let i = 0; i < t.length; i += 3) lines.push(`f ${t[i] + 1} ${t[i + 1] + 1} ${t[i + 2] + 1}`);
  return lines.join('\n') + '\n';
}

function toJson(model) {
  return JSON.stringify({
    vertexCount: model.vertexCount, complete: model.complete, stats: model.stats,
    positions: Array.from(model.positions), points: Array.from(model.points), edges: Array.from(model.edges),
    triangles: Array.from(model.triangles), tetrahedra: Array.from(model.tetrahedra),
  });
}

try {
  const args = parseArguments(process.argv.slice(2));
  let bytes = readFileSync(args.input);
  let model;
  if (args.bytes && args.bytes < bytes.length) {
    const decoder = await createDecoder();
    try {
      decoder.push(bytes.subarray(0, args.bytes));
      model = decoder.snapshot();
    } finally {
      decoder.dispose();
    }
  } else {
    model = await decode(bytes);
  }
  const extension = args.output.slice(args.output.lastIndexOf('.') + 1).toLowerCase();
  const writers = { ply: toPly, obj: toObj, json: toJson };
  if (!writers[extension]) throw new Error(`cannot write .${extension}: use .ply, .obj or .json`);
  writeFileSync(args.output, writers[extension](model));
} catch (error) {
  const code = error instanceof KdmeshError ? ` [${error.code}]` : '';
  console.error(`kdmesh-decode: error: ${error.message}${code}`);
  process.exit(1);
}
