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
  Box3, BufferAttribute, BufferGeometry, DoubleSide, Group, LineBasicMaterial, LineSegments, Loader, Mesh,
  MeshStandardMaterial, Points, PointsMaterial, Sphere,
} from 'three';

const nextFrame = () =>
  new Promise((resolve) => (typeof requestAnimationFrame === 'function' ? requestAnimationFrame(() => resolve()) : setTimeout(resolve, 16)));

// Writes `parts` (typed arrays of one type) one after the other into a
// geometry's attribute, replacing the attribute only when they no longer fit:
// refinement reuses buffers sized for the final model (from the header)
// instead of allocating at every step, and lists that are drawn together
// (triangles and the boundary of tetrahedra) are copied once, straight into
// place. Returns the attribute; the caller sets the draw range.
function updateAttribute(geometry, name, parts, itemSize, capacity) {
  const length = parts.reduce((sum, part) => sum + part.length, 0);
  let attribute = name === 'index' ? geometry.index : geometry.getAttribute(name);
  if (!attribute || attribute.array.length < length) {
    const storage = new parts[0].constructor(Math.max(length, capacity * itemSize));
    attribute = new BufferAttribute(storage, itemSize);
    if (name === 'index') geometry.setIndex(attribute);
    else geometry.setAttribute(name, attribute);
  }
  let offset = 0;
  for (const part of parts) {
    attribute.array.set(part, offset);
    offset += part.length;
  }
  attribute.clearUpdateRanges?.();
  attribute.addUpdateRange?.(0, length);
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
      const position = updateAttribute(surface.geometry, 'position', [start ?? model.positions], 3, capacity);
      lines.geometry.setAttribute('position', position);
      points.geometry.setAttribute('position', position);
      if (start) morph(position, start, model.positions, model.vertexCount);
      else morphId += 1;  // a level drawn at once ends any morph in flight
      // Normals come from the worker. On the final dragon (871k triangles,
      // Node 20) the worker's loop takes 90 ms and three.js's
      // computeVertexNormals 140 ms, which would block the main thread.
      if (model.normals.length) updateAttribute(surface.geometry, 'normal', [model.normals], 3, capacity);
      const lists = [
        [surface, [model.triangles, model.boundary]],
        [lines, [model.edges, model.tetrahedronEdges]],
        [points, [model.points]],
      ];
      // One bounding volume from the current vertices serves all three
      // objects (the shared attribute is padded to the final size).
      const box = new Box3().setFromArray(model.positions);
      const sphere = box.getBoundingSphere(new Sphere());
      for (const [object, parts] of lists) {
        const count = parts.reduce((sum, part) => sum + part.length, 0);
        if (count) updateAttribute(object.geometry, 'index', parts, 1, count);
        object.geometry.setDrawRange(0, count);
        object.geometry.boundingBox = box.clone();
        object.geometry.boundingSphere = sphere.clone();
        object.visible = count > 0;
      }
    };

    // A snapshot waits for the next frame; an error that arrives meanwhile
    // is reported after it is drawn, so the last good level stays on screen.
    let drawing = Promise.resolve();
    const draw = async (model) => {
      await nextFrame();  // at most one geometry update per frame
      if (finished) return;
      apply(model);
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

  dispose() {
    for (const worker of this.workers) worker.terminate();
    this.workers.clear();
  }
}
