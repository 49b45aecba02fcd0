// The kdmesh viewer: streams a .kdm model into three.js and shows it refine.
// Query: ?model=NAME_OR_URL&throttle=KBPS. State for scripts and tests lives
// in window.kdmeshViewer.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { GpuFence, KDMeshLoader } from 'kdmesh/three';
import { modelChecksum } from './model-checksum.js';

const $ = (id) => document.getElementById(id);
const viewer = (window.kdmeshViewer = {
  state: 'idle', refinements: 0, vertexCount: 0, triangleCount: 0, tetrahedronCount: 0, edgeCount: 0,
  pointCount: 0, bytesReceived: 0, bytesExpected: 0, level: 0, error: null, firstRenderMs: null,
  // Since the load began: the first and the last level drawn, and the last
  // level decoded.
  completeMs: null, finalRenderMs: null, levelsSeen: [], longTasks: [],
  // Workers decoding a stream (0 once a load has ended, however).
  activeWorkers: () => loader.busyWorkers,
  // Of the complete model, for tests to compare with a Node decode. Computed
  // when read: hashing the dragon's arrays takes ~60 ms, a long task the
  // page itself has no use for.
  get checksum() {
    return this.state === 'complete' ? modelChecksum(current.userData.stats.model) : null;
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
    renderer.render(scene, camera);
    previousFrame.set();
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

function frame(group) {
  const box = new THREE.Box3().setFromObject(group);
  if (box.isEmpty()) return;
  const sphere = box.getBoundingSphere(new THREE.Sphere());
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
let pendingProgress = null;
function queueStatus(text, progress) {
  if (text !== undefined) pendingStatus = text;
  if (progress !== undefined) pendingProgress = progress;
  requestRender();
}
function paintStatus() {
  if (pendingStatus !== null) showStatus(pendingStatus);
  if (pendingProgress !== null) $('progress').value = pendingProgress;
  pendingStatus = pendingProgress = null;
}

function describe(stats) {
  const m = stats.model;
  const kb = (viewer.bytesReceived / 1024).toFixed(0);
  const total = viewer.bytesExpected ? ` of ${(viewer.bytesExpected / 1024).toFixed(0)}` : '';
  const bpv = m && m.vertexCount ? ((8 * m.progress.bytesConsumed) / m.vertexCount).toFixed(1) : '–';
  return `${kb}${total} KiB · level ${viewer.level} · ${viewer.vertexCount} vertices · ${viewer.triangleCount} triangles` +
    (viewer.tetrahedronCount ? ` · ${viewer.tetrahedronCount} tetrahedra` : '') +
    (viewer.edgeCount ? ` · ${viewer.edgeCount} edges` : '') + ` · ${bpv} bits/vertex so far`;
}

function start(load) {
  controller?.abort();
  if (current) {
    scene.remove(current);
    current.traverse((o) => o.geometry?.dispose());  // the materials are the loader's
  }
  controller = new AbortController();
  framed = false;
  const began = (loadBegan = performance.now());
  Object.assign(viewer, { state: 'loading', refinements: 0, error: null, firstRenderMs: null, completeMs: null, finalRenderMs: null, bytesReceived: 0, levelsSeen: [], longTasks: [] });
  pendingStatus = pendingProgress = null;
  showStatus('loading…');
  const options = {
    signal: controller.signal,
    geomorph: $('geomorph').checked,
    tetrahedra: $('wireframe').checked ? 'wireframe' : 'boundary',
    onAnimate: requestRender,
    onHeader(header) { viewer.bytesExpected = header.totalBytes; },
    onProgress(stats) {
      viewer.bytesReceived = stats.bytesReceived;
      queueStatus(undefined, stats.bytesExpected ? stats.bytesReceived / stats.bytesExpected : 0);
    },
    onRefine(group, stats) {
      const m = stats.model;
      Object.assign(viewer, {
        refinements: stats.refinements, vertexCount: m.vertexCount, triangleCount: m.triangles.length / 3,
        tetrahedronCount: m.tetrahedra.length / 4, edgeCount: m.edges.length / 2, pointCount: m.points.length,
        level: m.progress.level,
      });
      if (!viewer.levelsSeen.includes(m.progress.level)) viewer.levelsSeen.push(m.progress.level);
      if (!framed) { frame(group); framed = true; }
      if (m.complete) {
        viewer.completeMs = performance.now() - began;
        viewer.state = 'complete';
      }
      queueStatus(describe(stats), m.complete ? 1 : undefined);
    },
  };
  current = load(options);
  scene.add(current);
  current.userData.loaded.catch((error) => {
    pendingStatus = null;
    viewer.state = 'error';
    viewer.error = error.code === 'aborted' ? 'stopped: showing the last level received' : error.message;
    showStatus(viewer.error, error.code !== 'aborted');
  });
}

function loadUrl(url, throttle) {
  const full = throttle > 0 ? `${url}${url.includes('?') ? '&' : '?'}throttle=${throttle}` : url;
  start((options) => loader.loadProgressive(full, options));
}

async function loadFile(file) {
  let bytes = new Uint8Array(await file.arrayBuffer());
  if (!file.name.toLowerCase().endsWith('.kdm')) {
    showStatus(`encoding ${file.name} on the server…`);
    const response = await fetch(`encode?name=${encodeURIComponent(file.name)}`, { method: 'POST', body: bytes });
    if (!response.ok) {
      viewer.state = 'error';
      viewer.error = `cannot encode ${file.name}: ${await response.text()}`;
      showStatus(viewer.error, true);
      return;
    }
    bytes = new Uint8Array(await response.arrayBuffer());
  }
  start((options) => {
    const group = loader.loadProgressive(URL.createObjectURL(new Blob([bytes])), options);
    return group;
  });
}

async function gallery() {
  try {
    const response = await fetch('models/');
    return response.ok ? await response.json() : [];
  } catch {
    return [];
  }
}

// Shaders compile before the first model streams, not while it does.
await loader.prepareRenderer(renderer, camera, scene);
const params = new URLSearchParams(location.search);
$('geomorph').checked = params.get('geomorph') === '1';
const throttle = Number(params.get('throttle') ?? 0);
if (![...$('throttle').options].some((o) => o.value === String(throttle)))
  $('throttle').add(new Option(`${throttle} kbit/s`, String(throttle)));
$('throttle').value = String(throttle);
const models = await gallery();
for (const { name, bytes } of models) $('model').add(new Option(`${name} (${(bytes / 1024).toFixed(0)} KiB)`, name));
const requested = params.get('model') ?? models[0]?.name;
if (requested && !models.some((m) => m.name === requested)) $('model').add(new Option(requested, requested));
if (requested) {
  $('model').value = requested;
  loadUrl(/^(https?:|\/|\.)/.test(requested) ? requested : `models/${encodeURIComponent(requested)}`, throttle);
}

$('model').addEventListener('change', () => loadUrl(`models/${encodeURIComponent($('model').value)}`, Number($('throttle').value)));
$('throttle').addEventListener('change', () => $('model').value && loadUrl(`models/${encodeURIComponent($('model').value)}`, Number($('throttle').value)));
$('stop').addEventListener('click', () => controller?.abort());
const reload = () => $('model').value && loadUrl(`models/${encodeURIComponent($('model').value)}`, Number($('throttle').value));
$('geomorph').addEventListener('change', reload);
$('wireframe').addEventListener('change', reload);

$('file').addEventListener('change', () => $('file').files[0] && loadFile($('file').files[0]));
const view = $('view');
view.addEventListener('dragover', (e) => { e.preventDefault(); view.classList.add('dragging'); });
view.addEventListener('dragleave', () => view.classList.remove('dragging'));
view.addEventListener('drop', (e) => {
  e.preventDefault();
  view.classList.remove('dragging');
  if (e.dataTransfer.files[0]) loadFile(e.dataTransfer.files[0]);
});
