// Type declarations for kdmesh (web/kdmesh.js).

/** An error from the decoder. `code` is stable: 'bad-magic', 'unsupported-version',
 * 'corrupt-header', 'corrupt-chunk', 'truncated', 'trailing-bytes', 'limit-exceeded',
 * 'disposed', 'invalid-argument', 'out-of-memory' or 'wasm-unavailable'; from
 * kdmesh/three also 'aborted', 'network' and 'worker-failed'. */
export class KdmeshError extends Error {
  constructor(code: string, message: string);
  readonly code: string;
}

/** Where the WebAssembly decoder can come from: a URL, the .wasm bytes or a compiled module. */
export type WasmSource = string | URL | ArrayBuffer | ArrayBufferView | WebAssembly.Module;

/** Caps on what a stream may ask for; exceeding one is a 'limit-exceeded' error. */
export interface DecoderLimits {
  maxVertices?: number;
  maxSimplices?: number;
  maxChunkBytes?: number;
  /** Vertices per byte of the whole stream (default 1024): raise it for clouds of many coincident points. */
  maxVerticesPerByte?: number;
  /** Edges, triangles and tetrahedra per byte of the whole stream (default 1024). */
  maxSimplicesPerByte?: number;
}

export interface DecoderOptions {
  limits?: DecoderLimits;
  /**
   * Where a vertex whose cell is not yet a grid point is drawn before the stream is complete:
   * halfway from the cell's centre to its neighbours' plane, clamped to the cell ('predicted', the default), or at the cell's centre.
   */
  coarsePlacement?: 'predicted' | 'centre';
}

export interface Header {
  vertexCount: number;
  maxDimension: number;
  /** Maximal simplices per dimension 0..3 of the complete model ([0]: isolated points). */
  simplexCounts: [number, number, number, number];
  quantization: 'grid' | 'float32';
  bits: number;
  step: number;
  totalBytes: number;
  chunkCount: number;
  /** Levels of the kd-tree: `progress.level` reaches it when the stream is complete (and goes past it
   * while coincident vertices of meshes and of attribute streams split apart). */
  depth: number;
  /** Vertex attributes the stream carries (their names and codings arrive with the first snapshot's `attributes`). */
  attributeCount: number;
  /** Whether edges, triangles and tetrahedra carry integer labels (Model.labels). */
  labelled: boolean;
  /** Whether the stream was encoded with --fast-decode (a larger stream that decodes faster). */
  fastDecode: boolean;
  /** The stream's label table, once it has arrived (right after the header and the attribute table): its
   * distinct labels, ascending. A label's index here is the same at every level (kdmesh/three's
   * materialIndex). null until then; empty for streams without labels. */
  labels: Int32Array | null;
}

/**
 * How a stream codes a vertex attribute (`kdmesh info` names the same): 'exact' keeps every bit;
 * 'uniform' quantizes each float32 component to codingBits bits over its range (encoder option
 * --attr-bits); 'octahedral' codes a float32 × 3 'normal' as unit vectors in two codingBits-bit
 * octahedral coordinates (--normal-bits), predicted from its neighbours' normals when the vertex
 * is created (point clouds, tetrahedral meshes); 'geometric-octahedral' codes a surface's normals
 * so after the last position bits, predicted from the decoded triangles: until they arrive a
 * vertex shows the normal of its triangles in the prefix. The decoded values are float32 either way.
 */
export type AttributeCoding = 'exact' | 'uniform' | 'octahedral' | 'geometric-octahedral';

/** A vertex attribute's values: vertexCount · itemSize of its type, as a three.js BufferAttribute takes them. */
export interface VertexAttribute {
  array: Uint8Array | Int8Array | Uint16Array | Int16Array | Uint32Array | Int32Array | Float32Array;
  itemSize: number;
  coding: AttributeCoding;
  /** Bits per component ('uniform') or per octahedral coordinate (the octahedral codings); 0 when 'exact'. */
  codingBits: number;
}

export interface Progress {
  bytesReceived: number;
  bytesConsumed: number;
  bytesExpected: number;
  chunksApplied: number;
  level: number;
  vertexCount: number;
  complete: boolean;
  /** No input vertex is farther than this from its snapshot vertex. */
  errorBound: number;
}

export interface Model {
  vertexCount: number;
  /** xyz, 3 floats per vertex (a float64 stream's float32 roundings). */
  positions: Float32Array;
  /** Float64 streams only: xyz, 3 doubles per vertex, exact once complete. */
  positions64?: Float64Array;
  /** Isolated vertices. */
  points: Uint32Array;
  /** 2 indices per edge. */
  edges: Uint32Array;
  /** 3 indices per triangle, in the input's winding. */
  triangles: Uint32Array;
  /** 4 indices per tetrahedron, in the input's orientation. */
  tetrahedra: Uint32Array;
  /** Vertex attributes by name (colours, normals, texture coordinates, ...), exact at every level. */
  attributes: Record<string, VertexAttribute>;
  /** Streams with simplex labels only: one label (material, region, group id) per simplex of each list,
   * exact once complete; a coarse simplex shows the label of an input simplex it stands for. */
  labels?: { edges: Int32Array; triangles: Int32Array; tetrahedra: Int32Array };
  complete: boolean;
  stats: { bytes: number; level: number; chunks: number; errorBound: number; bitsPerVertex: number };
}

export class Decoder {
  /** Feeds bytes (any split); applies every whole chunk. Throws KdmeshError on bad data. */
  push(bytes: ArrayBuffer | ArrayBufferView): Progress;
  /** Throws KdmeshError('truncated') unless the stream is complete. */
  finish(): void;
  readonly header: Header | null;
  readonly progress: Progress;
  /** The current level. With copy: false the arrays view WebAssembly memory and are
   * valid only until the next call on this decoder. */
  snapshot(options?: { copy?: boolean }): Model;
  /** parents[v]: the vertex that v was split from (connectivity streams). */
  parents(): Uint32Array;
  /** Frees the decoder's WebAssembly memory. */
  dispose(): void;
}

/** Where to load the WebAssembly decoder from. Default: the copy embedded in the package. */
export function setWasmSource(source: WasmSource): void;
/** Compiles the decoder (default source: setWasmSource's, else embedded); rejects with 'wasm-unavailable'. */
export function compileWasm(source?: WasmSource): Promise<WebAssembly.Module>;
export function createDecoder(options?: DecoderOptions): Promise<Decoder>;
export function decode(bytes: Uint8Array | ArrayBuffer, options?: DecoderOptions): Promise<Model>;
/** Bytes of WebAssembly heap in use (diagnostics). */
export function memoryInUse(): Promise<number>;
