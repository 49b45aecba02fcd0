// kdmesh/three — a three.js loader for progressive .kdm streams.
//
//   import { KDMeshLoader } from 'kdmesh/three';
//   const loader = new KDMeshLoader();
//   const model = loader.loadProgressive(url, { onRefine(model, stats) {}, signal });
//   scene.add(model);                 // usable at once, refined in place
//   await model.userData.loaded;      // resolves when the last byte is applied
//
// Decoding runs in a module worker; bytes are fed as fetch delivers them and
// the geometry is refreshed at most once per animation frame. The returned
// THREE.Group holds a Mesh (triangles, and the boundary of tetrahedra), a
// LineSegments (edges) and a Points (isolated vertices), drawn with the
// loader's `materials` (shared by every model it loads; change or replace
// them before loading). `await loader.prepareRenderer(renderer, camera, scene)`
// before streaming keeps the first refinements from blocking the page.
import {
  Box3, BufferAttribute, BufferGeometry, DoubleSide, Float32BufferAttribute, Group, LineBasicMaterial, LineSegments, Loader, Mesh,
  MeshStandardMaterial, Points, PointsMaterial, Scene, ShaderMaterial, Sphere, Vector3, WebGLRenderTarget,
} from 'three';

// After the next frame, in a task of its own: a refinement applied inside
// the frame's callbacks would lengthen the task that also draws it.
const nextFrame = () =>
  new Promise((resolve) =>
    typeof requestAnimationFrame === 'function' ? requestAnimationFrame(() => setTimeout(resolve, 0)) : setTimeout(resolve, 16));

// The whole array behind a view from the worker.
const storageOf = (view) => new view.constructor(view.buffer);

// Makes `storage` the geometry's attribute `name`, without a copy: the
// worker sizes storage for the final model (from the header) and hands it
// over, and an attribute whose storage keeps its size keeps its GPU buffer.
function adoptAttribute(geometry, name, storage, itemSize) {
  let attribute = name === 'index' ? geometry.index : geometry.getAttribute(name);
  if (attribute && attribute.array.byteLength === storage.byteLength) {
    attribute.array = storage;
  } else {
    attribute = new BufferAttribute(storage, itemSize);
    if (name === 'index') geometry.setIndex(attribute);
    else geometry.setAttribute(name, attribute);
  }
  return attribute;
}

// One set of geometries for a model's three objects (surface, lines,
// points; they share the position attribute). A model has two: the level on
// screen is drawn from one while the next level goes to the GPU in the other.
class GeometrySet {
  constructor() {
    this.geometries = [new BufferGeometry(), new BufferGeometry(), new BufferGeometry()];
    this.queue = [];  // attributes with elements not yet marked for upload: { attribute, marked, used }
  }

