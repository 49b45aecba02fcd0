// Type declarations for kdmesh/three (web/three.js).
import {
  BufferGeometry, Camera, Group, LineBasicMaterial, Loader, LoadingManager, Material, MeshStandardMaterial, PointsMaterial, Scene,
  WebGLRenderer,
} from 'three';
import { DecoderLimits, Header, Model, Progress, WasmSource } from 'kdmesh';

/** The triangles of one simplex label in the surface's index, as BufferGeometry.addGroup takes them. */
export interface LabelGroup {
  /** First index of the range, and indices in it (3 per triangle). */
  start: number;
  count: number;
  /** The label's index in the stream's label table (Header.labels): the same at every level. */
  materialIndex: number;
  label: number;
}

/** A level as the worker hands it over: the Model's lists plus what drawing needs. */
export interface StreamedModel extends Model {
  /** Boundary triangles of the tetrahedra, stored right after `triangles`. */
  boundary: Uint32Array;
  /** The surface's index: `triangles` then `boundary`; for labelled streams the same triangles ordered by
   * label (boundary triangles with their tetrahedron's label), each label's in their order in those lists. */
  surface: Uint32Array;
  /** Labelled streams: one group per distinct label of the surface's triangles, in ascending label order,
   * covering `surface` (a label of the stream absent from the level has none); empty otherwise. Edge
   * labels make no groups. */
  groups: LabelGroup[];
  /** Edges of the tetrahedra ('wireframe'), stored right after `edges`. */
  tetrahedronEdges: Uint32Array;
  /** [minX, minY, minZ, maxX, maxY, maxZ] */
  bounds: number[];
  /** The stream's 'normal' attribute when it is three float32, else computed from the triangles (empty without any). */
  normals: Float32Array;
  /** With geomorph: the vertex each vertex was split from. */
  parents: Uint32Array;
  progress: Progress;
}

export interface LoadStats {
  refinements: number;
  bytesReceived: number;
  /** The stream's size from its header, before it the response's Content-Length (0 if unknown). */
  bytesExpected: number;
  header: Header | null;
  complete: boolean;
  /** The last level drawn. */
  model: StreamedModel | null;
}

export interface LoadOptions<T> {
  /**
   * After each refinement. A promise (thenable) it returns holds the next refinement back until it
   * settles, while the worker decodes on; the complete model still comes as soon as it is decoded.
   * A page whose frames are slow to draw can so pace the levels it is handed.
   */
  onRefine?: (object: T, stats: LoadStats) => unknown;
  onHeader?: (header: Header) => void;
  onProgress?: (stats: LoadStats, event: ProgressEvent) => void;
  /** Aborting stops the download and keeps the current level. */
  signal?: AbortSignal;
  /** Decoder caps for this load (default: setDecoderLimits'). */
  limits?: DecoderLimits;
  /** Where vertices of unfinished cells are drawn (kdmesh's DecoderOptions). */
  coarsePlacement?: 'predicted' | 'centre';
}

/** loadGeometry and parseGeometry also take: */
export interface GeometryOptions extends LoadOptions<BufferGeometry> {
  /** Refine this geometry (its attributes and index are replaced) instead of a new one. */
  geometry?: BufferGeometry;
  /**
   * The geometry attribute of each stream attribute, by the stream's name: only these are set, and
   * no normals are computed (kdmesh/gltf names glTF semantics so).
   */
  attributes?: Record<string, { name: string; normalized: boolean }>;
}

export interface ProgressiveOptions extends LoadOptions<Group> {
  tetrahedra?: 'boundary' | 'wireframe';
  geomorph?: boolean;
  geomorphFrames?: number;
  onAnimate?: (object: Group) => void;
  /** The surface Mesh's material instead of `materials.surface`: an array draws the triangles of each simplex
   * label with the material at the label's index in Header.labels (the geometry's groups; userData.labels
   * is that table). */
  materials?: Material | Material[];
}

export interface ModelUserData {
  stats: LoadStats;
  /** Resolves with the object once complete; rejects with a KdmeshError. */
  loaded: Promise<unknown>;
}

export interface GeometryUserData extends ModelUserData {
  /** What the index holds, once the header has arrived. */
  primitive?: 'triangles' | 'lines' | 'points';
  /** Labelled triangles: the stream's label table (Header.labels), labels[materialIndex] the label of a
   * group's triangles, the same at every level (loadProgressive's surface geometry has the same). */
  labels?: Int32Array;
}

/** Tells without waiting whether the GPU has finished the work issued before the last set(). */
export class GpuFence {
  constructor(gl: WebGL2RenderingContext);
  passed(): boolean;
  set(): void;
}

/**
 * Loads .kdm streams into three.js. The stream's vertex attributes become geometry attributes of
 * the same names, refined in place: 'color' (integer types normalized), 'normal' (the stream's
 * instead of computed ones), 'uv', and any other under its own name. A model with a 'color' draws
 * the loader's own materials with vertexColors; materials the page supplies need it set by the page.
 */
export class KDMeshLoader extends Loader<Group> {
  constructor(manager?: LoadingManager);
  /** Shared by every model the loader loads; change or replace them before loading. */
  materials: { surface: MeshStandardMaterial; lines: LineBasicMaterial; points: PointsMaterial };
  uploadBytesPerSlice: number;
  workerLimit: number;
  /** Milliseconds after which an idle worker ends (default 10000). */
  workerIdleTime: number;
  decoderLimits: DecoderLimits;
  /** Every worker started, busy or idle. */
  readonly workers: Set<Worker>;
  /** Workers decoding a stream now. */
  readonly busyWorkers: number;

  prepareRenderer(renderer: WebGLRenderer, camera: Camera, scene: Scene): Promise<void>;
  setDecoderPath(path: string): this;
  setWasmSource(source: WasmSource): this;
  setWorkerUrl(url: string | URL): this;
  setWorkerLimit(limit: number): this;
  setDecoderLimits(limits: DecoderLimits): this;
  preload(): this;
  load(url: string, onLoad?: (group: Group) => void, onProgress?: (event: ProgressEvent) => void,
    onError?: (error: unknown) => void): Group;
  parse(buffer: ArrayBuffer | ArrayBufferView, onLoad?: (group: Group) => void, onError?: (error: unknown) => void): Group;
  loadProgressive(url: string, options?: ProgressiveOptions): Group & { userData: ModelUserData };
  loadGeometry(url: string, options?: GeometryOptions): BufferGeometry & { userData: GeometryUserData };
  /** loadGeometry for a whole stream already in memory. */
  parseGeometry(buffer: ArrayBuffer | ArrayBufferView, options?: GeometryOptions): BufferGeometry & { userData: GeometryUserData };
  abort(): this;
  dispose(): this;
}
