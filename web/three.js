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
// LineSegments (edges) and a Points (isolated vertices).
import {
  BufferAttribute, BufferGeometry, DoubleSide, Group, LineBasicMaterial, LineSegments, Loader, Mesh,
  MeshStandardMaterial, Points, PointsMaterial,
} from 'three';

const nextFrame = () =>
  new Promise((resolve) => (typeof requestAnimationFrame === 'function' ? requestAnimationFrame(() => resolve()) : setTimeout(resolve, 16)));

// Replaces a geometry's attribute only when it no longer fits, so refinement
// reuses buffers sized for the final model (from the header) instead of
// allocating at every step; the draw range shows the current part.
function updateAttribute(geometry, name, array, itemSize, capacity) {
  let attribute = name === 'index' ? geometry.index : geometry.getAttribute(name);
  if (!attribute || attribute.array.length < array.length) {
    const storage = new array.constructor(Math.max(array.length, capacity * itemSize));
    attribute = new BufferAttribute(storage, itemSize);
    if (name === 'index') geometry.setIndex(attribute);
    else geometry.setAttribute(name, attribute);
  }
  attribute.array.set(array);
  attribute.clearUpdateRanges?.();
  attribute.addUpdateRange?.(0, array.length);
  attribute.needsUpdate = true;
  return attribute;
}

export class KDMeshLoader extends Loader {
  constructor(manager) {
    super(manager);
    this.wasmSource = undefined;
    this.workerUrl = new URL('./kdmesh-worker.js', import.meta.url);
    this.workers = new Set();
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
   * geomorphFrames frames, default 12; onAnimate(model) after each frame).
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
    const group = new Group();
    group.name = 'kdmesh';
    const surface = new Mesh(new BufferGeometry(), new MeshStandardMaterial({ color: 0xb8c4d6, roughness: 0.6, metalness: 0.05, side: DoubleSide }));
    const lines = new LineSegments(new BufferGeometry(), new LineBasicMaterial({ color: 0x33475b }));
    const points = new Points(new BufferGeometry(), new PointsMaterial({ color: 0x1f6feb, size: 2, sizeAttenuation: false }));
    group.add(surface, lines, points);

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

    const apply = (model) => {
      const capacity = stats.header?.vertexCount ?? model.vertexCount;
      let start = null;
      if (options.geomorph && previous) {
        start = new Float32Array(model.positions.length);
        for (let v = 0; v < model.vertexCount; ++v) {
          let ancestor = v;
          while (ancestor >= previous.count) ancestor = model.parents[ancestor];
          start[3 * v] = previous.positions[3 * ancestor];
          start[3 * v + 1] = previous.positions[3 * ancestor + 1];
          start[3 * v + 2] = previous.positions[3 * ancestor + 2];
        }
      }
      if (options.geomorph) previous = { positions: model.positions, count: model.vertexCount };
      const position = updateAttribute(surface.geometry, 'position', start ?? model.positions, 3, capacity);
      lines.geometry.setAttribute('position', position);
      points.geometry.setAttribute('position', position);
      if (start) morph(position, start, model.positions, model.vertexCount);
      else morphId += 1;  // a level drawn at once ends any morph in flight
      const faces = model.tetrahedra.length
        ? (() => {
            const merged = new Uint32Array(model.triangles.length + model.boundary.length);
            merged.set(model.triangles);
            merged.set(model.boundary, model.triangles.length);
            return merged;
          })()
        : model.triangles;
      updateAttribute(surface.geometry, 'index', faces, 1, faces.length);
      surface.geometry.setDrawRange(0, faces.length);
      // Normals come from the worker. On the final dragon (871k triangles,
      // Node 20) the worker's loop takes 90 ms and three.js's
      // computeVertexNormals 140 ms, which would block the main thread.
      updateAttribute(surface.geometry, 'normal', model.normals, 3, capacity);
      const edges = model.tetrahedronEdges.length
        ? (() => {
            const merged = new Uint32Array(model.edges.length + model.tetrahedronEdges.length);
            merged.set(model.edges);
            merged.set(model.tetrahedronEdges, model.edges.length);
            return merged;
          })()
        : model.edges;
      updateAttribute(lines.geometry, 'index', edges, 1, edges.length);
      lines.geometry.setDrawRange(0, edges.length);
      updateAttribute(points.geometry, 'index', model.points, 1, model.points.length);
      points.geometry.setDrawRange(0, model.points.length);
      for (const object of [surface, lines, points]) {
        object.geometry.computeBoundingSphere();
        object.geometry.computeBoundingBox();
        object.visible = object.geometry.drawRange.count > 0;
      }
    };

    worker.onmessage = async ({ data }) => {
      if (finished) return;
      if (data.type === 'header') {
        stats.header = data.header;
        stats.bytesExpected = data.header.totalBytes;
        options.onHeader?.(data.header);
      } else if (data.type === 'snapshot') {
        await nextFrame();  // at most one geometry update per frame
        if (finished) return;
        apply(data.model);
        stats.refinements += 1;
        stats.complete = data.model.complete;
        stats.model = data.model;
        options.onRefine?.(group, stats);
        if (stats.complete) finish();
        else worker.postMessage({ type: 'next' });
      } else if (data.type === 'error') {
        const error = new Error(data.message);
        error.code = data.code;
        finish(error);
      }
    };
    worker.onerror = (event) => finish(new Error(event.message || 'the kdmesh worker failed'));
    worker.postMessage({ type: 'start', wasmSource: this.wasmSource, tetrahedra: options.tetrahedra });

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

  dispose() {
    for (const worker of this.workers) worker.terminate();
    this.workers.clear();
  }
}
