// The page of the consumer test: what an application importing the
// installed package does. It loads model.kdm three ways (KDMeshLoader's
// Group, its BufferGeometry, decode() on the main thread) and model.kdm.glb
// (the same model in a glTF scene) with GLTFLoader and kdmesh/gltf, and
// publishes what it got in window.result. ?selfhost=1 loads the worker and the wasm
// from the package's files instead of the bundled copies.
import { decode } from 'kdmesh';
import { KDMeshLoader } from 'kdmesh/three';
import { KDMeshGLTFExtension } from 'kdmesh/gltf';
import { LoadingManager, REVISION } from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { modelChecksum } from './model-checksum.js';

async function main() {
  const events = [];
  const manager = new LoadingManager();
  manager.onStart = () => events.push('start');
  manager.onLoad = () => events.push('load');
  const loader = new KDMeshLoader(manager);
  if (new URLSearchParams(location.search).has('selfhost')) {
    loader.setWorkerUrl('/node_modules/kdmesh/web/kdmesh-worker.js').setDecoderPath('/node_modules/kdmesh/web/dist/');
  }
  const group = await loader.loadAsync('model.kdm');
  const geometry = loader.loadGeometry('model.kdm');
  await geometry.userData.loaded;
  const bytes = new Uint8Array(await (await fetch('model.kdm')).arrayBuffer());
  const decoded = await decode(bytes);
  const gltf = await new GLTFLoader().register((parser) => new KDMeshGLTFExtension(parser, { loader })).loadAsync('model.kdm.glb');
  await gltf.userData.kdmesh.loaded;
  const meshes = [];
  gltf.scene.traverse((object) => object.isMesh && meshes.push(object.geometry));
  loader.dispose();
  return {
    revision: REVISION,
    group: modelChecksum(group.userData.stats.model),
    geometry: { vertices: geometry.getAttribute('position').count, indices: geometry.drawRange.count, primitive: geometry.userData.primitive },
    decode: modelChecksum(decoded),
    gltf: { streams: gltf.userData.kdmesh.streams, vertices: meshes[0].getAttribute('position').count, indices: meshes[0].drawRange.count },
    events,
  };
}

main().then((result) => (window.result = result), (error) => (window.result = { error: `${error.code ?? ''} ${error.message}` }));
