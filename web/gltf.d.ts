// Type declarations for kdmesh/gltf (web/gltf.js).
import { BufferGeometry, Group, Mesh, SkinnedMesh } from 'three';
import type { GLTFLoaderPlugin, GLTFParser } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { DecoderLimits } from 'kdmesh';
import { KDMeshLoader, LoadStats } from 'kdmesh/three';

/** 'KDMESH_progressive_compression' (docs/GLTF.md). */
export const EXTENSION_NAME: 'KDMESH_progressive_compression';

export interface KDMeshGLTFOptions {
  /** Decodes the streams in its pool of workers (default: one loader shared by every plugin without one). */
  loader?: KDMeshLoader;
  /** After each refinement of a compressed primitive's geometry; a promise it returns holds that primitive's next refinement back until it settles. */
  onRefine?: (geometry: BufferGeometry, stats: LoadStats) => unknown;
  /** Aborting stops every stream at its current level. */
  signal?: AbortSignal;
  limits?: DecoderLimits;
}

/** What the plugin adds to GLTFLoader's result, as gltf.userData.kdmesh. */
export interface KDMeshGLTFUserData {
  /** Resolves with the result once every stream of the scene is complete. */
  loaded: Promise<unknown>;
  /** Compressed primitives (geometries) being refined. */
  streams: number;
}

/**
 * GLTFLoader plugin: loader.register((parser) => new KDMeshGLTFExtension(parser, options)). The scene
 * comes at once; each compressed primitive's geometry is refined in place as its stream is decoded.
 */
export class KDMeshGLTFExtension implements GLTFLoaderPlugin {
  constructor(parser: GLTFParser, options?: KDMeshGLTFOptions);
  readonly name: 'KDMESH_progressive_compression';
  parser: GLTFParser;
  loader: KDMeshLoader;
  loadMesh(meshIndex: number): Promise<Group | Mesh | SkinnedMesh> | null;
  afterRoot(result: { userData: Record<string, unknown> }): null;
}
