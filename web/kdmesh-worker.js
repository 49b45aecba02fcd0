// The worker behind KDMeshLoader: decodes a stream off the main thread and
// hands back snapshots as transferable arrays, one at a time, when the page
// asks for the next one (so a fast network never floods the page). A worker
// decodes one stream after another: the loader keeps a pool of them.
//
// kdmesh/three runs it from web/dist/kdmesh-worker-source.js (this file
// bundled into one classic script, see scripts/bundle-worker.mjs) through a
// Blob URL, or as a module worker from a URL given to setWorkerUrl().
//
// Messages in:  {type: 'start', wasm (a WebAssembly.Module), limits?, coarsePlacement?, tetrahedra?, geomorph?,
//               normals? (false: compute none)}
//               (a new stream), {type: 'bytes', bytes}, {type: 'end'},
//               {type: 'next'} (the page is ready for a snapshot),
//               {type: 'last'} (the page is ready for the complete model only, for now)
// Messages out: {type: 'header', header} (with header.labels, see sendHeader()),
//               {type: 'snapshot', model} (the last one has model.complete),
//               {type: 'error', code, message}
//
// A snapshot's arrays are sized for the final model, so that the page can
// adopt them as GPU buffer storage: positions, normals and each vertex
// attribute (model.attributes, name -> {array, itemSize, ...}) in their own
// storage, the lists of simplices packed (see pack()), and the surface's
// index (model.surface) with, for labelled streams, its triangles ordered
// by label into model.groups (see orderByLabel()).
import { createDecoder, setWasmSource } from './kdmesh.js';

let wasmSet = false;
let job = null;  // the stream being decoded (see start())

// Faces of the tetrahedra that belong to exactly one: the visible surface of
// a tetrahedral mesh, oriented outwards when the tetrahedra are positive.
// `owners[i]` is the tetrahedron of face i (whose label the face shows).
function boundaryOfTetrahedra(tetrahedra) {
  const faces = new Map();
  const corners = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];
  for (let t = 0; t < tetrahedra.length; t += 4) {
    for (const [a, b, c] of corners) {
      const face = [tetrahedra[t + a], tetrahedra[t + b], tetrahedra[t + c]];
      const key = face.slice().sort((x, y) => x - y).join(',');
      if (faces.has(key)) faces.delete(key);
      else faces.set(key, { face, owner: t / 4 });
    }
  }
  const triangles = new Uint32Array(faces.size * 3);
  const owners = new Uint32Array(faces.size);
  let i = 0;
  for (const { face, owner } of faces.values()) {
    owners[i] = owner;
    triangles.set(face, 3 * i++);
  }
  return { triangles, owners };
}

// The drawn triangles of a labelled stream (`triangles`, 3 indices each,
// with `labels`, one per triangle) ordered by label for three.js's
// geometry groups: in new storage of at least `capacity` elements (see
// pack()), the triangles of each label in one range, in the order of the
// stream's label table `table` (ascending), each label's triangles in their
// order here (a stable counting sort: one pass to count, one to place).
// `indexOf` maps each label to its index in the table; labels come in runs,
// so a label like the last skips the look-up. Returns the ordered triangles
// and one group per label the triangles have, { start, count } in indices,
// materialIndex the label's index in the table (the same at every level,
// whichever labels a level lacks), and the label.
function orderByLabel(triangles, labels, table, indexOf, capacity) {
  const indices = new Uint32Array(labels.length);
  const counts = new Uint32Array(table.length);
  let last = 0, index = -1;
  for (let t = 0; t < labels.length; ++t) {
    if (index < 0 || labels[t] !== last) {
      last = labels[t];
      index = indexOf.get(last);
    }
    indices[t] = index;
    ++counts[index];
  }
  // Where each label's next triangle goes, in triangles: after those of
  // every smaller label.
  const next = new Uint32Array(table.length);
  const groups = [];
  for (let i = 0, start = 0; i < table.length; start += counts[i++]) {
    next[i] = start;
    if (counts[i]) groups.push({ start: 3 * start, count: 3 * counts[i], materialIndex: i, label: table[i] });
  }
  const storage = new Uint32Array(Math.max(triangles.length, capacity));
  for (let t = 0; t < labels.length; ++t) {
    const to = 3 * next[indices[t]]++;
    storage[to] = triangles[3 * t];
    storage[to + 1] = triangles[3 * t + 1];
    storage[to + 2] = triangles[3 * t + 2];
  }
  return { surface: storage.subarray(0, triangles.length), groups };
}

