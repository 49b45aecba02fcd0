// The kdmesh viewer: streams a .kdm model (or a glTF scene whose primitives
// are kdmesh streams, see kdmesh/gltf) into three.js and shows it refine.
// Query: ?model=NAME_OR_URL&throttle=KBPS. State for scripts and tests lives
// in window.kdmeshViewer.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { GpuFence, KDMeshLoader } from 'kdmesh/three';
import { KDMeshGLTFExtension } from 'kdmesh/gltf';
import { modelChecksum } from './model-checksum.js';

const $ = (id) => document.getElementById(id);
const viewer = (window.kdmeshViewer = {
  // state: 'idle', 'encoding' (a dropped mesh file, on the server),
  // 'loading', 'complete' or 'error' (also when stopped).
  state: 'idle', source: null, refinements: 0, vertexCount: 0, triangleCount: 0, tetrahedronCount: 0, edgeCount: 0,
  pointCount: 0, bytesReceived: 0, bytesExpected: 0, level: 0, error: null, firstRenderMs: null,
  // Names of the model's vertex attributes ('color' draws as vertex colours).
  attributes: [],
  // A stream with simplex labels: its labels, ascending (header.labels:
  // the label of each materialIndex), and whether the surface is coloured
  // by them.
  labelled: false, labels: [], colouredByLabel: false,
  // A glTF scene: its compressed primitives (streams) and those complete.
  streams: 0, streamsComplete: 0,
  // The complete model's totals, from the stream's header.
  levelCount: 0, vertexTotal: 0,
  // Since the load began: the first and the last level drawn, and the last
  // level decoded.
  completeMs: null, finalRenderMs: null, levelsSeen: [], longTasks: [],
  // Workers decoding a stream (0 once a load has ended, however).
  activeWorkers: () => loader.busyWorkers,
  // Of the complete model, for tests to compare with a Node decode. Computed
  // when read: hashing the dragon's arrays takes ~60 ms, a long task the
  // page itself has no use for.
  get checksum() {
    return this.state === 'complete' && current.userData.stats.model ? modelChecksum(current.userData.stats.model) : null;
  },
  // Whether the drawn positions are the last level's exactly (for tests:
  // geomorphs must end where the model is).
  drawnPositionsMatch() {
    const model = current?.userData.stats.model;
    const drawn = current?.children[0].geometry.getAttribute('position')?.array;
    if (!model || !drawn) return false;
    for (let i = 0; i < model.positions.length; ++i) if (drawn[i] !== model.positions[i]) return false;
    return true;
  },
  // Of the pixels of a new frame that differ from the background, the share
  // of the commonest colour (for tests: near 1 for a flat silhouette).
  commonestColourShare() {
    const data = framePixels();
    const counts = new Map();
    let total = 0;
    for (let i = 0; i < data.length; i += 4) {
      if (Math.abs(data[i] - 0xf4) + Math.abs(data[i + 1] - 0xf6) + Math.abs(data[i + 2] - 0xf8) <= 24) continue;
      const colour = (data[i] << 16) | (data[i + 1] << 8) | data[i + 2];
      counts.set(colour, (counts.get(colour) ?? 0) + 1);
      ++total;
    }
    return total ? Math.max(...counts.values()) / total : 0;
  },
  // Pixels of a new frame where one of red, green and blue is more than
  // 2.5 times each of the others, by that channel (for tests: vertex colours
  // drawn as the file has them, where the default materials are grey-blue).
  vividPixels() {
    const data = framePixels();
    const counts = { red: 0, green: 0, blue: 0 };
    const names = ['red', 'green', 'blue'];
    for (let i = 0; i < data.length; i += 4)
      for (let c = 0; c < 3; ++c)
        if (data[i + c] > 2.5 * data[i + (c + 1) % 3] && data[i + c] > 2.5 * data[i + (c + 2) % 3]) ++counts[names[c]];
    return counts;
  },
  // Pixels of a new frame that differ from the background (for tests).
  modelPixels() {
    const data = framePixels();
    const [r, g, b] = [0xf4, 0xf6, 0xf8];
    let count = 0;
    for (let i = 0; i < data.length; i += 4)
      if (Math.abs(data[i] - r) + Math.abs(data[i + 1] - g) + Math.abs(data[i + 2] - b) > 24) ++count;
    return count;
  },
  // Pixels that differ between a frame of the model as streamed and one of
  // copies of its geometries uploaded whole (for tests: 0 when every slice
  // of every level reached the GPU).
  pixelsDifferingFromFreshUpload() {
    const streamed = framePixels();
    const objects = current.children;
    const geometries = objects.map((object) => object.geometry);
    objects.forEach((object) => (object.geometry = object.geometry.clone()));
    const fresh = framePixels();
    objects.forEach((object, i) => {
      object.geometry.dispose();
      object.geometry = geometries[i];
    });
    let count = 0;
    for (let i = 0; i < streamed.length; i += 4)
      if (streamed[i] !== fresh[i] || streamed[i + 1] !== fresh[i + 1] || streamed[i + 2] !== fresh[i + 2]) ++count;
    return count;
  },
});

