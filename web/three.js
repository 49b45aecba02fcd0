// kdmesh/three — a three.js loader for progressive .kdm streams, in the
// idiom of three.js's own loaders (DRACOLoader).
//
//   import { KDMeshLoader } from 'kdmesh/three';
//   const loader = new KDMeshLoader(manager);   // LoadingManager events, resolveURL, path
//   const model = loader.loadProgressive(url, { onRefine(model, stats) {}, signal });
//   scene.add(model);                 // usable at once, refined in place
//   await model.userData.loaded;      // resolves when the last byte is applied
//   const geometry = loader.loadGeometry(url);   // or a BufferGeometry, refined in place
//   loader.parseGeometry(bytes, { geometry, attributes });  // a stream in memory into a given geometry (kdmesh/gltf)
//
// Decoding runs in a pool of workers (setWorkerLimit, default 4), started
// from the worker's source bundled in the package, so no bundler needs
// configuring; bytes are fed as fetch delivers them and the geometry is
// refreshed at most once per animation frame. The THREE.Group of
// loadProgressive/load/parse holds a Mesh (triangles, and the boundary of
// tetrahedra), a LineSegments (edges) and a Points (isolated vertices),
// drawn with the loader's `materials` (shared by every model it loads;
// change or replace them before loading). The stream's vertex attributes
// become geometry attributes of the same names ('color', 'normal', 'uv',
// and any other under its own name, see vertexAttributesOf()), refined in
// place like the positions; a model with a 'color' draws with vertex
// colours (materials the page supplies need vertexColors set). A stream
// with simplex labels draws its triangles ordered by label, one geometry
// group per label (see setLabelGroups), so that a surface Mesh with an
// array of materials draws each label with its own. `await
// loader.prepareRenderer(renderer, camera, scene)` before streaming keeps
// the first refinements from blocking the page.
import {
  Box3, BufferAttribute, BufferGeometry, DoubleSide, Float32BufferAttribute, Group, LineBasicMaterial, LineSegments, Loader, Mesh,
  MeshStandardMaterial, Points, PointsMaterial, Scene, ShaderMaterial, Sphere, Vector3, WebGLRenderTarget,
} from 'three';
import { compileWasm, KdmeshError } from './kdmesh.js';

// After the next frame, in a task of its own: a refinement applied inside
// the frame's callbacks would lengthen the task that also draws it.
const nextFrame = () =>
  new Promise((resolve) =>
    typeof requestAnimationFrame === 'function' ? requestAnimationFrame(() => setTimeout(resolve, 0)) : setTimeout(resolve, 16));

// The whole array behind a view from the worker.
const storageOf = (view) => new view.constructor(view.buffer);

// adoptAttribute's name for the geometry's index (a vertex attribute of the
// stream may be called 'index').
const INDEX = null;

// Makes `storage` the geometry's attribute `name` (or its index), without a
// copy: the worker sizes storage for the final model (from the header) and
// hands it over, and an attribute whose storage keeps its size keeps its GPU
// buffer.
function adoptAttribute(geometry, name, storage, itemSize, normalized = false) {
  let attribute = name === INDEX ? geometry.index : geometry.getAttribute(name);
  if (attribute && attribute.array.byteLength === storage.byteLength) {
    attribute.array = storage;
  } else {
    attribute = new BufferAttribute(storage, itemSize, normalized);
    if (name === INDEX) geometry.setIndex(attribute);
    else geometry.setAttribute(name, attribute);
  }
  return attribute;
}

// The geometry attributes of a level besides 'position', as
// { name, array, itemSize, normalized }: 'normal' from model.normals (the
// stream's own normals or, without them, the worker's), then the stream's
// vertex attributes under their own names ('color', 'uv', ...), as three.js's
// shaders and loaders name them. A 'color' of an integer type is normalized
// (0-255 is 0-1 for uint8). Attributes named 'position', and a 'normal' the
// worker did not take as the normals (not three float32), would replace the
// loader's own: they stay in the model's `attributes` only.
function vertexAttributesOf(model) {
  const out = [];
  if (model.normals.length) out.push({ name: 'normal', array: model.normals, itemSize: 3, normalized: false });
  for (const [name, { array, itemSize }] of Object.entries(model.attributes)) {
    if (name === 'position' || name === 'normal') continue;
    out.push({ name, array, itemSize, normalized: name === 'color' && !(array instanceof Float32Array) });
  }
  return out;
}

// One set of geometries for a model's three objects (surface, lines,
// points; they share the vertex attributes). A model has two: the level on
// screen is drawn from one while the next level goes to the GPU in the other.
class GeometrySet {
  constructor() {
    this.geometries = [new BufferGeometry(), new BufferGeometry(), new BufferGeometry()];
    this.queue = [];  // attributes with elements not yet marked for upload: { attribute, marked, used }
  }

  // Takes a level's arrays; their first `used` elements are to go to the GPU
  // (see mark()).
  stage(name, geometryIndex, storage, used, itemSize, normalized) {
    const attribute = adoptAttribute(this.geometries[geometryIndex], name, storage, itemSize, normalized);
    if (used > 0) this.queue.push({ attribute, marked: 0, used });
    return attribute;
  }