// Area-weighted vertex normals of the triangles, for streams without normals
// of their own (see streamNormals()): computed here, off the page's main
// thread, and sent with the snapshot; in storage as large as the
// positions' (see pack()).
function vertexNormals(positions, triangles) {
  const normals = new Float32Array(positions.buffer.byteLength / 4).subarray(0, positions.length);
  for (let t = 0; t < triangles.length; t += 3) {
    const a = 3 * triangles[t], b = 3 * triangles[t + 1], c = 3 * triangles[t + 2];
    const ax = positions[a], ay = positions[a + 1], az = positions[a + 2];
    const ux = positions[b] - ax, uy = positions[b + 1] - ay, uz = positions[b + 2] - az;
    const vx = positions[c] - ax, vy = positions[c + 1] - ay, vz = positions[c + 2] - az;
    const nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    normals[a] += nx;
    normals[a + 1] += ny;
    normals[a + 2] += nz;
    normals[b] += nx;
    normals[b + 1] += ny;
    normals[b + 2] += nz;
    normals[c] += nx;
    normals[c + 1] += ny;
    normals[c + 2] += nz;
  }
  for (let i = 0; i < positions.length; i += 3) {
    const x = normals[i], y = normals[i + 1], z = normals[i + 2];
    const inverse = 1 / (Math.sqrt(x * x + y * y + z * z) || 1);
    normals[i] = x * inverse;
    normals[i + 1] = y * inverse;
    normals[i + 2] = z * inverse;
  }
  return normals;
}

// The stream's own normals, when it has a 'normal' attribute of three
// float32 components: they stand for the input's, which triangles of a
// coarse level would only approximate. Else undefined.
function streamNormals(attributes) {
  const normal = attributes.normal;
  return normal && normal.itemSize === 3 && normal.array instanceof Float32Array ? normal.array : undefined;
}

// Lists drawn together, one after the other in one new array of at least
// `capacity` elements (the final model's size, from the header), so that the
// page adopts the array as a GPU buffer's storage without copying or
// reallocating at every level. Returns views of the lists in it.
function pack(Type, lists, capacity) {
  const length = lists.reduce((sum, list) => sum + list.length, 0);
  const storage = new Type(Math.max(length, capacity));
  let offset = 0;
  return lists.map((list) => {
    storage.set(list, offset);
    offset += list.length;
    return storage.subarray(offset - list.length, offset);
  });
}

// Smallest and largest coordinates, [x, y, z, x, y, z]; NaN coordinates
// are passed over.
function bounds(positions) {
  let minX = Infinity, minY = Infinity, minZ = Infinity, maxX = -Infinity, maxY = -Infinity, maxZ = -Infinity;
  for (let i = 0; i < positions.length; i += 3) {
    const x = positions[i], y = positions[i + 1], z = positions[i + 2];
    if (x < minX) minX = x;
    if (x > maxX) maxX = x;
    if (y < minY) minY = y;
    if (y > maxY) maxY = y;
    if (z < minZ) minZ = z;
    if (z > maxZ) maxZ = z;
  }
  return [minX, minY, minZ, maxX, maxY, maxZ];
}

// Every edge of the tetrahedra once, for the wireframe view.
function edgesOfTetrahedra(tetrahedra) {
  const seen = new Set();
  const out = [];
  const pairs = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];
  for (let t = 0; t < tetrahedra.length; t += 4) {
    for (const [i, j] of pairs) {
      const a = Math.min(tetrahedra[t + i], tetrahedra[t + j]), b = Math.max(tetrahedra[t + i], tetrahedra[t + j]);
      const key = a * 4294967296 + b;
      if (!seen.has(key)) {
        seen.add(key);
        out.push(a, b);
      }
    }
  }
  return Uint32Array.from(out);
}

// While received bytes wait to be decoded, handing over snapshots may take
// at most this share of the worker's time: a snapshot waits until decoding
// since the previous one has taken (1 - share) / share times as long as that
// one did. With nothing waiting, a snapshot delays no decoding and goes at
// once; so does the last.
const kHandOverShare = 0.1;

