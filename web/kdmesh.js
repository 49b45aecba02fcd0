// kdmesh — progressive decoding of .kdm streams in browsers and Node, with
// the same C++ decoder as the native tools, compiled to WebAssembly.
//
//   import { decode, createDecoder } from 'kdmesh';
//   const model = await decode(bytes);                // whole stream
//   const decoder = await createDecoder();            // or piece by piece
//   decoder.push(piece);                              // any split of the bytes
//   const coarse = decoder.snapshot();                // the current level
//   decoder.dispose();
//
// The WebAssembly binary is embedded in the package (base64, loaded on first
// use), so nothing needs configuring under Node or a bundler. To serve the
// .wasm file yourself, call setWasmSource(url) before the first decoder.

import createKdmeshModule from './dist/kdmesh-wasm.js';

/** An error from the decoder, with a stable `code` such as 'corrupt-chunk'. */
export class KdmeshError extends Error {
  constructor(code, message) {
    super(message);
    this.name = 'KdmeshError';
    this.code = code;
  }
}

let wasmSource;
let modulePromise;

/**
 * Where the WebAssembly decoder comes from: a URL (string or URL), the bytes
 * of kdmesh-wasm.wasm (ArrayBuffer or typed array), or a compiled
 * WebAssembly.Module. Call before the first decoder is created; the default
 * is the copy embedded in the package.
 */
export function setWasmSource(source) {
  if (modulePromise) throw new KdmeshError('invalid-argument', 'setWasmSource must be called before the first decoder');
  wasmSource = source;
}

function base64Bytes(text) {
  if (typeof Buffer === 'function') return new Uint8Array(Buffer.from(text, 'base64'));
  const binary = atob(text);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes;
}

async function compile(source) {
  if (source instanceof WebAssembly.Module) return source;
  if (source === undefined) {
    const { wasmBase64 } = await import('./dist/kdmesh-wasm-binary.js');
    return WebAssembly.compile(base64Bytes(wasmBase64));
  }
  if (source instanceof ArrayBuffer || ArrayBuffer.isView(source)) return WebAssembly.compile(source);
  const response = await fetch(String(source), { credentials: 'same-origin' });
  if (!response.ok) throw new Error(`HTTP ${response.status} for ${response.url}`);
  // Streaming compilation needs the wasm MIME type; other hosts get the bytes compiled.
  if (typeof WebAssembly.compileStreaming === 'function' && response.headers.get('content-type') === 'application/wasm')
    return WebAssembly.compileStreaming(response);
  return WebAssembly.compile(await response.arrayBuffer());
}

/**
 * Compiles the WebAssembly decoder from `source` (as for setWasmSource;
 * default: the source set there, else the embedded copy). The module can be
 * posted to workers, which then skip the download and the compilation.
 * Rejects with a KdmeshError 'wasm-unavailable'.
 */
export async function compileWasm(source = wasmSource) {
  try {
    return await compile(source);
  } catch (error) {
    throw new KdmeshError('wasm-unavailable', `cannot load the kdmesh WebAssembly decoder: ${error.message ?? error}`);
  }
}

// The Emscripten module running `wasm` (a WebAssembly.Module). Emscripten
// reports only synchronous failures of an instantiateWasm hook, so an
// asynchronous one rejects here.
function instantiate(wasm) {
  return new Promise((resolve, reject) => {
    createKdmeshModule({
      instantiateWasm(imports, receive) {
        WebAssembly.instantiate(wasm, imports).then((instance) => receive(instance), reject);
        return {};
      },
    }).then(resolve, reject);
  });
}

// The records the C API writes as doubles, described by kdm_layout() (see
// wasm/binding.cpp): for each record, its fields with their offsets.
function parseLayout(text) {
  const records = {};
  for (const line of text.split('\n')) {
    const colon = line.indexOf(':');
    let offset = 0;
    const fields = line.slice(colon + 1).trim().split(' ').map((spec) => {
      const [, name, count, kind] = /^(\w+)(?:\[(\d+)\])?(?::(.+))?$/.exec(spec);
      const field = { name, offset, count: Number(count ?? 1), words: kind && kind !== 'bool' ? kind.split('|') : null, bool: kind === 'bool' };
      offset += field.count;
      return field;
    });
    records[line.slice(0, colon)] = { fields, size: offset };
  }
  return records;
}