  get pending() {
    return this.queue.length > 0;
  }

  // Marks up to `bytes` more of the staged elements for upload at the next
  // render of the geometries.
  mark(bytes) {
    while (bytes > 0 && this.queue.length > 0) {
      const item = this.queue[0];
      const { attribute } = item;
      const elementBytes = attribute.array.BYTES_PER_ELEMENT;
      const count = Math.min(item.used - item.marked, Math.max(1, Math.floor(bytes / elementBytes)));
      // A buffer three.js has yet to create gets its first elements from
      // createBuffersFromUsedBytes, an existing one the update range.
      usedBytes.set(attribute.array, (item.marked + count) * elementBytes);
      attribute.clearUpdateRanges();  // earlier slices are on the GPU
      attribute.addUpdateRange(item.marked, count);
      attribute.needsUpdate = true;
      item.marked += count;
      bytes -= count * elementBytes;
      if (item.marked === item.used) this.queue.shift();
    }
  }
}

/**
 * Tells whether the GPU has finished the WebGL work issued before the last
 * set(), without waiting: WebGL calls made while the GPU is still busy block
 * the page's main thread until it is done (under software WebGL, up to a
 * second per frame of a large model). Draw a frame only once passed().
 */
export class GpuFence {
  constructor(gl) {
    this.gl = gl;
    this.sync = null;
  }

  passed() {
    if (!this.sync) return true;
    if (this.gl.clientWaitSync(this.sync, 0, 0) === this.gl.TIMEOUT_EXPIRED) return false;
    this.gl.deleteSync(this.sync);
    this.sync = null;
    return true;
  }

  set() {
    this.sync = this.gl.fenceSync(this.gl.SYNC_GPU_COMMANDS_COMPLETE, 0);
    this.gl.flush();
  }
}

// Uploads the next level of models in slices, between the page's frames,
// on a renderer passed to prepareRenderer(). Under software WebGL in
// Chromium uploads block the page's main thread (a frame uploading half of
// the dragon's last level, ~10 MB, ran 39-47 ms of script), and a level
// drawn before all of it arrived would mix two levels' vertices and
// simplices. three.js uploads the attributes of the objects it renders, so
// the slices ride on renders of objects that draw nothing (an empty draw
// range, a trivial shader) into a 1x1 target, which leave the canvas alone.
// A slice waits until the GPU has finished all earlier work (GpuFence), or
// the upload would block the page until it had.
class SlicedUploads {
  constructor(renderer, camera, bytesPerSlice) {
    this.renderer = renderer;
    this.camera = camera;
    this.bytesPerSlice = bytesPerSlice;
    this.scene = new Scene();
    this.target = new WebGLRenderTarget(1, 1, { depthBuffer: false });
    this.material = new ShaderMaterial({
      vertexShader: 'void main() { gl_Position = vec4(0.0); }',
      fragmentShader: 'void main() { gl_FragColor = vec4(0.0); }',
    });
    this.gpu = new GpuFence(renderer.getContext());
  }

  // Objects that upload the geometries they are given (a model's three).
  createUploaders() {
    return [0, 1, 2].map(() => {
      const object = new Mesh(new BufferGeometry(), this.material);
      object.frustumCulled = false;
      return object;
    });
  }

  // Sends what is marked in the uploaders' geometries to the GPU.
  run(uploaders) {
    const { renderer } = this;
    for (const object of uploaders) object.geometry.setDrawRange(0, 0);
    this.scene.add(...uploaders);
    const target = renderer.getRenderTarget();
    renderer.setRenderTarget(this.target);
    renderer.render(this.scene, this.camera);
    renderer.setRenderTarget(target);
    this.scene.remove(...uploaders);
    this.gpu.set();
  }

  dispose() {
    this.target.dispose();
    this.material.dispose();
  }
}

// Buffers are sized for the final model from the first refinement on, but
// writing a fresh GPU buffer is slow (under software WebGL in Chromium, 3 ms
// per MB, against 0.2 ms per MB to rewrite one). So on renderers passed to
// prepareRenderer(), a buffer created from one of these arrays receives only
// the array's first `usedBytes` (the rest of a new WebGL buffer is zeros);
// the rest follows in slices (SlicedUploads).
const usedBytes = new WeakMap();
const preparedContexts = new WeakSet();
function createBuffersFromUsedBytes(gl) {
  if (preparedContexts.has(gl)) return;
  preparedContexts.add(gl);
  const bufferData = gl.bufferData;
  gl.bufferData = function (target, data, usage, ...rest) {
    const used = rest.length === 0 && ArrayBuffer.isView(data) ? usedBytes.get(data) : undefined;
    if (used === undefined) return bufferData.call(this, target, data, usage, ...rest);
    bufferData.call(this, target, data.byteLength, usage);
    if (used > 0) this.bufferSubData(target, 0, data, 0, used / data.BYTES_PER_ELEMENT);
  };
}