// Main-thread tasks over 50 ms since the current load began (where the
// browser reports them; entries arrive late, hence the time test).
let loadBegan = Infinity;
if (typeof PerformanceObserver === 'function' && PerformanceObserver.supportedEntryTypes?.includes('longtask')) {
  new PerformanceObserver((list) => {
    for (const entry of list.getEntries())
      if (entry.startTime >= loadBegan) viewer.longTasks.push(Math.round(entry.duration));
  }).observe({ type: 'longtask' });
}

function framePixels() {
  renderer.render(scene, camera);
  const canvas = document.createElement('canvas');
  canvas.width = renderer.domElement.width;
  canvas.height = renderer.domElement.height;
  const context = canvas.getContext('2d');
  context.drawImage(renderer.domElement, 0, 0);
  return context.getImageData(0, 0, canvas.width, canvas.height).data;
}

const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(Math.min(2, window.devicePixelRatio));
$('view').appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf4f6f8);
const camera = new THREE.PerspectiveCamera(40, 1, 0.001, 1000);
const controls = new OrbitControls(camera, renderer.domElement);
scene.add(new THREE.HemisphereLight(0xffffff, 0x445566, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.8);
camera.add(sun);
sun.position.set(1, 2, 3);
scene.add(camera);

function resize() {
  const { clientWidth: w, clientHeight: h } = $('view');
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(1, h);
  camera.updateProjectionMatrix();
}
window.addEventListener('resize', resize);
resize();
// Frames are drawn on demand (camera moves, refinements, resizes): a
// software-rendered page with a large model stays responsive. A frame is
// drawn only once the GPU has finished the previous one (see GpuFence).
const previousFrame = new GpuFence(renderer.getContext());
// While the decoder lags the download, drawing may keep the machine busy
// for at most this share of the time. Under software WebGL a frame of a
// large level takes the GPU process a second or more on the cores that the
// decoding worker needs; so such a level asks for the next one (the
// loader's onRefine promise) only once the frame that drew it has finished
// and (1 - share) / share times that frame's time has passed since. On a
// GPU a frame takes milliseconds, and while the decoder keeps up with the
// download a frame delays nothing: every level is drawn.
const kDrawShare = 0.25;
// The decoder lags when more than this many received bytes wait for it.
const kLagBytes = 65536;
let levelsToDraw = [];  // resolvers of levels shown since the last frame began
function paceRefinements(stats) {
  if (stats.bytesReceived - stats.model.progress.bytesConsumed <= kLagBytes) return undefined;
  const drawn = new Promise((resolve) => levelsToDraw.push(resolve));
  requestRender();
  return drawn;
}
// Resolves `levels` once the frame begun at `began` has finished and
// drawing has had its share.
function paceAfterFrame(began, levels) {
  const fence = new GpuFence(renderer.getContext());
  fence.set();
  requestAnimationFrame(function poll() {
    if (!fence.passed()) {
      requestAnimationFrame(poll);
      return;
    }
    const frameMs = performance.now() - began;
    setTimeout(() => levels.forEach((resolve) => resolve()), (frameMs * (1 - kDrawShare)) / kDrawShare);
  });
}
let frameRequested = false;
function requestRender() {
  if (frameRequested) return;
  frameRequested = true;
  requestAnimationFrame(function tick() {
    if (!previousFrame.passed()) {
      requestAnimationFrame(tick);
      return;
    }
    frameRequested = false;
    paintStatus();
    controls.update();
    fitFog();
    const began = performance.now();
    renderer.render(scene, camera);
    previousFrame.set();
    if (levelsToDraw.length) {
      paceAfterFrame(began, levelsToDraw);
      levelsToDraw = [];
    }
    const elapsed = performance.now() - loadBegan;
    if (viewer.refinements > 0 && viewer.firstRenderMs === null) viewer.firstRenderMs = elapsed;
    if (viewer.state === 'complete' && viewer.finalRenderMs === null) viewer.finalRenderMs = elapsed;
  });
}
controls.addEventListener('change', requestRender);
window.addEventListener('resize', requestRender);

const loader = new KDMeshLoader();
let current = null;
let controller = null;
let framed = false;
let reloadCurrent = null;  // loads the current model again (after a toggle)
const files = new Map();   // opened files by menu value: { name, bytes } (.kdm bytes)

// Points have no normals to light them: fog from the front of the model to
// its back shades them by depth, where a flat colour would show only a
// silhouette. Surfaces and lines are lit and keep their colours.
loader.materials.surface.fog = false;
loader.materials.lines.fog = false;
scene.fog = new THREE.Fog(scene.background, 1, 2);
let modelRadius = 0;
function fitFog() {
  const distance = camera.position.distanceTo(controls.target);
  scene.fog.near = Math.max(0, distance - modelRadius);
  scene.fog.far = distance + 3 * modelRadius;
}

// Colouring by label: the surface Mesh draws each label group with a
// material of a fixed palette, chosen by the group's materialIndex (the
// label's index in the stream's label table, the same at every level), so
// that a region keeps its colour from level to level. One material per
// palette colour, made on first use.
const labelPalette = [0x4e79a7, 0xf28e2b, 0xe15759, 0x76b7b2, 0x59a14f, 0xedc948, 0xb07aa1, 0xff9da7, 0x9c755f, 0xbab0ac];
const labelMaterials = [];  // palette index -> material
function labelMaterial(materialIndex) {
  const colour = materialIndex % labelPalette.length;
  if (!labelMaterials[colour]) {
    labelMaterials[colour] = loader.materials.surface.clone();
    labelMaterials[colour].color.set(labelPalette[colour]);
  }
  return labelMaterials[colour];
}

// The surface of the current model coloured by label when the toggle is on
// and the level has label groups, else with the material the loader gave it
// (kept aside while the palette is on).
function colourByLabel() {
  const surface = current?.children?.[0];
  if (!surface?.isMesh) return;
  const labels = surface.geometry.userData.labels;
  const on = $('labels').checked && Boolean(labels?.length);
  if (on) {
    if (!Array.isArray(surface.material)) surface.userData.ownMaterial = surface.material;
    surface.material = Array.from(labels, (label, materialIndex) => labelMaterial(materialIndex));
  } else if (surface.userData.ownMaterial) {
    surface.material = surface.userData.ownMaterial;
    delete surface.userData.ownMaterial;
  }
  viewer.colouredByLabel = on;
  requestRender();
}

function frame(group) {
  const box = new THREE.Box3().setFromObject(group);
  if (box.isEmpty()) return;
  const sphere = box.getBoundingSphere(new THREE.Sphere());
  modelRadius = sphere.radius;
  const distance = (sphere.radius || 1) / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2));
  camera.near = distance / 100;
  camera.far = distance * 100;
  camera.position.copy(sphere.center).add(new THREE.Vector3(0.3, 0.25, 1).normalize().multiplyScalar(distance));
  camera.updateProjectionMatrix();
  controls.target.copy(sphere.center);
}