function readRecord({ fields }, values) {
  const out = {};
  for (const { name, offset, count, words, bool } of fields) {
    const value = values[offset];
    out[name] = count > 1 ? Array.from(values.subarray(offset, offset + count)) : bool ? value === 1 : words ? words[value] : value;
  }
  return out;
}

function loadModule() {
  if (!modulePromise) {
    modulePromise = compileWasm(wasmSource)
      .then((wasm) => instantiate(wasm).catch((error) => {
        throw new KdmeshError('wasm-unavailable', `cannot start the kdmesh WebAssembly decoder: ${error.message ?? error}`);
      }))
      .then((module) => Object.assign(module, { records: parseLayout(module.UTF8ToString(module._kdm_layout())) }))
      .catch((error) => {
        modulePromise = undefined;
        throw error;
      });
  }
  return modulePromise;
}

// Bytes handed to the WebAssembly decoder per call. Engines switch a
// WebAssembly function to its optimized code between calls, not while it
// runs, so a whole stream decoded in one call would run its first decode
// in the baseline compiler's code from start to end.
const PUSH_SLICE_BYTES = 16384;

const EMPTY_INDICES = new Uint32Array(0);
// Typed arrays of kdmesh::AttributeType's values, in its order.
const ATTRIBUTE_ARRAYS = [Uint8Array, Int8Array, Uint16Array, Int16Array, Uint32Array, Int32Array, Float32Array];
// Names of kdmesh::AttributeQuantization::Kind's values, in its order (as
// `kdmesh info` names them).
const ATTRIBUTE_CODINGS = ['exact', 'uniform', 'octahedral', 'geometric-octahedral'];

const limitNames = ['maxVertices', 'maxSimplices', 'maxChunkBytes', 'maxVerticesPerByte', 'maxSimplicesPerByte'];

// The decoder limits as the C API takes them (0: the default), each given
// one a whole number from 1 to 2^32 - 1.
function checkedLimits(limits) {
  if (typeof limits !== 'object' || limits === null) throw new TypeError('limits must be an object');
  for (const name of Object.keys(limits))
    if (!limitNames.includes(name)) throw new TypeError(`unknown decoder limit '${name}' (known: ${limitNames.join(', ')})`);
  const out = {};
  for (const name of limitNames) {
    const value = limits[name];
    if (value === undefined) {
      out[name] = 0;
    } else if (typeof value !== 'number' || !Number.isInteger(value) || value < 1 || value > 0xffffffff) {
      throw new RangeError(`decoder limit ${name} must be a whole number from 1 to 2^32 - 1, not ${String(value)}`);
    } else {
      out[name] = value;
    }
  }
  return out;
}