// What a model's geometry draws from a level: its lists of simplices, each
// [first list, elements of the second list stored right after it] (see the
// worker's pack()), for the surface (one list: the triangles with the
// boundary of the tetrahedra, ordered by label for labelled streams), the
// lines and the points.
const listsOf = (model) => [
  [model.surface, 0],
  [model.edges, model.tetrahedronEdges.length],
  [model.points, 0],
];

// A labelled stream's surface geometry gets the level's groups, one per
// label its triangles have, in ascending order, materialIndex the label's
// index in the stream's label table `labels` (the header's: every label of
// the stream, ascending, so a label keeps its materialIndex at every level,
// whichever labels a level lacks), and userData.labels, that table (the
// label of each materialIndex): a Mesh with an array of materials draws
// each label with its own, as three.js's loaders do for materials. Streams
// without labels leave the geometry's groups alone.
function setLabelGroups(geometry, model, labels) {
  if (!model.labels) return;
  geometry.clearGroups();
  for (const { start, count, materialIndex } of model.groups) geometry.addGroup(start, count, materialIndex);
  geometry.userData.labels = labels;
}

// Vertex colours come as files store them, in sRGB (PLY's red, green and
// blue), and three.js takes them as linear: `material`'s vertex shader
// converts them, per vertex, as three.js's PLYLoader does on loading. Any
// shader hook of `from` (the material copied) runs first.
function decodeSrgbVertexColours(material, from) {
  material.onBeforeCompile = (shader, renderer) => {
    from.onBeforeCompile(shader, renderer);
    shader.vertexShader = shader.vertexShader.replace('#include <color_vertex>', `#include <color_vertex>
#if defined( USE_COLOR ) || defined( USE_COLOR_ALPHA )
  vColor.rgb = mix( vColor.rgb * 0.0773993808, pow( vColor.rgb * 0.9478672986 + 0.0521327014, vec3( 2.4 ) ),
                    vec3( greaterThan( vColor.rgb, vec3( 0.04045 ) ) ) );
#endif`);
  };
  material.customProgramCacheKey = () => `${from.customProgramCacheKey()}|srgb-vertex-colours`;
}

// A model as a THREE.Group of three objects (surface, lines, points) with
// two sets of geometries: the level on screen is drawn from `front`; the
// next one is staged in `back` and, on renderers passed to
// prepareRenderer(), uploaded in slices by `uploaders`. With
// options.geomorph, every vertex glides from where its ancestor was drawn at
// the previous level to its new position over a few frames. A model with
// vertex colours draws with the materials `vertexColoured(material)` gives
// for the group's.
class GroupView {
  constructor(group, uploads, options, vertexColoured) {
    this.object = group;
    this.objects = group.children;
    this.uploads = uploads;
    this.uploaders = uploads?.createUploaders() ?? [];
    this.options = options;
    this.vertexColoured = vertexColoured;
    this.coloured = false;  // the objects have their vertex-coloured materials
    this.front = new GeometrySet();
    this.back = new GeometrySet();
    this.objects.forEach((object, i) => {
      object.geometry = this.front.geometries[i];
      object.visible = false;  // until it has simplices
    });
    this.previous = null;     // { positions, count } of the last level drawn
    this.morphTarget = null;  // { start, positions, count } for a geomorph of the level staged
    this.morphId = 0;
    this.labels = null;       // the stream's label table (see setLabelGroups)
  }

  header(header) {
    this.labels = header.labels;
  }

  // Draws `model` (after at least one frame); false when `stopped()` became
  // true meanwhile.
  async show(model, stopped) {
    await nextFrame();  // at most one geometry update per frame
    if (stopped()) return false;
    this.#stageVertices(model);
    this.#stageLists(model);
    const { uploads, uploaders, back } = this;
    if (uploads) {
      uploaders.forEach((object, i) => (object.geometry = back.geometries[i]));
      while (back.pending) {
        if (uploads.gpu.passed()) {
          back.mark(uploads.bytesPerSlice);
          uploads.run(uploaders);
        }
        await nextFrame();
        if (stopped()) return false;
      }
    } else {
      back.mark(Infinity);  // uploaded when first drawn
    }
    this.#swap(model);
    return true;
  }

  // The set not on screen holds an older level's GPU buffers.
  release() {
    for (const geometry of this.back.geometries) geometry.dispose();
  }