function showStatus(text, isError = false) {
  $('status').textContent = text;
  $('status').classList.toggle('error', isError);
}

// Progress and status text change with every chunk, but reach the page only
// in a frame that also draws the model, once the GPU is idle: a page change
// while a software-rendered GPU is still busy with the last frame made the
// main thread wait for it in the compositor's commit (one 95 ms task in
// nine streamed loads of the dragon, headless chromium with SwiftShader).
let pendingStatus = null;
let pendingProgress = null;  // { downloaded, decoded } fractions
function queueStatus(text, progress) {
  if (text !== undefined) pendingStatus = text;
  if (progress !== undefined) pendingProgress = { ...pendingProgress, ...progress };
  requestRender();
}
function paintStatus() {
  if (pendingStatus !== null) showStatus(pendingStatus);
  if (pendingProgress?.downloaded !== undefined) $('progress').value = pendingProgress.downloaded;
  if (pendingProgress?.decoded !== undefined) $('decoded').value = pendingProgress.decoded;
  pendingStatus = pendingProgress = null;
}

// An attribute's name, with its coding when the stream quantized it.
function describeAttribute(name, { coding, codingBits }) {
  return coding === 'exact' ? name : `${name} (${coding} ${codingBits} bits)`;
}

function describe(stats) {
  const m = stats.model;
  const count = (n) => n.toLocaleString('en-US');
  const of = (total) => (total ? ` of ${count(total)}` : '');
  const kb = (viewer.bytesReceived / 1024).toFixed(0);
  const total = viewer.bytesExpected ? ` of ${(viewer.bytesExpected / 1024).toFixed(0)}` : '';
  const bpv = m && m.vertexCount ? ((8 * m.progress.bytesConsumed) / m.vertexCount).toFixed(1) : '–';
  // Levels past the kd-tree's depth only tell coincident vertices apart:
  // the status counts them as the last.
  const level = viewer.levelCount ? Math.min(viewer.level, viewer.levelCount) : viewer.level;
  return `${kb}${total} KiB · level ${level}${of(viewer.levelCount)} · ${count(viewer.vertexCount)}${of(viewer.vertexTotal)} vertices` +
    (viewer.triangleCount ? ` · ${count(viewer.triangleCount)} triangles` : '') +
    (viewer.tetrahedronCount ? ` · ${count(viewer.tetrahedronCount)} tetrahedra` : '') +
    (viewer.edgeCount ? ` · ${count(viewer.edgeCount)} edges` : '') +
    (viewer.attributes.length ? ` · ${viewer.attributes.map((name) => describeAttribute(name, m.attributes[name])).join(', ')}` : '') +
    (viewer.labelled ? ` · ${count(viewer.labels.length)} labels` : '') +
    ` · ${bpv} bits/vertex${m?.complete ? '' : ' so far'}`;
}

