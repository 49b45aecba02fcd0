// glTF scenes with KDMESH_progressive_compression: the native CLI's output
// checked by the Khronos glTF validator, its streams decoded by the
// WebAssembly decoder against the accessors, and the GLTFLoader plugin's
// wiring (kdmesh/gltf) with a recording stand-in for KDMeshLoader (Node has
// no Web Workers; tests/browser/gltf.test.mjs decodes for real).
import { test, before } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync, existsSync } from 'node:fs';
import { join, dirname } from 'node:path';
import validator from 'gltf-validator';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { decode } from 'kdmesh';
import { KDMeshGLTFExtension, EXTENSION_NAME } from 'kdmesh/gltf';
import { cli, colouredTorus, workDir, writePly } from './fixtures.mjs';
import { writeTestScene, readGlb } from './gltf-fixtures.mjs';

const input = join(workDir, 'scene.glb');
let scene;

before(() => {
  scene = writeTestScene(input);
  execFileSync(cli, ['encode', input, '-o', join(workDir, 'scene.kdm.glb'), '-q']);
  execFileSync(cli, ['encode', input, '-o', join(workDir, 'streams.kdm.gltf'), '--kdm-files', '-q']);
  execFileSync(cli, ['encode', input, '-o', join(workDir, 'uris.kdm.glb'), '--kdm-files', '-q']);
  execFileSync(cli, ['decode', join(workDir, 'scene.kdm.glb'), '-o', join(workDir, 'plain.glb'), '-q']);
  execFileSync(cli, ['encode', input, '-o', join(workDir, 'fallback.kdm.glb'), '--fallback', '-q']);
  // A complex written as a scene: the torus of the PLY tests, with its attributes.
  writePly(join(workDir, 'torus.ply'), colouredTorus());
  execFileSync(cli, ['encode', join(workDir, 'torus.ply'), '-o', join(workDir, 'torus.kdm'), '-q']);
  execFileSync(cli, ['decode', join(workDir, 'torus.kdm'), '-o', join(workDir, 'torus.glb'), '-q']);
});

async function validate(path) {
  return validator.validateBytes(new Uint8Array(readFileSync(path)), {
    uri: path,
    externalResourceFunction: async (uri) => new Uint8Array(readFileSync(join(dirname(path), decodeURIComponent(uri)))),
  });
}

function errorsOf(report) {
  return report.issues.messages.filter((m) => m.severity === 0).map((m) => `${m.code} ${m.pointer}: ${m.message}`);
}

test('the validator finds no errors in the input, the encoded scenes and the decoded scene', async () => {
  for (const name of ['scene.glb', 'scene.kdm.glb', 'streams.kdm.gltf', 'plain.glb', 'fallback.kdm.glb', 'torus.glb']) {
    const report = await validate(join(workDir, name));
    assert.deepEqual(errorsOf(report), [], name);
    assert.ok(report.info.totalVertexCount > 0 || name.includes('kdm'), name);
  }
});

test('a fallback is not required, and a complex\'s attributes get their glTF semantics', () => {
  const { json } = readGlb(readFileSync(join(workDir, 'fallback.kdm.glb')));
  assert.deepEqual(json.extensionsUsed, [EXTENSION_NAME]);
  assert.equal(json.extensionsRequired, undefined);
  const [torus] = json.meshes[0].primitives;
  assert.ok(torus.extensions[EXTENSION_NAME]);
  assert.ok(json.accessors[torus.attributes.POSITION].bufferView !== undefined);
  const scene = readGlb(readFileSync(join(workDir, 'torus.glb'))).json;
  const [primitive] = scene.meshes[0].primitives;
  assert.deepEqual(Object.keys(primitive.attributes).sort(), ['COLOR_0', 'NORMAL', 'POSITION', 'TEXCOORD_0', '_LABEL']);
  assert.equal(scene.accessors[primitive.attributes.COLOR_0].normalized, true);
});

test('the validator reports errors where there are some', async () => {
  // The test above must be able to fail: an index beyond the vertices.
  const bytes = readFileSync(input);
  const { json, bin } = readGlb(bytes);
  const view = json.bufferViews[json.accessors[json.meshes[0].primitives[0].indices].bufferView];
  const offset = bytes.length - bin.length + view.byteOffset;
  bytes.writeUInt16LE(60000, offset);
  const report = await validator.validateBytes(new Uint8Array(bytes));
  assert.ok(errorsOf(report).length > 0);
});

test('compressed primitives name their streams; the scene around them is the input\'s', () => {
  const { json } = readGlb(readFileSync(join(workDir, 'scene.kdm.glb')));
  assert.deepEqual(json.extensionsUsed, [EXTENSION_NAME]);
  assert.deepEqual(json.extensionsRequired, [EXTENSION_NAME]);
  assert.deepEqual(json.nodes, scene.nodes);
  assert.deepEqual(json.materials, scene.materials);
  assert.deepEqual(json.meshes.map((m) => m.name), scene.meshes.map((m) => m.name));
  const [torus] = json.meshes[0].primitives;
  assert.deepEqual(torus.extensions[EXTENSION_NAME].attributes, { NORMAL: 'NORMAL', TEXCOORD_0: 'TEXCOORD_0', COLOR_0: 'COLOR_0' });
  const [loop, cloud] = json.meshes[1].primitives;
  assert.equal(loop.mode, 1);  // the line loop became a line list
  assert.equal(cloud.mode, 0);
  // The quad's morph target keeps it uncompressed, with its data.
  const [quad] = json.meshes[2].primitives;
  assert.equal(quad.extensions, undefined);
  assert.ok(json.accessors[quad.attributes.POSITION].bufferView !== undefined);
  assert.ok(readFileSync(join(workDir, 'scene.kdm.glb')).length < readFileSync(input).length);
});