  #stageVertices(model) {
    const { options, back } = this;
    let drawn = storageOf(model.positions);
    this.morphTarget = null;
    if (options.geomorph && this.previous) {
      const previous = this.previous;
      drawn = new Float32Array(drawn.length);  // moves between the levels; model.positions stays
      for (let v = 0; v < model.vertexCount; ++v) {
        let ancestor = v;
        while (ancestor >= previous.count) ancestor = model.parents[ancestor];
        drawn[3 * v] = previous.positions[3 * ancestor];
        drawn[3 * v + 1] = previous.positions[3 * ancestor + 1];
        drawn[3 * v + 2] = previous.positions[3 * ancestor + 2];
      }
      this.morphTarget = { start: drawn.slice(0, model.positions.length), positions: model.positions, count: model.vertexCount };
    }
    if (options.geomorph) this.previous = { positions: model.positions, count: model.vertexCount };
    // The three objects share each vertex attribute: one GPU buffer apiece.
    const share = (name, attribute) => {
      back.geometries[1].setAttribute(name, attribute);
      back.geometries[2].setAttribute(name, attribute);
    };
    share('position', back.stage('position', 0, drawn, model.positions.length, 3));
    // Normals come from the worker (the stream's, or computed there: on the
    // final dragon, 871k triangles, Node 20, the worker's loop takes 90 ms
    // and three.js's computeVertexNormals 140 ms, which would block the
    // main thread).
    for (const { name, array, itemSize, normalized } of vertexAttributesOf(model))
      share(name, back.stage(name, 0, storageOf(array), array.length, itemSize, normalized));
  }

  #stageLists(model) {
    // One bounding volume from the current vertices (the worker's) serves
    // all three objects.
    const box = new Box3().setFromArray(model.bounds);
    const sphere = box.getBoundingSphere(new Sphere());
    listsOf(model).forEach(([first, more], i) => {
      const count = first.length + more;
      if (count) this.back.stage(INDEX, i, storageOf(first), count, 1);
      const geometry = this.back.geometries[i];
      if (i === 0) setLabelGroups(geometry, model, this.labels);
      geometry.boundingBox = box.clone();
      geometry.boundingSphere = sphere.clone();
    });
  }

  // The staged level goes on screen; the set it replaces takes the next.
  #swap(model) {
    [this.front, this.back] = [this.back, this.front];
    listsOf(model).forEach(([first, more], i) => {
      const count = first.length + more;
      this.front.geometries[i].setDrawRange(0, count);
      this.objects[i].geometry = this.front.geometries[i];
      this.objects[i].visible = count > 0;
    });
    if (model.attributes.color && !this.coloured) {
      this.coloured = true;
      for (const object of this.objects) object.material = this.vertexColoured(object.material);
    }
    const position = this.front.geometries[0].getAttribute('position');
    if (this.morphTarget) this.#morph(position, this.morphTarget);
    else this.morphId += 1;  // a level drawn at once ends any morph in flight
  }

  // The three objects share one position attribute, so one update moves them all.
  #morph(attribute, { start, positions, count }) {
    const id = ++this.morphId;
    const frames = this.options.geomorphFrames ?? 12;
    let frame = 0;
    const step = () => {
      if (id !== this.morphId) return;
      frame += 1;
      const t = frame / frames;
      const array = attribute.array;
      for (let i = 0; i < 3 * count; ++i) array[i] = start[i] + t * (positions[i] - start[i]);
      attribute.needsUpdate = true;
      this.options.onAnimate?.(this.object);
      if (frame < frames) requestAnimationFrame(step);
    };
    requestAnimationFrame(step);
  }
}

// A model as one BufferGeometry, refined in place, for the page's own
// material and object: its index holds the triangles (with the boundary of
// tetrahedra) when the complete model has any, else its edges; a point
// cloud has no index. userData.primitive ('triangles', 'lines' or
// 'points') says which, once the header has arrived. Labelled triangles
// come with groups and userData.labels (see setLabelGroups).
//
// `attributes`, when given, names the geometry attribute of each stream
// attribute, { [streamName]: { name, normalized } }: those alone are set,
// and no normals are computed (as glTF primitives are drawn, see kdmesh/gltf).
class GeometryView {
  constructor(geometry, attributes = null) {
    this.object = geometry;
    this.attributes = attributes;
    this.list = -1;  // which of listsOf() the index holds (-1: none)
    this.labels = null;  // the stream's label table (see setLabelGroups)
  }

  header(header) {
    this.labels = header.labels;
    const [, edges, triangles, tetrahedra] = header.simplexCounts;
    this.list = triangles + tetrahedra > 0 ? 0 : edges > 0 ? 1 : -1;
    this.object.userData.primitive = ['triangles', 'lines'][this.list] ?? 'points';
  }

  async show(model, stopped) {
    await nextFrame();
    if (stopped()) return false;
    const geometry = this.object;
    const update = (name, storage, used, itemSize, normalized) => {
      const attribute = adoptAttribute(geometry, name, storage, itemSize, normalized);
      attribute.clearUpdateRanges();
      attribute.addUpdateRange(0, used);
      attribute.needsUpdate = true;
    };
    update('position', storageOf(model.positions), model.positions.length, 3);
    for (const { name, array, itemSize, normalized } of this.#vertexAttributes(model))
      update(name, storageOf(array), array.length, itemSize, normalized);
    let count = model.vertexCount;
    if (this.list >= 0) {
      const [first, more] = listsOf(model)[this.list];
      count = first.length + more;
      if (count) update(INDEX, storageOf(first), count, 1);
      if (this.list === 0) setLabelGroups(geometry, model, this.labels);
    }
    geometry.setDrawRange(0, count);
    geometry.boundingBox = new Box3().setFromArray(model.bounds);
    geometry.boundingSphere = geometry.boundingBox.getBoundingSphere(new Sphere());
    return true;
  }

  release() {}

  #vertexAttributes(model) {
    if (!this.attributes) return vertexAttributesOf(model);
    return Object.entries(model.attributes).filter(([name]) => Object.hasOwn(this.attributes, name))
      .map(([name, { array, itemSize }]) => ({ ...this.attributes[name], array, itemSize }));
  }
}

