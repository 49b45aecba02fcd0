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
  MeshStandardMaterial, Points, PointsMaterial, Sphere, Vector3,
} from 'three';

// After the next frame, in a task of its own: a refinement applied inside
// the frame's callbacks would lengthen the task that also draws it.
const nextFrame = () =>
  new Promise((resolve) =>
    typeof requestAnimationFrame === 'function' ? requestAnimationFrame(() => setTimeout(resolve, 0)) : setTimeout(resolve, 16));

// The whole array behind a view from the worker.
const storageOf = (view) => new view.constructor(view.buffer);

// Makes `storage` the geometry's attribute `name`, of which the first `used`
// elements are the current level. The worker sizes storage for the final
// model (from the header) and hands it over without a copy; an attribute
// whose storage keeps its size keeps its GPU buffer, so refinement neither
// copies nor reallocates on the page. Returns the attribute; the caller sets
// the draw range.
function adoptAttribute(geometry, name, storage, used, itemSize) {
  let attribute = name === 'index' ? geometry.index : geometry.getAttribute(name);
  if (attribute && attribute.array.byteLength === storage.byteLength) {
    attribute.array = storage;
  } else {
    attribute = new BufferAttribute(storage, itemSize);
    if (name === 'index') geometry.setIndex(attribute);
    else geometry.setAttribute(name, attribute);
  }
  usedBytes.set(storage, used * storage.BYTES_PER_ELEMENT);
  attribute.clearUpdateRanges();
  attribute.addUpdateRange(0, used);
  attribute.needsUpdate = true;
  return attribute;
}

// Buffers are sized for the final model from the first refinement on, but
// writing a fresh GPU buffer is slow (under software WebGL in Chromium, 3 ms
// per MB, against 0.2 ms per MB to rewrite one): the 21 MB of the dragon's
// buffers would block the page for 60-360 ms. So on renderers passed to
// prepareRenderer(), a buffer created from one of these arrays receives only
// the array's first `usedBytes` (the rest of a new WebGL buffer is zeros),
// and later refinements touch the remainder a little at a time.
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
   *    (see createBuffersFromUsedBytes).
   * Call it before streaming starts.
   */
  async prepareRenderer(renderer, camera, scene) {
    createBuffersFromUsedBytes(renderer.getContext());
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
   * changes between refinements (geomorph frames; a level's vertices, which
   * reach the GPU a frame before its simplices).
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

    const applyVertices = (model) => {
      let drawn = storageOf(model.positions);
      let start = null;
      if (options.geomorph && previous) {
        drawn = new Float32Array(drawn.length);  // moves between the levels; model.positions stays
        for (let v = 0; v < model.vertexCount; ++v) {
          let ancestor = v;
          while (ancestor >= previous.count) ancestor = model.parents[ancestor];
          drawn[3 * v] = previous.positions[3 * ancestor];
          drawn[3 * v + 1] = previous.positions[3 * ancestor + 1];
          drawn[3 * v + 2] = previous.positions[3 * ancestor + 2];
        }
        start = drawn.slice(0, model.positions.length);
      }
      if (options.geomorph) previous = { positions: model.positions, count: model.vertexCount };
      const position = adoptAttribute(surface.geometry, 'position', drawn, model.positions.length, 3);
      lines.geometry.setAttribute('position', position);
      points.geometry.setAttribute('position', position);
      if (start) morph(position, start, model.positions, model.vertexCount);
      else morphId += 1;  // a level drawn at once ends any morph in flight
      // Normals come from the worker. On the final dragon (871k triangles,
      // Node 20) the worker's loop takes 90 ms and three.js's
      // computeVertexNormals 140 ms, which would block the main thread.
      if (model.normals.length) adoptAttribute(surface.geometry, 'normal', storageOf(model.normals), model.normals.length, 3);
    };
    const applyLists = (model) => {
      // Lists drawn together lie one after the other in one storage (see the worker).
      const lists = [
        [surface, model.triangles, model.boundary.length],
        [lines, model.edges, model.tetrahedronEdges.length],
        [points, model.points, 0],
      ];
      // One bounding volume from the current vertices (the worker's) serves
      // all three objects.
      const box = new Box3().setFromArray(model.bounds);
      const sphere = box.getBoundingSphere(new Sphere());
      for (const [object, first, more] of lists) {
        const count = first.length + more;
        if (count) adoptAttribute(object.geometry, 'index', storageOf(first), count, 1);
        object.geometry.setDrawRange(0, count);
        object.geometry.boundingBox = box.clone();
        object.geometry.boundingSphere = sphere.clone();
        object.visible = count > 0;
      }
    };

    // A snapshot waits for the next frame; an error that arrives meanwhile
    // is reported after it is drawn, so the last good level stays on screen.
    let drawing = Promise.resolve();
    // The vertices and the lists of a level reach the GPU in separate
    // frames, which halves the largest upload of a frame; meanwhile the
    // previous level's lists are drawn over the new positions (vertices keep
    // their ids, and new ones are not yet referenced).
    const draw = async (model) => {
      await nextFrame();  // at most one geometry update per frame
      if (finished) return;
      applyVertices(model);
      options.onAnimate?.(group);
      await nextFrame();
      if (finished) return;
      applyLists(model);
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
    for (const worker of this.workers) worker.terminate();
    this.workers.clear();
    for (const material of Object.values(this.materials)) material.dispose();
  }
}