// The bytes of an ArrayBuffer or of a view of one (a typed array or a
// DataView), without a copy; anything else is a TypeError rather than
// bytes made up from it.
function bytesOf(bytes) {
  if (bytes instanceof Uint8Array) return bytes;
  if (ArrayBuffer.isView(bytes)) return new Uint8Array(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  if (bytes instanceof ArrayBuffer || (typeof SharedArrayBuffer !== 'undefined' && bytes instanceof SharedArrayBuffer))
    return new Uint8Array(bytes);
  throw new TypeError(`push() takes an ArrayBuffer or a view of one, not ${bytes === null ? 'null' : typeof bytes}`);
}

/** A progressive decoder; create it with createDecoder(). */
export class Decoder {
  #module;
  #handle;
  #scratch;  // doubles shared with the C API
  #error;    // sticky: a failed decoder stays failed

  constructor(module, options = {}) {
    this.#module = module;
    const limits = checkedLimits(options.limits ?? {});
    const placement = options.coarsePlacement ?? 'predicted';
    if (placement !== 'predicted' && placement !== 'centre')
      throw new RangeError(`coarsePlacement must be 'predicted' or 'centre', not ${String(placement)}`);
    this.#handle = module._kdm_create(limits.maxVertices, limits.maxSimplices, limits.maxChunkBytes,
                                      limits.maxVerticesPerByte, limits.maxSimplicesPerByte, placement === 'centre' ? 1 : 0);
    this.#scratch = module._malloc(8 * Math.max(module.records.header.size, module.records.progress.size));
    if (!this.#handle || !this.#scratch) throw new KdmeshError('out-of-memory', 'cannot allocate a decoder');
  }

  #live() {
    if (!this.#handle) throw new KdmeshError('disposed', 'the decoder has been disposed');
    if (this.#error) throw this.#error;
    return this.#module;
  }

  #check(code) {
    if (code === 0) return;
    const m = this.#module;
    const name = m.UTF8ToString(m._kdm_error_name(code));
    this.#error = new KdmeshError(name, m.UTF8ToString(m._kdm_error_message(this.#handle)));
    throw this.#error;
  }

  #doubles(count) {
    return new Float64Array(this.#module.HEAPU8.buffer, this.#scratch, count);
  }

  /**
   * Feeds the next bytes of the stream (any split, even one byte at a time).
   * Applies every whole chunk and keeps the rest buffered. Throws a
   * KdmeshError on corrupt data; the decoder then stays failed.
   */
  push(bytes) {
    const m = this.#live();
    const view = bytesOf(bytes);
    let start = 0;
    do {
      const slice = view.subarray(start, start + PUSH_SLICE_BYTES);
      const at = m._kdm_input(this.#handle, slice.length);
      m.HEAPU8.set(slice, at);
      this.#check(m._kdm_push(this.#handle, slice.length));
      start += slice.length;
    } while (start < view.length);
    return this.progress;
  }

  /** Throws unless the stream is complete (e.g. 'truncated'). */
  finish() {
    const m = this.#live();
    this.#check(m._kdm_finish(this.#handle));
  }

  /**
   * Header fields once the header (at most 88 bytes) has arrived, else null;
   * with `labels`, the stream's label table once it has arrived (it follows
   * the header and the attribute table): an Int32Array of the stream's
   * distinct simplex labels, ascending, where a label's index is the same at
   * every level (a material index for it). null until then, empty for
   * streams without labels. A copy.
   */
  get header() {
    const m = this.#live();
    const h = this.#handle;
    if (!m._kdm_has_header(h)) return null;
    m._kdm_header(h, this.#scratch);
    const header = readRecord(m.records.header, this.#doubles(m.records.header.size));
    // A labelled stream's table holds at least one label: none yet means not arrived.
    const count = m._kdm_table_label_count(h);
    header.labels = count || !header.labelled ? new Int32Array(m.HEAPU8.buffer, m._kdm_table_labels(h), count).slice() : null;
    return header;
  }

  /** { bytesReceived, bytesConsumed, bytesExpected, chunksApplied, level, vertexCount, complete, errorBound } */
  get progress() {
    const m = this.#live();
    m._kdm_progress(this.#handle, this.#scratch);
    return readRecord(m.records.progress, this.#doubles(m.records.progress.size));
  }

  /**
   * The model at the current level: { vertexCount, positions, positions64?,
   * points, edges, triangles, tetrahedra, attributes, labels?, complete,
   * stats }. `positions64` (float64 streams only) is a Float64Array of the
   * exact doubles once complete (before, `positions` widened). `labels`
   * (streams with simplex labels only) holds { edges, triangles, tetrahedra },
   * an Int32Array of one label per simplex of each list. `attributes` maps
   * each vertex attribute's name to { array, itemSize, coding, codingBits }:
   * a typed array of vertexCount · itemSize values, the type's own
   * (Uint8Array for uint8, ...), and how the stream codes them: 'exact'
   * (codingBits 0), 'uniform' (float32 quantized to codingBits bits per
   * component over its range, the encoder's --attr-bits), 'octahedral'
   * (unit normals as two codingBits-bit octahedral coordinates,
   * --normal-bits) or 'geometric-octahedral' (the same for a surface's
   * normals, which arrive after the last position bits: until then a
   * vertex shows the normal of its triangles). With { copy: false } the arrays
   * are views of WebAssembly memory, valid only until the next call on this
   * decoder; by default they are copies the caller may keep.
   */
  snapshot({ copy = true } = {}) {
    const m = this.#live();
    const h = this.#handle;
    m._kdm_snapshot(h);
    const vertexCount = m._kdm_vertex_count(h);
    const take = (array) => (copy ? array.slice() : array);
    const positions = take(new Float32Array(m.HEAPU8.buffer, m._kdm_positions(h), 3 * vertexCount));
    const indices = (dimension) => {
      const count = m._kdm_index_count(h, dimension);
      return count ? take(new Uint32Array(m.HEAPU8.buffer, m._kdm_indices(h, dimension), count)) : EMPTY_INDICES;
    };
    // Vertex attributes by name: { array, itemSize }, as a three.js
    // BufferAttribute takes them, with how the stream codes them (coding,
    // codingBits: 0 when exact).
    const attributes = {};
    for (let a = 0, count = m._kdm_attribute_count(h); a < count; ++a) {
      const Type = ATTRIBUTE_ARRAYS[m._kdm_attribute_type(h, a)];
      const itemSize = m._kdm_attribute_components(h, a);
      const array = take(new Type(m.HEAPU8.buffer, m._kdm_attribute_values(h, a), vertexCount * itemSize));
      attributes[m.UTF8ToString(m._kdm_attribute_name(h, a))] = {
        array, itemSize, coding: ATTRIBUTE_CODINGS[m._kdm_attribute_coding(h, a)], codingBits: m._kdm_attribute_coding_bits(h, a),
      };
    }
    const progress = this.progress;
    const model = {
      vertexCount,
      positions,
      points: indices(0),
      edges: indices(1),
      triangles: indices(2),
      tetrahedra: indices(3),
      attributes,
      complete: progress.complete,
      stats: {
        bytes: progress.bytesConsumed,
        level: progress.level,
        chunks: progress.chunksApplied,
        errorBound: progress.errorBound,
        bitsPerVertex: vertexCount ? (8 * progress.bytesConsumed) / vertexCount : 0,
      },
    };
    const doubles = m._kdm_positions64(h);
    if (doubles) model.positions64 = take(new Float64Array(m.HEAPU8.buffer, doubles, 3 * vertexCount));
    if (this.header?.labelled) {
      const labels = (dimension) => {
        const count = m._kdm_label_count(h, dimension);
        return count ? take(new Int32Array(m.HEAPU8.buffer, m._kdm_labels(h, dimension), count)) : new Int32Array(0);
      };
      model.labels = { edges: labels(1), triangles: labels(2), tetrahedra: labels(3) };
    }
    return model;
  }

  /**
   * For streams with connectivity: parents[v] is the vertex that v was split
   * from (vertex ids are stable across snapshots), e.g. to animate a newly
   * split vertex from its parent's position. A copy.
   */
  parents() {
    const m = this.#live();
    const count = m._kdm_parent_count(this.#handle);
    return new Uint32Array(m.HEAPU8.buffer, m._kdm_parents(this.#handle), count).slice();
  }

  /** Frees the decoder's WebAssembly memory; the decoder is unusable after. */
  dispose() {
    if (!this.#handle) return;
    this.#module._kdm_destroy(this.#handle);
    this.#module._free(this.#scratch);
    this.#handle = 0;
    this.#scratch = 0;
  }
}

/**
 * Bytes of WebAssembly heap in use by all decoders (diagnostics: it returns
 * to the same value once every decoder is disposed).
 */
export async function memoryInUse() {
  return (await loadModule())._kdm_heap_in_use();
}

/**
 * A new progressive decoder. Options: { limits: { maxVertices, maxSimplices, maxChunkBytes,
 * maxVerticesPerByte, maxSimplicesPerByte }, coarsePlacement: 'predicted' (default: a vertex
 * whose cell is not yet a grid point lies halfway from its cell's centre to its neighbours' plane, clamped to the cell) or
 * 'centre' (at the cell's centre) }.
 */
export async function createDecoder(options = {}) {
  return new Decoder(await loadModule(), options);
}

/** Decodes a whole stream; rejects with a KdmeshError on corrupt or truncated data. */
export async function decode(bytes, options = {}) {
  const decoder = await createDecoder(options);
  try {
    decoder.push(bytes);
    decoder.finish();
    return decoder.snapshot();
  } finally {
    decoder.dispose();
  }
}