// Starts a load; `load(options)` returns the model's group. Callbacks of a
// load that another has replaced change nothing.
function start(load) {
  controller?.abort();
  if (current) {
    scene.remove(current);
    current.traverse((o) => o.geometry?.dispose());  // the materials are the loader's
  }
  controller = new AbortController();
  framed = false;
  const began = (loadBegan = performance.now());
  Object.assign(viewer, {
    state: 'loading', refinements: 0, error: null, firstRenderMs: null, completeMs: null, finalRenderMs: null, bytesReceived: 0,
    bytesExpected: 0, levelCount: 0, vertexTotal: 0, levelsSeen: [], longTasks: [], attributes: [], streams: 0, streamsComplete: 0,
    labelled: false, labels: [], colouredByLabel: false,
  });
  $('labels-option').hidden = true;
  pendingStatus = pendingProgress = null;
  $('progress').value = $('decoded').value = 0;
  showStatus('loading…');
  let group = null;
  const isCurrent = () => group === current;
  const options = {
    signal: controller.signal,
    isCurrent,
    geomorph: $('geomorph').checked,
    // ?placement=centre draws unfinished vertices at their cells' centres.
    coarsePlacement: params.get('placement') === 'centre' ? 'centre' : 'predicted',
    tetrahedra: $('wireframe').checked ? 'wireframe' : 'boundary',
    onAnimate: requestRender,
    onHeader(header) {
      if (!isCurrent()) return;
      Object.assign(viewer, {
        levelCount: header.depth, vertexTotal: header.vertexCount, labelled: header.labelled, labels: Array.from(header.labels ?? []),
      });
      $('labels-option').hidden = !header.labelled;  // offered only for models with labels
    },
    onProgress(stats) {
      if (!isCurrent()) return;
      // The stream's size from its header, before it the response's Content-Length.
      Object.assign(viewer, { bytesReceived: stats.bytesReceived, bytesExpected: stats.bytesExpected });
      queueStatus(undefined, { downloaded: stats.bytesExpected ? stats.bytesReceived / stats.bytesExpected : 0 });
    },
    onRefine(model, stats) {
      if (!isCurrent()) return;
      const m = stats.model;
      Object.assign(viewer, {
        refinements: stats.refinements, vertexCount: m.vertexCount, triangleCount: m.triangles.length / 3,
        tetrahedronCount: m.tetrahedra.length / 4, edgeCount: m.edges.length / 2, pointCount: m.points.length,
        level: m.progress.level, attributes: Object.keys(m.attributes),
      });
      colourByLabel();
      if (!viewer.levelsSeen.includes(m.progress.level)) viewer.levelsSeen.push(m.progress.level);
      if (!framed) { frame(model); framed = true; }
      if (m.complete) {
        viewer.completeMs = performance.now() - began;
        viewer.state = 'complete';
      }
      queueStatus(describe(stats), {
        decoded: viewer.vertexTotal ? m.vertexCount / viewer.vertexTotal : 0,
        ...(m.complete ? { downloaded: 1 } : {}),
      });
      return paceRefinements(stats);
    },
  };
  group = current = load(options);
  scene.add(current);
  current.userData.loaded.catch((error) => {
    if (!isCurrent()) return;
    pendingStatus = null;
    viewer.state = 'error';
    viewer.error = error.code === 'aborted' ? 'stopped: showing the last level received' : error.message;
    showStatus(viewer.error, error.code !== 'aborted');
  });
}