function snapshotDue() {
  return !job.pending.length || job.decoder.progress.complete ||
    job.decodeMs * kHandOverShare >= job.handOverMs * (1 - kHandOverShare);
}

function sendSnapshot() {
  const { decoder, wireframe, geomorph } = job;
  if (!decoder || !job.changed) return;
  if (!(job.wanted && snapshotDue()) && !(job.wantsLast && decoder.progress.complete)) return;
  const began = performance.now();
  const live = decoder.snapshot({ copy: false });  // views, valid until the next call on the decoder
  const { triangles: boundary, owners } = live.tetrahedra.length ? boundaryOfTetrahedra(live.tetrahedra)
    : { triangles: new Uint32Array(0), owners: new Uint32Array(0) };
  const tetrahedronEdges = live.tetrahedra.length && wireframe ? edgesOfTetrahedra(live.tetrahedra) : new Uint32Array(0);
  // Capacities: the final maximal simplices and isolated vertices, and for
  // tetrahedra up to four boundary triangles and six edges each.
  const { vertexCount, simplexCounts: [pointCount, edgeCount, triangleCount, tetrahedronCount] } = decoder.header;
  const [positions] = pack(Float32Array, [live.positions], 3 * vertexCount);
  const [points] = pack(Uint32Array, [live.points], pointCount);
  const [edges, tetrahedronEdgesInPlace] = pack(Uint32Array, [live.edges, tetrahedronEdges],
    2 * (edgeCount + (wireframe ? 6 * tetrahedronCount : 0)));
  // The surface's index: the triangles, then the boundary of the
  // tetrahedra, in storage sized for the final model; for labelled streams
  // that is the surface ordered by label (the boundary's triangles with
  // their tetrahedra's labels), and `triangles` a copy in the decoder's order.
  const surfaceCapacity = 3 * (triangleCount + 4 * tetrahedronCount);
  const [triangles, boundaryInPlace] = pack(Uint32Array, [live.triangles, boundary], live.labels ? 0 : surfaceCapacity);
  const drawnTriangles = new Uint32Array(triangles.buffer, 0, triangles.length + boundary.length);  // both lists
  let surface = drawnTriangles, groups = [];
  if (live.labels) {
    const drawnLabels = new Int32Array(drawnTriangles.length / 3);
    drawnLabels.set(live.labels.triangles);
    for (let i = 0; i < owners.length; ++i) drawnLabels[live.labels.triangles.length + i] = live.labels.tetrahedra[owners[i]];
    ({ surface, groups } = orderByLabel(drawnTriangles, drawnLabels, job.labels, job.labelIndex, surfaceCapacity));
  }
  // Each vertex attribute in storage of its own, sized like the positions'.
  const attributes = {};
  for (const [name, attribute] of Object.entries(live.attributes))
    attributes[name] = { ...attribute, array: pack(attribute.array.constructor, [attribute.array], vertexCount * attribute.itemSize)[0] };
  // Simplex labels (labelled streams): copies, as the views into the
  // decoder's memory must not be posted (a view posts its whole buffer).
  const labels = live.labels && {
    edges: live.labels.edges.slice(), triangles: live.labels.triangles.slice(),
    tetrahedra: live.labels.tetrahedra.slice(),
  };
  const model = {
    ...live, positions, points, edges, triangles, tetrahedra: live.tetrahedra.slice(), attributes, labels,
    boundary: boundaryInPlace, tetrahedronEdges: tetrahedronEdgesInPlace, surface, groups,
    bounds: bounds(positions),
    normals: streamNormals(attributes) ??
      (drawnTriangles.length && job.normals ? vertexNormals(positions, drawnTriangles) : new Float32Array(0)),
    parents: geomorph ? decoder.parents() : new Uint32Array(0),
    progress: decoder.progress,
  };
  job.wanted = job.wantsLast = false;
  job.changed = false;
  job.decodeMs = 0;
  job.handOverMs = performance.now() - began;
  const buffers = [positions, points, edges, triangles, surface, model.tetrahedra, model.normals, model.parents,
    ...Object.values(attributes).map((a) => a.array), ...(labels ? Object.values(labels) : [])]
    .map((a) => a.buffer).filter((b, i, all) => b.byteLength && all.indexOf(b) === i);
  postMessage({ type: 'snapshot', model }, buffers);
  if (model.complete) end();
}