test('each stream decodes to the counts and attributes of its accessors', async () => {
  const { json, bin } = readGlb(readFileSync(join(workDir, 'scene.kdm.glb')));
  const streamed = readGlb(readFileSync(input)).json;
  let streams = 0;
  for (const [m, mesh] of json.meshes.entries()) {
    for (const [p, primitive] of mesh.primitives.entries()) {
      const extension = primitive.extensions?.[EXTENSION_NAME];
      if (!extension) continue;
      streams += 1;
      const view = json.bufferViews[extension.bufferView];
      const model = await decode(bin.subarray(view.byteOffset, view.byteOffset + view.byteLength));
      assert.ok(model.complete);
      assert.equal(model.vertexCount, json.accessors[primitive.attributes.POSITION].count, `mesh ${m} primitive ${p}`);
      // Every vertex of the input primitives is drawn: the counts are the input's.
      assert.equal(model.vertexCount, streamed.accessors[streamed.meshes[m].primitives[p].attributes.POSITION].count);
      const list = primitive.mode === 4 ? model.triangles : primitive.mode === 1 ? model.edges : null;
      if (list) assert.equal(list.length, json.accessors[primitive.indices].count);
      else assert.equal(primitive.indices, undefined);
      for (const [semantic, name] of Object.entries(extension.attributes ?? {})) {
        const accessor = json.accessors[primitive.attributes[semantic]];
        const { itemSize, array } = model.attributes[name];
        assert.equal(itemSize, { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 }[accessor.type]);
        assert.equal(array.length, accessor.count * itemSize);
      }
    }
  }
  assert.equal(streams, 3);
  // The separate streams are the same bytes, named by URI.
  const separate = JSON.parse(readFileSync(join(workDir, 'streams.kdm.gltf'), 'utf8'));
  const uri = separate.meshes[0].primitives[0].extensions[EXTENSION_NAME].uri;
  assert.equal(uri, 'streams.0-0.kdm');
  assert.ok(existsSync(join(workDir, uri)));
});

// A stand-in for KDMeshLoader that records what the plugin asks of it.
function recordingLoader() {
  const calls = [];
  const settle = (geometry) => {
    geometry.userData.loaded = Promise.resolve(geometry);
    return geometry;
  };
  return {
    calls,
    parseGeometry(buffer, options) {
      calls.push({ kind: 'bytes', bytes: new Uint8Array(buffer), options });
      return settle(options.geometry);
    },
    loadGeometry(url, options) {
      calls.push({ kind: 'url', url, options });
      return settle(options.geometry);
    },
  };
}

function parse(bytes, path, loader) {
  const gltfLoader = new GLTFLoader().register((parser) => new KDMeshGLTFExtension(parser, { loader }));
  const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  return new Promise((resolve, reject) => gltfLoader.parse(buffer, path, resolve, reject));
}

test('the plugin hands each stream to the loader with the geometry GLTFLoader made for it', async () => {
  const loader = recordingLoader();
  const bytes = readFileSync(join(workDir, 'scene.kdm.glb'));
  const gltf = await parse(bytes, '', loader);
  assert.equal(gltf.userData.kdmesh.streams, 3);
  assert.equal(await gltf.userData.kdmesh.loaded, gltf);
  // The scene graph is the input's.
  const names = [];
  gltf.scene.traverse((object) => object.name && names.push(object.name));
  for (const name of ['root', 'torus', 'quad']) assert.ok(names.includes(name), name);
  const torus = gltf.scene.getObjectByName('torus');
  const [call] = loader.calls.filter((c) => c.options.geometry === torus.geometry);
  assert.equal(call.kind, 'bytes');
  const { json, bin } = readGlb(bytes);
  const view = json.bufferViews[json.meshes[0].primitives[0].extensions[EXTENSION_NAME].bufferView];
  assert.deepEqual(call.bytes, new Uint8Array(bin.subarray(view.byteOffset, view.byteOffset + view.byteLength)));
  assert.deepEqual(call.options.attributes, {
    NORMAL: { name: 'normal', normalized: false }, TEXCOORD_0: { name: 'uv', normalized: false }, COLOR_0: { name: 'color', normalized: true },
  });
  // Geometry of the final size, drawing nothing until the first level.
  assert.equal(torus.geometry.getAttribute('position').count, json.accessors[json.meshes[0].primitives[0].attributes.POSITION].count);
  assert.equal(torus.geometry.drawRange.count, 0);
  // The line list and the points draw as LineSegments and Points; the
  // uncompressed quad keeps its own positions.
  const kinds = loader.calls.map((c) => c.options.geometry);
  assert.equal(kinds.length, 3);
  const quad = gltf.scene.getObjectByName('quad');
  assert.ok(!kinds.includes(quad.geometry));
  assert.deepEqual([...quad.geometry.getAttribute('position').array.slice(3, 6)], [1, 0, 0]);
  const types = new Set();
  gltf.scene.traverse((object) => kinds.includes(object.geometry) && types.add(object.type));
  assert.deepEqual([...types].sort(), ['LineSegments', 'Mesh', 'Points']);
});

test('streams named by URI are fetched relative to the scene', async () => {
  const loader = recordingLoader();
  const gltf = await parse(readFileSync(join(workDir, 'uris.kdm.glb')), 'https://example.org/scenes/', loader);
  assert.deepEqual(loader.calls.map((c) => c.url).sort(),
    ['https://example.org/scenes/uris.0-0.kdm', 'https://example.org/scenes/uris.1-0.kdm', 'https://example.org/scenes/uris.1-1.kdm']);
  assert.equal(gltf.userData.kdmesh.streams, 3);
});