// .glb and .gltf files are scenes (see loadScene).
const isScene = (name) => /\.(glb|gltf)$/i.test(name.split('?')[0]);

// What the status line says of a scene: its streams and their vertices and
// triangles so far.
function describeScene(group) {
  let vertices = 0, triangles = 0;
  group.traverse((object) => {
    const model = object.geometry?.userData.stats?.model;
    if (model) {
      vertices += model.vertexCount;
      triangles += model.triangles.length / 3;
    }
  });
  Object.assign(viewer, { vertexCount: vertices, triangleCount: triangles });
  const count = (n) => n.toLocaleString('en-US');
  return `${(viewer.bytesReceived / 1024).toFixed(0)} KiB · glTF scene · ${viewer.streamsComplete} of ${viewer.streams} kdmesh streams complete` +
    ` · ${count(vertices)} vertices · ${count(triangles)} triangles`;
}

// A glTF scene through GLTFLoader with kdmesh/gltf, as a group that holds
// the scene once it is built; its compressed primitives refine in place in
// the loader's workers. userData: loaded, stats (refinements, complete).
function loadScene(url, options) {
  const group = new THREE.Group();
  const stats = { refinements: 0, complete: false, model: null };
  const refined = (geometry, geometryStats) => {
    stats.refinements += 1;
    if (geometryStats.complete) viewer.streamsComplete += 1;
    viewer.refinements = stats.refinements;
    if (!framed) { frame(group); framed = true; }
    queueStatus(describeScene(group), { decoded: viewer.streams ? viewer.streamsComplete / viewer.streams : 1 });
  };
  const gltfLoader = new GLTFLoader().register((parser) =>
    new KDMeshGLTFExtension(parser, {
      loader, signal: options.signal,
      onRefine: (geometry, s) => {
        if (!options.isCurrent()) return undefined;
        refined(geometry, s);
        return paceRefinements(s);
      },
    }));
  const loaded = gltfLoader.loadAsync(url, (event) => options.onProgress({ bytesReceived: event.loaded, bytesExpected: event.total }))
    .then(async (gltf) => {
      group.add(gltf.scene);
      viewer.streams = gltf.userData.kdmesh?.streams ?? 0;
      if (!viewer.streams) {
        stats.refinements = viewer.refinements = 1;  // a plain scene is drawn whole
        frame(group);
        framed = true;
      }
      await gltf.userData.kdmesh?.loaded;
      stats.complete = true;
      if (options.isCurrent()) {
        viewer.completeMs = performance.now() - loadBegan;
        viewer.state = 'complete';
        queueStatus(describeScene(group), { downloaded: 1, decoded: 1 });
      }
      return group;
    });
  Object.assign(group.userData, { loaded, stats });
  return group;
}

// A gallery model (by menu value) or a URL, paced by the throttle menu.
function loadUrl(url) {
  const throttle = Number($('throttle').value);
  const full = throttle > 0 ? `${url}${url.includes('?') ? '&' : '?'}throttle=${throttle}` : url;
  viewer.source = url;
  reloadCurrent = () => loadUrl(url);
  start((options) => (isScene(url) ? loadScene : loader.loadProgressive.bind(loader))(full, options));
}