// The stream is over: the decoder's memory goes back to the worker's heap
// for the next stream.
function end() {
  job.decoder?.dispose();
  job.decoder = null;
  job.done = true;
}

// The header goes to the page once the stream's label table (header.labels,
// after the header and the attribute table) has arrived too, so that the
// page knows every label's materialIndex before the first level; a stream
// that fails before the table sends it without (labels null) first.
function sendHeader() {
  const { header } = job;
  job.headerSent = true;
  if (header.labels) {
    job.labels = header.labels;
    job.labelIndex = new Map(Array.from(header.labels, (label, index) => [label, index]));
  }
  postMessage({ type: 'header', header });
}

function fail(error) {
  if (job.header && !job.headerSent) sendHeader();
  postMessage({ type: 'error', code: error.code ?? 'error', message: error.message ?? String(error) });
  end();
}

// Received bytes wait in job.pending and are decoded one piece per task, so
// that the page's 'next' requests are seen between pieces: the page gets
// refinements while a fast download is still being decoded.
const kSliceBytes = 16384;

function pump(current) {
  current.pumping = false;
  if (current !== job || job.done || !job.decoder) return;
  const { decoder, pending } = job;
  try {
    if (pending.length) {
      const before = decoder.progress.chunksApplied;
      const began = performance.now();
      decoder.push(pending.shift());
      job.decodeMs += performance.now() - began;
      if (!job.headerSent) {
        job.header = decoder.header;
        if (job.header?.labels) sendHeader();
      }
      if (decoder.progress.chunksApplied !== before) job.changed = true;
    } else if (job.ending) {
      job.ending = false;
      decoder.finish();
    }
    sendSnapshot();
  } catch (error) {
    fail(error);
    return;
  }
  if (pending.length || job.ending) schedule();
}

// Each piece is decoded in a task of its own, posted through a message
// channel: a chain of setTimeout(0) calls is clamped to at least 4 ms a
// call after the fifth, idle time that a stream of many pieces would pay
// at nearly every piece. Each message pumps the job that posted it, in
// posting order.
const pieces = new MessageChannel();
const pumped = [];
pieces.port1.onmessage = () => pump(pumped.shift());
function schedule() {
  if (job.pumping || !job.decoder) return;
  job.pumping = true;
  pumped.push(job);
  pieces.port2.postMessage(null);
}

async function start({ wasm, limits, coarsePlacement, tetrahedra, geomorph, normals }) {
  const current = (job = {
    decoder: null, done: false, wanted: true, wantsLast: false, changed: false, pending: [], ending: false, pumping: false,
    header: null, headerSent: false,  // the header as last read, and whether the page has it (see sendHeader())
    labels: null, labelIndex: null,   // the label table, and each label's index in it (see orderByLabel())
    decodeMs: 0, handOverMs: 0,  // decoding since the last snapshot, and that snapshot's cost (snapshotDue())
    wireframe: tetrahedra === 'wireframe',  // also send the edges of the tetrahedra
    geomorph: Boolean(geomorph),            // also send every vertex's parent
    normals: normals !== false,             // compute normals for streams without their own
  });
  try {
    if (!wasmSet) {
      setWasmSource(wasm);
      wasmSet = true;
    }
    const decoder = await createDecoder({ limits, coarsePlacement });
    if (current !== job) return decoder.dispose();
    job.decoder = decoder;
    schedule();
  } catch (error) {
    if (current === job) fail(error);
  }
}

onmessage = ({ data }) => {
  if (data.type === 'start') return start(data);
  if (!job || job.done) return;
  switch (data.type) {
    case 'bytes':
      // Slices of at most 16 KiB: a large network read still yields
      // refinements (and the levels before a corrupt chunk) along the way.
      for (let at = 0; at < data.bytes.length; at += kSliceBytes) job.pending.push(data.bytes.subarray(at, at + kSliceBytes));
      schedule();
      break;
    case 'end':
      job.ending = true;
      schedule();
      break;
    case 'next':
      job.wanted = true;
      if (job.decoder) sendSnapshot();
      break;
    case 'last':
      job.wantsLast = true;
      if (job.decoder) sendSnapshot();
      break;
  }
};
