// Uses every export of kdmesh, kdmesh/three and kdmesh/gltf as a TypeScript program
// would; tests/types/types.test.mjs compiles it with tsc --strict.
import {
  AttributeCoding, compileWasm, createDecoder, decode, Decoder, Header, KdmeshError, memoryInUse, Model, Progress, setWasmSource,
  VertexAttribute,
} from 'kdmesh';
import { GpuFence, KDMeshLoader, LabelGroup, LoadStats, StreamedModel } from 'kdmesh/three';
import {
  BufferGeometry, Group, LoadingManager, Mesh, MeshBasicMaterial, MeshNormalMaterial, PerspectiveCamera, Scene, WebGLRenderer,
} from 'three';

export async function decoding(bytes: Uint8Array): Promise<number> {
  setWasmSource(new URL('https://example.com/kdmesh-wasm.wasm'));
  const module: WebAssembly.Module = await compileWasm(bytes);
  setWasmSource(module);
  const model: Model = await decode(bytes, { limits: { maxVertices: 1e6 } });
  const decoder: Decoder = await createDecoder();
  const progress: Progress = decoder.push(bytes.subarray(0, 100));
  const header: Header | null = decoder.header;
  const coarse = decoder.snapshot({ copy: false });
  const parents: Uint32Array = decoder.parents();
  const colour: VertexAttribute | undefined = coarse.attributes.color;
  const coding: AttributeCoding | undefined = coarse.attributes.normal?.coding;
  const quantized = coding === 'uniform' || coding === 'octahedral' ? coarse.attributes.normal.codingBits : 0;
  const attributeValues = (colour?.array.length ?? 0) + (colour?.itemSize ?? 0) + (header?.attributeCount ?? 0) + quantized;
  const regions: Int32Array | undefined = header?.labelled ? coarse.labels?.triangles : undefined;
  const table: Int32Array | null = header?.labels ?? null;
  decoder.finish();
  decoder.dispose();
  try {
    await decode(new Uint8Array(3));
  } catch (error) {
    if (error instanceof KdmeshError) return error.code.length;
  }
  return model.positions.length + progress.errorBound + (header?.simplexCounts[2] ?? 0) + coarse.triangles.length +
    parents.length + attributeValues + (regions?.length ?? 0) + (table?.length ?? 0) + (await memoryInUse()) +
    (model.stats.bitsPerVertex > 0 ? 1 : 0);
}

export async function loading(renderer: WebGLRenderer): Promise<BufferGeometry> {
  const manager = new LoadingManager();
  const loader = new KDMeshLoader(manager)
    .setWorkerLimit(2)
    .setDecoderLimits({ maxVertices: 1e7 })
    .setDecoderPath('/kdmesh/')
    .setWasmSource(new ArrayBuffer(8))
    .setWorkerUrl(new URL('https://example.com/kdmesh-worker.js'))
    .setRequestHeader({ Authorization: 'token' })
    .setWithCredentials(true)
    .setPath('/models/')
    .preload();
  loader.workerIdleTime = 5000;
  const scene = new Scene();
  const camera = new PerspectiveCamera();
  await loader.prepareRenderer(renderer, camera, scene);
  const controller = new AbortController();
  const group: Group = loader.loadProgressive('a.kdm', {
    signal: controller.signal,
    geomorph: true,
    tetrahedra: 'wireframe',
    limits: { maxSimplices: 1e7 },
    onRefine: (object: Group, stats: LoadStats) => {
      const level: StreamedModel | null = stats.model;
      return object.visible === stats.complete && (level?.normals.length ?? 0) >= (level?.attributes.normal?.array.length ?? 0);
    },
    onHeader: (header: Header) => header.totalBytes,
    onProgress: (stats: LoadStats, event: ProgressEvent) => stats.bytesReceived + event.loaded,
  });
  scene.add(group);
  await group.userData.loaded;
  const whole: Group = await loader.loadAsync('b.kdm');
  loader.load('c.kdm', (g: Group) => scene.add(g), (event: ProgressEvent) => event.total, (error: unknown) => String(error));
  loader.parse(new ArrayBuffer(10), (g: Group) => g.children.length);
  const geometry = loader.loadGeometry('d.kdm', { onRefine: (g: BufferGeometry) => g.drawRange.count });
  loader.loadGeometry('e.kdm', { onRefine: () => new Promise<void>((resolve) => setTimeout(resolve, 100)) });
  scene.add(new Mesh(geometry, new MeshNormalMaterial()));
  const primitive: 'triangles' | 'lines' | 'points' | undefined = geometry.userData.primitive;
  await geometry.userData.loaded;
  // Simplex labels as groups: one material per label of the stream's table.
  const byLabel = loader.loadProgressive('e.kdm', {
    materials: [new MeshBasicMaterial({ color: 0xff0000 }), new MeshBasicMaterial({ color: 0x00ff00 })],
    onRefine: (object: Group, stats: LoadStats) => {
      const groups: LabelGroup[] = stats.model?.groups ?? [];
      return groups.every((g) =>
        stats.header?.labels?.[g.materialIndex] === g.label && g.start + g.count <= (stats.model?.surface.length ?? 0));
    },
  });
  const labels: Int32Array | undefined = geometry.userData.labels;
  scene.add(byLabel);
  const fence = new GpuFence(renderer.getContext() as WebGL2RenderingContext);
  fence.set();
  const busy: number = loader.busyWorkers + (fence.passed() ? 1 : 0) + (primitive ? 1 : 0) + whole.children.length + (labels?.length ?? 0);
  loader.materials.surface.color.set(busy);
  return loader.abort().dispose() === loader ? geometry : new BufferGeometry();
}

// kdmesh/gltf: the GLTFLoader plugin, registered as three.js's own are.
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { EXTENSION_NAME, KDMeshGLTFExtension, KDMeshGLTFUserData } from 'kdmesh/gltf';

export async function gltfScene(url: string, bytes: Uint8Array): Promise<number> {
  const kdmesh = new KDMeshLoader();
  const loader = new GLTFLoader().register((parser) => new KDMeshGLTFExtension(parser, {
    loader: kdmesh, onRefine: (geometry: BufferGeometry) => geometry.computeBoundingSphere(), limits: { maxVertices: 1e7 },
  }));
  const gltf = await loader.loadAsync(url);
  const streams = gltf.userData.kdmesh as KDMeshGLTFUserData;
  await streams.loaded;
  const geometry = kdmesh.parseGeometry(bytes, { attributes: { NORMAL: { name: 'normal', normalized: false } } });
  await geometry.userData.loaded;
  return streams.streams + EXTENSION_NAME.length + gltf.scene.children.length;
}