// A file already in the menu (see openFile).
function loadFile(value) {
  const { name, bytes } = files.get(value);
  viewer.source = name;
  reloadCurrent = () => loadFile(value);
  const url = URL.createObjectURL(new Blob([bytes]));
  start((options) => {
    // GLTFLoader tells a .glb from a .gltf by its bytes; a .gltf must hold its buffers (data URIs).
    const group = isScene(name) ? loadScene(url, options) : loader.loadProgressive(url, options);
    group.userData.loaded.finally(() => URL.revokeObjectURL(url)).catch(() => {});
    return group;
  });
}

// What the server's encoder said, for the status line: its first line.
const firstLine = (text) => text.trim().split('\n')[0].slice(0, 300);

// Opens a dropped or picked file: a .kdm as it is, a mesh file encoded by
// the dev server first. The menu then shows it.
async function openFile(file) {
  controller?.abort();
  let bytes = new Uint8Array(await file.arrayBuffer());
  if (!file.name.toLowerCase().endsWith('.kdm') && !isScene(file.name)) {
    Object.assign(viewer, { state: 'encoding', error: null, source: file.name });
    showStatus(`encoding ${file.name} on the server…`);
    let response;
    try {
      response = await fetch(`encode?name=${encodeURIComponent(file.name)}`, { method: 'POST', body: bytes });
    } catch (error) {
      response = { ok: false, text: async () => error.message };
    }
    if (!response.ok) {
      viewer.state = 'error';
      viewer.error = `cannot encode ${file.name}: ${firstLine(await response.text())}`;
      showStatus(viewer.error, true);
      return;
    }
    bytes = new Uint8Array(await response.arrayBuffer());
  }
  const value = `file:${file.name}`;
  if (!files.has(value)) $('model').add(new Option(`${file.name} (file)`, value));
  files.set(value, { name: file.name, bytes });
  $('model').value = value;
  loadFile(value);
}

// Loads what the model menu shows.
function loadSelected() {
  const value = $('model').value;
  if (files.has(value)) loadFile(value);
  else if (value) loadUrl(/^(https?:|\/|\.)/.test(value) ? value : `models/${encodeURIComponent(value)}`);
}

async function gallery() {
  try {
    const response = await fetch('models/');
    return response.ok ? await response.json() : [];
  } catch {
    return [];
  }
}

// The decoder compiles and a worker starts, and shaders compile, before the
// first model streams, not while it does.
loader.preload();
await loader.prepareRenderer(renderer, camera, scene);
const params = new URLSearchParams(location.search);
$('geomorph').checked = params.get('geomorph') === '1';
const throttle = Number(params.get('throttle') ?? 0);
if (![...$('throttle').options].some((o) => o.value === String(throttle)))
  $('throttle').add(new Option(`${throttle} kbit/s`, String(throttle)));
$('throttle').value = String(throttle);
const models = await gallery();
for (const { name, bytes } of models) $('model').add(new Option(`${name} (${(bytes / 1024).toFixed(0)} KiB)`, name));
// A gallery model by its file name, or by its name without .kdm; else a URL.
const asked = params.get('model');
const requested = models.find((m) => m.name === asked || m.name === `${asked}.kdm`)?.name ?? asked ?? models[0]?.name;
if (requested && !models.some((m) => m.name === requested)) $('model').add(new Option(requested, requested));
if (requested) {
  $('model').value = requested;
  loadSelected();
}

$('model').addEventListener('change', loadSelected);
$('throttle').addEventListener('change', () => reloadCurrent?.());
$('stop').addEventListener('click', () => controller?.abort());
$('geomorph').addEventListener('change', () => reloadCurrent?.());
$('wireframe').addEventListener('change', () => reloadCurrent?.());
$('labels').addEventListener('change', colourByLabel);

$('file').addEventListener('change', () => $('file').files[0] && openFile($('file').files[0]));
const view = $('view');
view.addEventListener('dragover', (e) => { e.preventDefault(); view.classList.add('dragging'); });
view.addEventListener('dragleave', () => view.classList.remove('dragging'));
view.addEventListener('drop', (e) => {
  e.preventDefault();
  view.classList.remove('dragging');
  if (e.dataTransfer.files[0]) openFile(e.dataTransfer.files[0]);
});