export class KDMeshLoader extends Loader {
  #idle = [];           // workers ready for a stream
  #idleTimers = new Map();  // idle worker -> timer that ends it
  #waiting = [];        // loads waiting for a worker: functions that wake them
  #loads = new Set();   // loads in flight: functions that stop them with an error
  #wasm = null;         // Promise of the compiled WebAssembly module
  #workerScript = null; // Promise of { url, options } to start workers with
  #disposed = false;
  #ownMaterials;        // the materials the constructor made
  #colouredMaterials = new Map();  // one of those -> its copy for vertex colours (see #vertexColoured)

  constructor(manager) {
    super(manager);
    this.wasmSource = undefined;
    this.workerUrl = null;
    this.workerLimit = 4;
    // An idle worker ends after this many milliseconds: WebAssembly memory
    // never shrinks, and a worker that decoded a large model holds all the
    // memory it took until it ends.
    this.workerIdleTime = 10000;
    this.decoderLimits = {};
    this.workers = new Set();  // every worker started, busy or idle
    // Bytes of a level sent to the GPU at a time, on renderers passed to
    // prepareRenderer() (see SlicedUploads).
    this.uploadBytesPerSlice = 4 << 20;
    this.uploads = null;
    this.materials = {
      surface: new MeshStandardMaterial({ color: 0xb8c4d6, roughness: 0.6, metalness: 0.05, side: DoubleSide }),
      lines: new LineBasicMaterial({ color: 0x33475b }),
      points: new PointsMaterial({ color: 0x1f6feb, size: 2, sizeAttenuation: false }),
    };
    this.#ownMaterials = new Set(Object.values(this.materials));
  }

  /** Workers decoding a stream now. */
  get busyWorkers() {
    return this.workers.size - this.#idle.length;
  }

  /**
   * Prepares `renderer` to draw the loader's models in `scene` (whose lights
   * decide the shaders) without blocking the page, as measured in Chromium:
   *  - compiles the materials' shaders, and those of their vertex-coloured
   *    copies, and draws a sample of each kind of object with each once,
   *    hidden behind `camera` (under software WebGL the first draw of a
   *    model otherwise took 130-230 ms, even with the shaders compiled);
   *  - fills the GPU buffers of models as their content grows, not at once
   *    (see createBuffersFromUsedBytes), and uploads a level in slices of
   *    `uploadBytesPerSlice` between frames, while the previous level stays
   *    on screen (see SlicedUploads).
   * Call it before streaming starts.
   */
  async prepareRenderer(renderer, camera, scene) {
    createBuffersFromUsedBytes(renderer.getContext());
    this.uploads?.dispose();
    this.uploads = new SlicedUploads(renderer, camera, this.uploadBytesPerSlice);
    const sample = this.#createGroup();
    const behind = camera.localToWorld(new Vector3(0, 0, 1));
    const corners = new Float32BufferAttribute([...behind.toArray(), ...behind.toArray(), ...behind.toArray()], 3);
    const [surface, lines, points] = sample.children;
    surface.geometry.setAttribute('normal', new Float32BufferAttribute([0, 0, 1, 0, 0, 1, 0, 0, 1], 3));
    // 32-bit indices like the models' (a different index type is a different
    // pipeline for the GPU).
    surface.geometry.setIndex(new BufferAttribute(new Uint32Array([0, 1, 2]), 1));
    lines.geometry.setIndex(new BufferAttribute(new Uint32Array([0, 1]), 1));
    points.geometry.setIndex(new BufferAttribute(new Uint32Array([0]), 1));
    const white = new BufferAttribute(new Uint8Array(9).fill(255), 3, true);
    for (const object of sample.children) {
      object.geometry.setAttribute('position', corners);
      object.geometry.setAttribute('color', white);
      object.frustumCulled = false;
    }
    // The same objects with the materials of models with vertex colours.
    const coloured = sample.clone();
    for (const object of coloured.children) object.material = this.#vertexColoured(object.material);
    const samples = new Group().add(sample, coloured);
    try {
      await renderer.compileAsync(samples, camera, scene);
      scene.add(samples);
      renderer.render(scene, camera);
      // The uploads' shader, compiled now too.
      const uploaders = this.uploads.createUploaders();
      uploaders.forEach((object, i) => (object.geometry = sample.children[i].geometry));
      this.uploads.run(uploaders);
    } finally {
      scene.remove(samples);
      for (const object of sample.children) object.geometry.dispose();
    }
  }