  // Takes a level's arrays; their first `used` elements are to go to the GPU
  // (see mark()).
  stage(name, geometryIndex, storage, used, itemSize) {
    const attribute = adoptAttribute(this.geometries[geometryIndex], name, storage, itemSize);
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

export class KDMeshLoader extends Loader {
  constructor(manager) {
    super(manager);
    this.wasmSource = undefined;
    this.workerUrl = new URL('./kdmesh-worker.js', import.meta.url);
    this.workers = new Set();
    // Bytes of a level sent to the GPU at a time, on renderers passed to
    // prepareRenderer() (see SlicedUploads).
    this.uploadBytesPerSlice = 4 << 20;
    this.uploads = null;
    this.materials = {
      surface: new MeshStandardMaterial({ color: 0xb8c4d6, roughness: 0.6, metalness: 0.05, side: DoubleSide }),
      lines: new LineBasicMaterial({ color: 0x33475b }),
      points: new PointsMaterial({ color: 0x1f6feb, size: 2, sizeAttenuation: false }),
    };
  }

  /**
   * Prepares `renderer` to draw the loader's models in `scene` (whose lights
   * decide the shaders) without blocking the page, as measured in Chromium:
   *  - compiles the materials' shaders and draws a sample of each kind of
   *    object once, hidden behind `camera` (under software WebGL the first
   *    draw of a model otherwise took 130-230 ms, even with the shaders
   *    compiled);
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
    for (const object of sample.children) {
      object.geometry.setAttribute('position', corners);
      object.frustumCulled = false;
    }
    try {
      await renderer.compileAsync(sample, camera, scene);
      scene.add(sample);
      renderer.render(scene, camera);
      // The uploads' shader, compiled now too.
      const uploaders = this.uploads.createUploaders();
      uploaders.forEach((object, i) => (object.geometry = sample.children[i].geometry));
      this.uploads.run(uploaders);
    } finally {
      scene.remove(sample);
      for (const object of sample.children) object.geometry.dispose();
    }
  }

  // The objects of one model: their geometries are the model's own, the
  // materials the loader's.
  #createGroup() {
    const group = new Group();
    group.name = 'kdmesh';
    const { surface, lines, points } = this.materials;
    group.add(new Mesh(new BufferGeometry(), surface), new LineSegments(new BufferGeometry(), lines),
      new Points(new BufferGeometry(), points));
    return group;
  }

  /** Self-hosting: where the worker loads kdmesh-wasm.wasm from (default: embedded). */
  setDecoderPath(path) {
    this.wasmSource = new URL('kdmesh-wasm.wasm', new URL(path, globalThis.location?.href)).href;
    return this;
  }

  /** Where the decoding worker script lives (default: next to this module). */
  setWorkerUrl(url) {
    this.workerUrl = url;
    return this;
  }

  /** three.js loader interface: onLoad receives the group once complete. */
  load(url, onLoad, onProgress, onError) {
    const model = this.loadProgressive(url, {
      onProgress: (stats) => onProgress?.({ loaded: stats.bytesReceived, total: stats.bytesExpected, lengthComputable: stats.bytesExpected > 0 }),
    });
    model.userData.loaded.then(() => onLoad?.(model), (error) => (onError ? onError(error) : this.manager.itemError(url)));
    return model;
  }

  loadAsync(url, onProgress) {
    return new Promise((resolve, reject) => this.load(url, resolve, onProgress, reject));
  }

  /** Decodes a whole stream already in memory. */
  parse(buffer, onLoad, onError) {
    const model = this.#start({});
    model.userData.feed(new Uint8Array(buffer).slice());  // the worker takes the copy
    model.userData.end();
    model.userData.loaded.then(() => onLoad?.(model), onError);
    return model;
  }

  /**
   * Starts streaming `url` and returns the group at once. Options: onRefine(model,
   * stats) after each refinement, onHeader(header), onProgress(stats),
   * signal (AbortSignal: stops the download and keeps the current level),
   * tetrahedra: 'boundary' (default: the faces in exactly one tetrahedron) or
   * 'wireframe' (the boundary plus every edge of the tetrahedra), geomorph
   * (true: new vertices glide from their parent's position over
   * geomorphFrames frames, default 12), onAnimate(model) whenever the model
   * changes between refinements (geomorph frames).
   */
  loadProgressive(url, options = {}) {
    const model = this.#start(options);
    const { feed, end, fail } = model.userData;
    const stream = async () => {
      const response = await fetch(this.path ? this.path + url : url, { signal: options.signal, credentials: this.withCredentials ? 'include' : 'same-origin' });
      if (!response.ok) throw new Error(`${url}: HTTP ${response.status}`);
      const reader = response.body.getReader();
      for (;;) {
        const { done, value } = await reader.read();
        if (done) break;
        feed(value);
      }
      end();
    };
    stream().catch((error) => fail(error));
    return model;
  }

  #start(options) {
    const worker = new Worker(this.workerUrl, { type: 'module' });
    this.workers.add(worker);
    const group = this.#createGroup();
    const [surface, lines, points] = group.children;
    for (const object of group.children) object.visible = false;  // until it has simplices

    const stats = { refinements: 0, bytesReceived: 0, bytesExpected: 0, header: null, complete: false, model: null };
    let settle;
    const loaded = new Promise((resolve, reject) => (settle = { resolve, reject }));
    loaded.catch(() => {});  // callers that only watch events need not handle it
    let finished = false;
    const finish = (error) => {
      if (finished) return;
      finished = true;
      worker.terminate();
      this.workers.delete(worker);
      // The set not on screen holds an older level's GPU buffers.
      for (const geometry of back.geometries) geometry.dispose();
      if (error) settle.reject(error);
      else settle.resolve(group);
    };

    // Geomorphs: every vertex glides from where its ancestor was drawn at
    // the previous level to its new position over a few frames. The three
    // objects share one position attribute, so one update moves them all.
    let previous = null;  // { positions, count } of the last level drawn
    let morphId = 0;
    const morph = (attribute, from, to, count) => {
      const id = ++morphId;
      const frames = options.geomorphFrames ?? 12;
      let frame = 0;
      const step = () => {
        if (id !== morphId) return;
        frame += 1;
        const t = frame / frames;
        const array = attribute.array;
        for (let i = 0; i < 3 * count; ++i) array[i] = from[i] + t * (to[i] - from[i]);
        attribute.needsUpdate = true;
        options.onAnimate?.(group);
        if (frame < frames) requestAnimationFrame(step);
      };
      requestAnimationFrame(step);
    };

    // The level on screen is drawn from `front`; the next one is staged in
    // `back` and, on prepared renderers, uploaded by `uploaders` in slices.
    let front = new GeometrySet();
    let back = new GeometrySet();
    const uploads = this.uploads;
    const uploaders = uploads?.createUploaders() ?? [];
    const objects = group.children;
    objects.forEach((object, i) => (object.geometry = front.geometries[i]));

    let morphTarget = null;  // { start, positions, count } for a geomorph of the level staged
    const stageVertices = (model) => {
      let drawn = storageOf(model.positions);
      morphTarget = null;
      if (options.geomorph && previous) {
        drawn = new Float32Array(drawn.length);  // moves between the levels; model.positions stays
        for (let v = 0; v < model.vertexCount; ++v) {
          let ancestor = v;
          while (ancestor >= previous.count) ancestor = model.parents[ancestor];
          drawn[3 * v] = previous.positions[3 * ancestor];
          drawn[3 * v + 1] = previous.positions[3 * ancestor + 1];
          drawn[3 * v + 2] = previous.positions[3 * ancestor + 2];
        }
        morphTarget = { start: drawn.slice(0, model.positions.length), positions: model.positions, count: model.vertexCount };
      }
      if (options.geomorph) previous = { positions: model.positions, count: model.vertexCount };
      const position = back.stage('position', 0, drawn, model.positions.length, 3);
      back.geometries[1].setAttribute('position', position);
      back.geometries[2].setAttribute('position', position);
      // Normals come from the worker. On the final dragon (871k triangles,
      // Node 20) the worker's loop takes 90 ms and three.js's
      // computeVertexNormals 140 ms, which would block the main thread.
      if (model.normals.length) back.stage('normal', 0, storageOf(model.normals), model.normals.length, 3);
    };
    // Lists drawn together lie one after the other in one storage (see the worker).
    const listsOf = (model) => [
      [model.triangles, model.boundary.length],
      [model.edges, model.tetrahedronEdges.length],
      [model.points, 0],
    ];
    const stageLists = (model) => {
      // One bounding volume from the current vertices (the worker's) serves
      // all three objects.
      const box = new Box3().setFromArray(model.bounds);
      const sphere = box.getBoundingSphere(new Sphere());
      listsOf(model).forEach(([first, more], i) => {
        const count = first.length + more;
        if (count) back.stage('index', i, storageOf(first), count, 1);
        const geometry = back.geometries[i];
        geometry.boundingBox = box.clone();
        geometry.boundingSphere = sphere.clone();
      });
    };
    // The staged level goes on screen; the set it replaces takes the next.
    const swap = (model) => {
      [front, back] = [back, front];
      listsOf(model).forEach(([first, more], i) => {
        const count = first.length + more;
        front.geometries[i].setDrawRange(0, count);
        objects[i].geometry = front.geometries[i];
        objects[i].visible = count > 0;
      });
      const position = front.geometries[0].getAttribute('position');
      if (morphTarget) morph(position, morphTarget.start, morphTarget.positions, morphTarget.count);
      else morphId += 1;  // a level drawn at once ends any morph in flight
    };

    // A snapshot waits for the next frame; an error that arrives meanwhile
    // is reported after it is drawn, so the last good level stays on screen.
    let drawing = Promise.resolve();
    const draw = async (model) => {
      await nextFrame();  // at most one geometry update per frame
      if (finished) return;
      stageVertices(model);
      stageLists(model);
      if (uploads) {
        uploaders.forEach((object, i) => (object.geometry = back.geometries[i]));
        while (back.pending) {
          if (uploads.gpu.passed()) {
            back.mark(uploads.bytesPerSlice);
            uploads.run(uploaders);
          }
          await nextFrame();
          if (finished) return;
        }
      } else {
        back.mark(Infinity);  // uploaded when first drawn
      }
      swap(model);
      stats.refinements += 1;
      stats.complete = model.complete;
      stats.model = model;
      options.onRefine?.(group, stats);
      if (stats.complete) finish();
      else worker.postMessage({ type: 'next' });
    };
    worker.onmessage = ({ data }) => {
      if (finished) return;
      if (data.type === 'header') {
        stats.header = data.header;
        stats.bytesExpected = data.header.totalBytes;
        options.onHeader?.(data.header);
      } else if (data.type === 'snapshot') {
        drawing = draw(data.model);
      } else if (data.type === 'error') {
        const error = new Error(data.message);
        error.code = data.code;
        drawing.then(() => finish(error));
      }
    };
    worker.onerror = (event) => finish(new Error(event.message || 'the kdmesh worker failed'));
    worker.postMessage({ type: 'start', wasmSource: this.wasmSource, tetrahedra: options.tetrahedra, geomorph: options.geomorph });

    group.userData = {
      stats,
      loaded,
      feed: (bytes) => {
        if (finished) return;
        stats.bytesReceived += bytes.length;
        worker.postMessage({ type: 'bytes', bytes }, [bytes.buffer]);
        options.onProgress?.(stats);
      },
      end: () => !finished && worker.postMessage({ type: 'end' }),
      // A failed or aborted download keeps the current level on screen.
      fail: (error) => finish(error),
    };
    options.signal?.addEventListener('abort', () => finish(Object.assign(new Error('aborted'), { code: 'aborted' })));
    return group;
  }

  /** Stops every decoding worker and frees the materials. */
  dispose() {
    this.uploads?.dispose();
    for (const worker of this.workers) worker.terminate();
    this.workers.clear();
    for (const material of Object.values(this.materials)) material.dispose();
  }
}
