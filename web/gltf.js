// kdmesh/gltf — a GLTFLoader plugin for KDMESH_progressive_compression
// (docs/GLTF.md), registered the way three.js's own plugins are:
//
//   import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
//   import { KDMeshLoader } from 'kdmesh/three';
//   import { KDMeshGLTFExtension } from 'kdmesh/gltf';
//   const kdmesh = new KDMeshLoader();   // its pool of workers decodes the streams
//   const loader = new GLTFLoader().register((parser) => new KDMeshGLTFExtension(parser, { loader: kdmesh }));
//   const gltf = await loader.loadAsync('scene.kdm.glb');
//   scene.add(gltf.scene);                   // at once; each compressed primitive refines in place
//   await gltf.userData.kdmesh.loaded;       // every stream complete
//
// GLTFLoader builds each mesh as usual; a compressed primitive's accessors
// hold no data (or an uncompressed fallback), so it starts with empty
// geometry of the final size, and its stream (from its buffer view, or
// fetched from its URI while the scene is shown) refines that geometry in
// place through KDMeshLoader.loadGeometry/parseGeometry. Meshes without
// the extension, and plain primitives beside compressed ones, load as
// GLTFLoader loads them.
import { LoaderUtils } from 'three';
import { KDMeshLoader } from './three.js';

export const EXTENSION_NAME = 'KDMESH_progressive_compression';

// glTF attribute semantics as GLTFLoader names them in three.js.
const ATTRIBUTES = {
  POSITION: 'position', NORMAL: 'normal', TANGENT: 'tangent', TEXCOORD_0: 'uv', TEXCOORD_1: 'uv1', TEXCOORD_2: 'uv2',
  TEXCOORD_3: 'uv3', COLOR_0: 'color', WEIGHTS_0: 'skinWeight', JOINTS_0: 'skinIndex',
};
const threeName = (semantic) => ATTRIBUTES[semantic] ?? semantic.toLowerCase();

// Pages that pass no loader share this one (and its workers).
let sharedLoader = null;

export class KDMeshGLTFExtension {
  /**
   * options: loader (a KDMeshLoader, default one shared by the pages' plugins), onRefine(geometry, stats)
   * after each refinement of a primitive, signal (AbortSignal), limits (decoder caps).
   */
  constructor(parser, options = {}) {
    this.parser = parser;
    this.name = EXTENSION_NAME;
    this.options = options;
    this.loader = options.loader ?? (sharedLoader ??= new KDMeshLoader());
    this.streams = new Map();  // geometry -> its stream's completion
  }

  loadMesh(meshIndex) {
    const { parser, name } = this;
    const meshDef = parser.json.meshes[meshIndex];
    if (!meshDef.primitives.some((primitive) => primitive.extensions?.[name])) return null;
    return parser.loadMesh(meshIndex).then((object) => {
      // loadMesh gives one object for one primitive, else a Group of one per primitive, in order.
      const objects = meshDef.primitives.length === 1 ? [object] : object.children;
      meshDef.primitives.forEach((primitive, i) => {
        const extension = primitive.extensions?.[name];
        if (extension && !this.streams.has(objects[i].geometry)) this.#stream(objects[i].geometry, primitive, extension);
      });
      return object;
    });
  }

  /** gltf.userData.kdmesh.loaded resolves when every stream of the scene is complete. */
  afterRoot(result) {
    const streams = [...this.streams.values()];
    result.userData ??= {};
    const loaded = Promise.all(streams).then(() => result);
    loaded.catch(() => {});  // pages that only look at the scene need not handle it
    result.userData.kdmesh = { loaded, streams: streams.length };
    return null;
  }

  // Refines `geometry` (GLTFLoader's, with empty arrays of the final size)
  // from the primitive's stream.
  #stream(geometry, primitive, extension) {
    const { json } = this.parser;
    const attributes = {};
    for (const [semantic, streamName] of Object.entries(extension.attributes ?? {})) {
      const accessor = json.accessors[primitive.attributes[semantic]];
      if (accessor) attributes[streamName] = { name: threeName(semantic), normalized: accessor.normalized === true };
    }
    geometry.setDrawRange(0, 0);  // nothing until the first level
    const { onRefine, signal, limits } = this.options;
    const options = { geometry, attributes, onRefine, signal, limits };
    let done;
    if (extension.uri !== undefined) {
      const url = LoaderUtils.resolveURL(extension.uri, this.parser.options.path ?? '');
      done = this.loader.loadGeometry(url, options).userData.loaded;
    } else {
      done = this.parser.getDependency('bufferView', extension.bufferView)
        .then((buffer) => this.loader.parseGeometry(buffer, options).userData.loaded);
    }
    this.streams.set(geometry, done);
  }
}