  #groupView(group, options) {
    return new GroupView(group, this.uploads, options, (material) => this.#vertexColoured(material));
  }

  // For a model with vertex colours: a material of the loader's own (one it
  // made, in `materials`) gives way to its copy with vertexColors set, a
  // white colour and sRGB vertex colours (see decodeSrgbVertexColours), so
  // that the colours show as the file has them; the copy is made again from
  // the material for each coloured model. A material the page put in
  // `materials` draws as it is: the page sets its vertexColors.
  #vertexColoured(material) {
    if (!this.#ownMaterials.has(material)) return material;
    let copy = this.#colouredMaterials.get(material);
    if (copy) copy.copy(material);
    else this.#colouredMaterials.set(material, (copy = material.clone()));
    copy.vertexColors = true;
    copy.color.set(0xffffff);
    decodeSrgbVertexColours(copy, material);
    copy.needsUpdate = true;
    return copy;
  }

  // The objects of one model: their geometries are the model's own, the
  // materials the loader's, or the surface's `materials` (an array: one per
  // label group, see setLabelGroups).
  #createGroup(materials = this.materials.surface) {
    const group = new Group();
    group.name = 'kdmesh';
    const { lines, points } = this.materials;
    group.add(new Mesh(new BufferGeometry(), materials), new LineSegments(new BufferGeometry(), lines),
      new Points(new BufferGeometry(), points));
    return group;
  }

  /** Self-hosting: the workers load kdmesh-wasm.wasm from this folder (default: the copy embedded in the package). */
  setDecoderPath(path) {
    return this.setWasmSource(new URL('kdmesh-wasm.wasm', new URL(path, globalThis.location?.href)).href);
  }

  /** Where the decoder's WebAssembly comes from: a URL, the .wasm bytes or a WebAssembly.Module. */
  setWasmSource(source) {
    this.wasmSource = source;
    this.#wasm = null;
    return this;
  }

  /**
   * Starts workers as module workers from this URL (web/kdmesh-worker.js,
   * exported as kdmesh/worker, next to kdmesh.js and dist/) instead of from
   * the source bundled in the package through a Blob URL: for pages whose
   * Content-Security-Policy refuses blob: workers.
   */
  setWorkerUrl(url) {
    this.workerUrl = url;
    this.#workerScript = null;
    return this;
  }

  /** How many workers decode at once; further loads wait for one (default 4). */
  setWorkerLimit(limit) {
    this.workerLimit = Math.max(1, limit);
    return this;
  }

  /**
   * Caps for every decoder: { maxVertices, maxSimplices, maxChunkBytes, maxVerticesPerByte,
   * maxSimplicesPerByte }; a stream beyond one fails with 'limit-exceeded'.
   */
  setDecoderLimits(limits) {
    this.decoderLimits = { ...limits };
    return this;
  }

  /** Compiles the decoder and starts a worker now, so that the first load need not wait for them. */
  preload() {
    this.#acquire().then((worker) => this.#release(worker, true), () => {});
    return this;
  }

  /** three.js loader interface: onLoad receives the group once complete. */
  load(url, onLoad, onProgress, onError) {
    const model = this.loadProgressive(url, { onProgress: onProgress && ((stats, event) => onProgress(event)) });
    model.userData.loaded.then(() => onLoad?.(model), (error) => onError?.(error));
    return model;
  }

  /** Decodes a whole stream already in memory. */
  parse(buffer, onLoad, onError) {
    const model = this.#createGroup();
    const bytes = ArrayBuffer.isView(buffer) ? new Uint8Array(buffer.buffer, buffer.byteOffset, buffer.byteLength) : new Uint8Array(buffer);
    this.#run(null, bytes.slice(), {}, this.#groupView(model, {}));  // the worker takes the copy
    model.userData.loaded.then(() => onLoad?.(model), (error) => onError?.(error));
    return model;
  }

  /**
   * Starts streaming `url` and returns the group at once. Options: onRefine(model,
   * stats) after each refinement (a promise it returns holds the next refinement
   * back until it settles: a page whose frames are slow to draw, say under
   * software WebGL, can leave the cores to the decoder), onHeader(header),
   * onProgress(stats, event),
   * signal (AbortSignal: stops the download and keeps the current level),
   * limits (decoder caps, default setDecoderLimits'), coarsePlacement ('predicted', the
   * default, or 'centre': where vertices of unfinished cells are drawn, see kdmesh's
   * createDecoder),
   * tetrahedra: 'boundary' (default: the faces in exactly one tetrahedron) or
   * 'wireframe' (the boundary plus every edge of the tetrahedra), geomorph
   * (true: new vertices glide from their parent's position over
   * geomorphFrames frames, default 12), onAnimate(model) whenever the model
   * changes between refinements (geomorph frames), materials (the surface
   * Mesh's material instead of loader.materials.surface: an array draws the
   * triangles of each simplex label with the material at the label's index
   * in header.labels, see setLabelGroups).
   */
  loadProgressive(url, options = {}) {
    const model = this.#createGroup(options.materials);
    this.#run(url, null, options, this.#groupView(model, options));
    return model;
  }

  /**
   * Like loadProgressive, but returns one BufferGeometry, refined in place,
   * for a material and object of the page's choice (see GeometryView):
   * geometry.userData has loaded, stats and primitive. No geomorphs. The
   * vertex attributes are the group's (a 'color' shows with a material
   * whose vertexColors is set).
   */
  loadGeometry(url, options = {}) {
    const geometry = options.geometry ?? new BufferGeometry();
    this.#run(url, null, options, this.#geometryView(geometry, options));
    return geometry;
  }

  /** Like loadGeometry, for a whole stream already in memory (refined as the worker decodes it). */
  parseGeometry(buffer, options = {}) {
    const geometry = options.geometry ?? new BufferGeometry();
    const bytes = ArrayBuffer.isView(buffer) ? new Uint8Array(buffer.buffer, buffer.byteOffset, buffer.byteLength) : new Uint8Array(buffer);
    this.#run(null, bytes.slice(), options, this.#geometryView(geometry, options));  // the worker takes the copy
    return geometry;
  }

  // options.geometry: refine this geometry (its attributes are replaced);
  // options.attributes: see GeometryView.
  #geometryView(geometry, options) {
    return new GeometryView(geometry, options.attributes ?? null);
  }

  /** Stops every load in flight; each keeps its current level and rejects with code 'aborted'. */
  abort() {
    for (const stop of [...this.#loads]) stop(new KdmeshError('aborted', 'the load was aborted'));
    return this;
  }

  /**
   * Stops every load in flight (rejecting with code 'disposed'), ends the
   * workers and frees the materials; the loader is unusable after.
   */
  dispose() {
    this.#disposed = true;
    for (const stop of [...this.#loads]) stop(new KdmeshError('disposed', 'the loader was disposed'));
    for (const wake of this.#waiting.splice(0)) wake();
    for (const worker of this.workers) worker.terminate();
    this.workers.clear();
    for (const timer of this.#idleTimers.values()) clearTimeout(timer);
    this.#idleTimers.clear();
    this.#idle = [];
    this.#workerScript?.then(({ url, revoke }) => revoke && URL.revokeObjectURL(url), () => {});
    this.uploads?.dispose();
    for (const material of [...Object.values(this.materials), ...this.#colouredMaterials.values()]) material.dispose();
    return this;
  }

  #compiledWasm() {
    if (!this.#wasm) {
      this.#wasm = compileWasm(this.wasmSource);
      this.#wasm.catch(() => (this.#wasm = null));  // a later load tries again
    }
    return this.#wasm;
  }

  #startWorker() {
    if (!this.#workerScript) {
      this.#workerScript = this.workerUrl
        ? Promise.resolve({ url: this.workerUrl, options: { type: 'module' }, revoke: false })
        : import('./dist/kdmesh-worker-source.js').then(({ workerSource }) => ({
          url: URL.createObjectURL(new Blob([workerSource], { type: 'text/javascript' })), options: {}, revoke: true,
        }));
    }
    return this.#workerScript;
  }

  // An idle worker, a new one while fewer than workerLimit run, or the next
  // one released.
  async #acquire() {
    const [script] = await Promise.all([this.#startWorker(), this.#compiledWasm()]);
    for (;;) {
      if (this.#disposed) throw new KdmeshError('disposed', 'the loader was disposed');
      if (this.#idle.length) {
        const worker = this.#idle.pop();
        clearTimeout(this.#idleTimers.get(worker));
        this.#idleTimers.delete(worker);
        return worker;
      }
      if (this.workers.size < this.workerLimit) {
        const worker = new Worker(script.url, script.options);
        this.workers.add(worker);
        return worker;
      }
      await new Promise((wake) => this.#waiting.push(wake));
    }
  }

  // A worker whose stream ended cleanly decodes the next; one stopped
  // mid-stream is ended.
  #release(worker, reusable) {
    worker.onmessage = worker.onerror = null;
    if (reusable && !this.#disposed) {
      this.#idle.push(worker);
      this.#idleTimers.set(worker, setTimeout(() => {
        this.#idle.splice(this.#idle.indexOf(worker), 1);
        this.#idleTimers.delete(worker);
        worker.terminate();
        this.workers.delete(worker);
      }, this.workerIdleTime));
    } else {
      worker.terminate();
      this.workers.delete(worker);
    }
    this.#waiting.shift()?.();
  }

  // Streams `url` (or decodes `bytes`) into `view`, whose object gets
  // userData { stats, loaded }.
  #run(url, bytes, options, view) {
    const stats = { refinements: 0, bytesReceived: 0, bytesExpected: 0, header: null, complete: false, model: null };
    let settle;
    const loaded = new Promise((resolve, reject) => (settle = { resolve, reject }));
    loaded.catch(() => {});  // callers that only watch events need not handle it
    Object.assign(view.object.userData, { stats, loaded });

    const resolved = url === null ? null : this.manager.resolveURL((this.path ?? '') + url);
    if (resolved !== null) this.manager.itemStart(resolved);
    const download = new AbortController();
    let worker = null;
    let finished = false;
    const stopped = () => finished;
    const finish = (error) => {
      if (finished) return;
      finished = true;
      this.#loads.delete(finish);
      if (error) download.abort();  // a complete stream's response ends by itself
      // The worker's stream ended cleanly when it completed or reported bad data.
      if (worker) this.#release(worker, !error || error.fromWorker === true);
      view.release();
      if (resolved !== null) {
        if (error) this.manager.itemError(resolved);
        this.manager.itemEnd(resolved);
      }
      if (error) settle.reject(error);
      else settle.resolve(view.object);
    };
    this.#loads.add(finish);
    const signals = [options.signal, this.manager.abortController?.signal].filter(Boolean);
    for (const signal of signals) {
      if (signal.aborted) finish(new KdmeshError('aborted', 'the load was aborted'));
      else signal.addEventListener('abort', () => finish(new KdmeshError('aborted', 'the load was aborted')), { once: true });
    }

    const progress = (event) => {
      options.onProgress?.(stats, event);
    };
    const progressEvent = () => {
      const init = { lengthComputable: stats.bytesExpected > 0, loaded: stats.bytesReceived, total: stats.bytesExpected };
      return typeof ProgressEvent === 'function' ? new ProgressEvent('progress', init) : init;
    };

    // A snapshot waits for the next frame; an error that arrives meanwhile
    // is reported after it is drawn, so the last good level stays on screen.
    // A promise from onRefine holds the next level back until it settles:
    // the worker decodes on meanwhile, and the page draws fewer levels; the
    // complete model comes as soon as it is decoded all the same.
    let drawing = Promise.resolve();
    const draw = async (model) => {
      if (!(await view.show(model, stopped))) return;
      stats.refinements += 1;
      stats.complete = model.complete;
      stats.model = model;
      const paced = options.onRefine?.(view.object, stats);
      if (stats.complete) return finish();
      if (paced && typeof paced.then === 'function') {
        worker.postMessage({ type: 'last' });
        await Promise.resolve(paced).then(() => {}, () => {});
      }
      if (!finished) worker.postMessage({ type: 'next' });
    };
    const onMessage = ({ data }) => {
      if (finished) return;
      if (data.type === 'header') {
        stats.header = data.header;
        stats.bytesExpected = data.header.totalBytes;
        view.header?.(data.header);
        options.onHeader?.(data.header);
      } else if (data.type === 'snapshot') {
        drawing = draw(data.model);
      } else if (data.type === 'error') {
        const error = Object.assign(new KdmeshError(data.code, data.message), { fromWorker: true });
        drawing.then(() => finish(error));
      }
    };

    // The download starts at once; its first bytes wait in `early` while
    // the WebAssembly compiles and a worker starts or frees up.
    const early = [];
    const feed = (piece) => {
      if (finished) return;
      stats.bytesReceived += piece.length;
      if (worker) worker.postMessage({ type: 'bytes', bytes: piece }, [piece.buffer]);
      else early.push(piece);
      progress(progressEvent());
    };
    const startWorker = async () => {
      const [acquired, wasm] = await Promise.all([this.#acquire(), this.#compiledWasm()]);
      if (finished) return this.#release(acquired, true);
      acquired.onmessage = onMessage;
      acquired.onerror = (event) => finish(new KdmeshError('worker-failed', `the kdmesh worker failed: ${event.message || 'no message'}`));
      const limits = options.limits ?? this.decoderLimits;
      acquired.postMessage({ type: 'start', wasm, limits, coarsePlacement: options.coarsePlacement,
                             tetrahedra: options.tetrahedra, geomorph: options.geomorph,
                             normals: !options.attributes });
      for (const piece of early) acquired.postMessage({ type: 'bytes', bytes: piece }, [piece.buffer]);
      early.length = 0;
      worker = acquired;
    };
    const stream = async () => {
      const started = startWorker();
      started.catch(finish);  // e.g. wasm-unavailable: fails the load without waiting for the download
      if (bytes) {
        feed(bytes);
      } else {
        const response = await fetch(new Request(resolved, {
          headers: new Headers(this.requestHeader), credentials: this.withCredentials ? 'include' : 'same-origin', signal: download.signal,
        }));
        if (!response.ok) throw new KdmeshError('network', `${resolved}: HTTP ${response.status}`);
        // The stream's own size comes with its header; until then, the
        // response's length where the server gives it.
        stats.bytesExpected = Number(response.headers.get('content-length')) || 0;
        const reader = response.body.getReader();
        for (;;) {
          const { done, value } = await reader.read();
          if (done) break;
          feed(value);
        }
      }
      await started;
      if (!finished) worker.postMessage({ type: 'end' });
    };
    stream().catch((error) => finish(error instanceof KdmeshError || finished ? error
      : new KdmeshError('network', `${resolved}: ${error.message ?? error}`)));
  }
}
