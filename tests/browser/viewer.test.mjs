// The viewer in a real browser: Debian's chromium, headless, WebGL through
// SwiftShader, driven by playwright-core. Run with `node --test tests/browser/`.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { serveAndLaunch } from './chromium.mjs';
import { decode } from 'kdmesh';
import { modelChecksum } from '../../web/model-checksum.js';
import { root, cli, colouredTorus, labelledTorus, writeLabelledPly, writePly } from '../js/fixtures.mjs';
import { writeTestScene } from '../js/gltf-fixtures.mjs';

const models = mkdtempSync(join(tmpdir(), 'kdmesh-browser-'));
const screenshots = join(root, 'build', 'screenshots');
let served, browser, base;

before(async () => {
  execFileSync(cli, ['encode', join(root, 'build', 'models', 'dragon_vrip.ply'), '-o', join(models, 'dragon.kdm'), '--bits', '12', '-q']);
  const bytes = readFileSync(join(models, 'dragon.kdm'));
  const corrupt = Uint8Array.from(bytes);
  corrupt[bytes.length >> 1] ^= 0x5a;
  writeFileSync(join(models, 'corrupt.kdm'), corrupt);
  // A 20 KB point cloud in chunks of at most 2 KiB (11 chunks, each a
  // possible refinement; the default 16 KiB would make 5, and the page draws
  // at most one level per frame), and one in the default chunks.
  execFileSync(cli, ['encode', join(root, 'build', 'models', 'fandisk.off'), '-o', join(models, 'small.kdm'), '--bits', '14', '--points-only', '--chunk-bytes', '2048', '-q']);
  execFileSync(cli, ['encode', join(root, 'build', 'models', 'fandisk.off'), '-o', join(models, 'points.kdm'), '--bits', '12', '--points-only', '-q']);
  // A torus with vertex colours, red on one side and blue on the other.
  writePly(join(models, 'coloured.ply'), colouredTorus());
  execFileSync(cli, ['encode', join(models, 'coloured.ply'), '-o', join(models, 'coloured.kdm'), '--bits', '12', '-q']);
  execFileSync(cli, ['encode', join(models, 'coloured.ply'), '-o', join(models, 'quantized.kdm'), '--bits', '12', '--attr-bits', '12',
    '--normal-bits', '10', '-q']);
  // A torus whose triangles carry four labels, one per quarter.
  writeLabelledPly(join(models, 'labelled.ply'), labelledTorus());
  execFileSync(cli, ['encode', join(models, 'labelled.ply'), '-o', join(models, 'labelled.kdm'), '--bits', '12', '-q']);
  // A glTF scene whose torus, line loop and point cloud are kdmesh streams.
  writeTestScene(join(models, 'input-scene.glb'));
  execFileSync(cli, ['encode', join(models, 'input-scene.glb'), '-o', join(models, 'scene.kdm.glb'), '-q']);
  execFileSync('mkdir', ['-p', screenshots]);
  served = await serveAndLaunch(models);
  ({ base, browser } = served);
});

after(async () => {
  await served?.close();
  rmSync(models, { recursive: true, force: true });
});

async function openViewer(query, viewport = { width: 800, height: 600 }) {
  const page = await browser.newPage({ viewport });
  const errors = [];
  page.on('pageerror', (error) => errors.push(error.message));
  await page.goto(`${base}/?${query}`, { waitUntil: 'domcontentloaded' });
  return { page, errors };
}

const viewerState = (page) => page.evaluate(() => ({ ...window.kdmeshViewer }));

test('the dragon streams through a throttled route, refines at least 5 times and ends exact', async () => {
  const { page, errors } = await openViewer('model=dragon.kdm&throttle=500');
  await page.waitForFunction(() => window.kdmeshViewer.refinements >= 2 && window.kdmeshViewer.state === 'loading', null, { timeout: 60000 });
  const early = await page.evaluate(() => window.kdmeshViewer.modelPixels());
  await page.screenshot({ path: join(screenshots, 'dragon-streaming.png') });
  await page.waitForFunction(() => window.kdmeshViewer.state !== 'loading', null, { timeout: 120000 });
  const state = await viewerState(page);
  assert.equal(state.state, 'complete', state.error ?? '');
  const final = await page.evaluate(() => window.kdmeshViewer.modelPixels());
  await page.screenshot({ path: join(screenshots, 'dragon-complete.png') });
  assert.ok(state.levelsSeen.length >= 5, `levels seen: ${state.levelsSeen}`);
  assert.ok(early > 500, `mid-stream model pixels: ${early}`);
  assert.ok(final > 5000, `final model pixels: ${final}`);
  assert.notEqual(final, early);
  assert.equal(await page.evaluate(() => window.kdmeshViewer.pixelsDifferingFromFreshUpload()), 0);

  const expected = await decode(readFileSync(join(models, 'dragon.kdm')));
  assert.equal(state.vertexCount, expected.vertexCount);
  assert.equal(state.triangleCount, expected.triangles.length / 3);
  assert.equal(state.checksum, modelChecksum(expected));
  assert.deepEqual(errors, []);
  await page.close();
});

test('a corrupted file shows a readable error, keeps the last good level and throws nothing uncaught', async () => {
  const { page, errors } = await openViewer('model=corrupt.kdm');
  await page.waitForFunction(() => window.kdmeshViewer.state === 'error', null, { timeout: 60000 });
  const status = await page.textContent('#status');
  assert.match(status, /checksum|corrupt|undecodable/i);
  // The levels decoded before the corrupt chunk stay on screen.
  const state = await viewerState(page);
  assert.ok(state.vertexCount > 0, 'a coarse model was shown before the error');
  assert.ok(await page.evaluate(() => window.kdmeshViewer.modelPixels()) > 100);
  assert.equal(await page.evaluate(() => window.kdmeshViewer.activeWorkers()), 0, 'the worker is freed');
  assert.deepEqual(errors, []);
  await page.close();
});

test('stopping mid-stream keeps the coarse model on screen, and loading again works', async () => {
  const { page, errors } = await openViewer('model=dragon.kdm&throttle=400');
  await page.waitForFunction(() => window.kdmeshViewer.refinements >= 1, null, { timeout: 60000 });
  await page.click('#stop');
  await page.waitForFunction(() => window.kdmeshViewer.state === 'error', null, { timeout: 10000 });
  const state = await viewerState(page);
  assert.match(state.error, /stopped/);
  assert.ok(state.vertexCount > 0);
  assert.equal(await page.evaluate(() => window.kdmeshViewer.activeWorkers()), 0, 'the worker is freed');
  const pixels = await page.evaluate(() => window.kdmeshViewer.modelPixels());
  assert.ok(pixels > 100, `pixels after stopping: ${pixels}`);
  await page.screenshot({ path: join(screenshots, 'dragon-stopped.png') });
  // Retry: the same model again, unthrottled, completes.
  await page.selectOption('#throttle', '0');
  await page.waitForFunction(() => window.kdmeshViewer.state === 'complete', null, { timeout: 120000 });
  assert.deepEqual(errors, []);
  await page.close();
});

test('geomorphs animate refinements and end exactly on the model', async () => {
  execFileSync(cli, ['encode', join(root, 'build', 'models', 'ball10k.1.ele'), '-o', join(models, 'ball.kdm'), '--bits', '16', '-q']);
  const { page, errors } = await openViewer('model=ball.kdm&throttle=300&geomorph=1');
  await page.waitForFunction(() => window.kdmeshViewer.refinements >= 2, null, { timeout: 60000 });
  await page.waitForFunction(() => window.kdmeshViewer.state === 'complete', null, { timeout: 60000 });
  await page.waitForFunction(() => window.kdmeshViewer.drawnPositionsMatch(), null, { timeout: 10000 });
  const state = await viewerState(page);
  assert.ok(state.refinements >= 3, `refinements: ${state.refinements}`);
  assert.deepEqual(errors, []);
  await page.close();
});

// Its five chunks (1, 2, 4 and 8 KiB, then the rest) arrive at least 160 ms
// apart at 100 kbit/s, so each is a refinement even on a loaded machine.
test('a 20 KB point cloud at 100 kbit/s refines at least 5 times; ?model= takes a name without .kdm; the status ends with totals', async () => {
  const { page, errors } = await openViewer('model=small&throttle=100');
  await page.waitForFunction(() => ['complete', 'error'].includes(window.kdmeshViewer.state), null, { timeout: 60000 });
  const state = await viewerState(page);
  assert.equal(state.state, 'complete', state.error ?? '');
  assert.equal(state.source, 'models/small.kdm');
  assert.ok(state.bytesExpected > 19000 && state.bytesExpected < 22000, `bytes: ${state.bytesExpected}`);
  assert.ok(state.refinements >= 5, `refinements: ${state.refinements}`);
  assert.ok(state.levelsSeen.length >= 5, `levels: ${state.levelsSeen}`);
  assert.equal(state.level, state.levelCount);
  assert.equal(state.vertexCount, state.vertexTotal);
  // The status line is written at the next animation frame after the state.
  await page.waitForFunction(() => !document.getElementById('status').textContent.includes('so far'), null,
                             { timeout: 10000 }).catch(() => {});
  const status = await page.textContent('#status');
  assert.match(status, new RegExp(`level ${state.levelCount} of ${state.levelCount} · ([\\d,]+) of \\1 vertices`), status);
  assert.doesNotMatch(status, /so far/);
  assert.deepEqual(await page.evaluate(() => [document.getElementById('progress').value, document.getElementById('decoded').value]), [1, 1]);
  assert.deepEqual(errors, []);
  await page.close();
});

test('switching models mid-load: the new model loads and completes, the old one is stopped quietly', async () => {
  const { page, errors } = await openViewer('model=dragon.kdm&throttle=400');
  await page.waitForFunction(() => window.kdmeshViewer.refinements >= 1, null, { timeout: 60000 });
  const loading = await page.evaluate(() => window.kdmeshViewer.state);
  await page.selectOption('#model', 'small.kdm');
  await page.waitForFunction(() => ['complete', 'error'].includes(window.kdmeshViewer.state), null, { timeout: 60000 });
  // Long enough for the dragon's rejection to have arrived.
  await page.waitForTimeout(500);
  const state = await viewerState(page);
  assert.equal(loading, 'loading');
  assert.equal(state.state, 'complete', state.error ?? '');
  assert.equal(state.error, null);
  assert.equal(state.source, 'models/small.kdm');
  assert.equal(await page.evaluate(() => window.kdmeshViewer.activeWorkers()), 0);
  assert.deepEqual(errors, []);
  await page.close();
});

test('an opened mesh file: encoding state, the menu shows it, toggles reload it; a bad file gives a clean message', async () => {
  const { page, errors } = await openViewer('model=points.kdm');
  await page.waitForFunction(() => window.kdmeshViewer.state === 'complete', null, { timeout: 60000 });
  // Slow the encoder down so that its state can be seen.
  await page.route('**/encode?*', async (route) => {
    await new Promise((resolve) => setTimeout(resolve, 700));
    await route.continue();
  });
  const obj = readFileSync(join(root, 'build', 'models', 'triceratops.off'), 'utf8');
  await page.setInputFiles('#file', { name: 'triceratops.off', mimeType: 'application/octet-stream', buffer: Buffer.from(obj) });
  await page.waitForFunction(() => window.kdmeshViewer.state === 'encoding', null, { timeout: 10000 });
  assert.match(await page.textContent('#status'), /encoding triceratops\.off/);
  await page.waitForFunction(() => window.kdmeshViewer.state === 'complete', null, { timeout: 60000 });
  const opened = await viewerState(page);
  assert.equal(opened.source, 'triceratops.off');
  assert.equal(opened.triangleCount, 5660);
  assert.equal(await page.$eval('#model', (select) => select.selectedOptions[0].textContent), 'triceratops.off (file)');
  // A toggle reloads the file, not the gallery model. A load starts with a
  // fresh levelsSeen array, so a mark on the old one tells the reload has
  // begun however fast it completes.
  await page.evaluate(() => { window.kdmeshViewer.levelsSeen.beforeToggle = true; });
  await page.click('#geomorph');
  await page.waitForFunction(() => !window.kdmeshViewer.levelsSeen.beforeToggle && window.kdmeshViewer.state === 'complete',
                             null, { timeout: 60000 });
  const toggled = await viewerState(page);
  assert.equal(toggled.source, 'triceratops.off');
  assert.equal(toggled.triangleCount, 5660);

  const garbage = Buffer.from([0x70, 0x6c, 0x79, 0x0a, 0xff, 0xfe, 0x00, 0x01, 0x9c, 0x0a]);
  await page.setInputFiles('#file', { name: 'broken.ply', mimeType: 'application/octet-stream', buffer: garbage });
  await page.waitForFunction(() => window.kdmeshViewer.state === 'error', null, { timeout: 20000 });
  const status = await page.textContent('#status');
  assert.match(status, /^cannot encode broken\.ply: broken\.ply: /);
  assert.doesNotMatch(status, /\/tmp|kdmesh-encode|input\.ply|kdmesh: error/);
  assert.doesNotMatch(status, /[\x00-\x1f\x7f-\x9f\ufffd]/);
  assert.deepEqual(errors, []);
  await page.close();
});

test('the header stays on one line at 1000 px, and the point cloud is shaded, not a flat silhouette', async () => {
  const { page, errors } = await openViewer('model=points', { width: 1000, height: 700 });
  await page.waitForFunction(() => window.kdmeshViewer.state === 'complete', null, { timeout: 60000 });
  // Tops of the header's items shown (the label option is hidden for models without labels).
  const tops = () => page.$$eval('header > *', (children) => children.filter((child) => child.getClientRects().length)
    .map((child) => Math.round(child.getBoundingClientRect().top)));
  const points = await tops();
  assert.ok(Math.max(...points) - Math.min(...points) <= 6, `tops of the header's items: ${points}`);
  assert.equal(await page.$eval('#file', (input) => input.accept.split(',').includes('.xyz')), true);
  const share = await page.evaluate(() => window.kdmeshViewer.commonestColourShare());
  await page.screenshot({ path: join(screenshots, 'points.png') });
  assert.ok(share > 0 && share < 0.2, `share of the commonest colour: ${share}`);
  // With the label option shown too.
  await page.selectOption('#model', 'labelled.kdm');
  await page.waitForFunction(() => window.kdmeshViewer.state === 'complete' && window.kdmeshViewer.labelled, null, { timeout: 60000 });
  const labelled = await tops();
  assert.equal(labelled.length, points.length + 1);
  assert.ok(Math.max(...labelled) - Math.min(...labelled) <= 6, `tops of the header's items: ${labelled}`);
  assert.deepEqual(errors, []);
  await page.close();
});

test('a model with vertex colours shows them, and the status names its attributes', async () => {
  const { page, errors } = await openViewer('model=coloured');
  await page.waitForFunction(() => window.kdmeshViewer.state === 'complete', null, { timeout: 60000 });
  const state = await viewerState(page);
  const vivid = await page.evaluate(() => window.kdmeshViewer.vividPixels());
  await page.screenshot({ path: join(screenshots, 'coloured.png') });
  assert.deepEqual(state.attributes, ['color', 'normal', 'uv', 'label']);
  assert.match(await page.$eval('#status', (status) => status.textContent), /· color, normal, uv, label ·/);
  assert.ok(vivid.red > 500 && vivid.blue > 500, `vivid pixels: ${JSON.stringify(vivid)}`);
  assert.deepEqual(errors, []);
  await page.close();
});

test('a glTF scene from the gallery and from the file picker: its streams complete and it is drawn', async () => {
  const { page, errors } = await openViewer('model=scene.kdm.glb&throttle=2000');
  await page.waitForFunction(() => window.kdmeshViewer.state === 'complete', null, { timeout: 60000 });
  const state = await viewerState(page);
  assert.equal(state.streams, 3);
  assert.equal(state.streamsComplete, 3);
  assert.ok(state.refinements >= 3, `refinements: ${state.refinements}`);
  assert.equal(state.vertexCount, 24 * 40 + 16 + 300);
  assert.ok(await page.evaluate(() => window.kdmeshViewer.modelPixels()) > 1000);
  assert.match(await page.textContent('#status'), /3 of 3 kdmesh streams complete/);
  const gallery = await page.$$eval('#model option', (options) => options.map((o) => o.value));
  assert.ok(gallery.includes('scene.kdm.glb') && gallery.includes('input-scene.glb'));
  // The same scene opened as a file: not sent to the encoder.
  await page.route('**/encode?*', (route) => route.abort());
  await page.setInputFiles('#file', { name: 'picked.kdm.glb', mimeType: 'model/gltf-binary', buffer: readFileSync(join(models, 'scene.kdm.glb')) });
  await page.waitForFunction(() => window.kdmeshViewer.source === 'picked.kdm.glb' && window.kdmeshViewer.state === 'complete', null, { timeout: 60000 });
  assert.equal((await viewerState(page)).streamsComplete, 3);
  assert.deepEqual(errors, []);
  await page.close();
});

test('a labelled model offers colouring by label, which draws the label groups in palette colours', async () => {
  // Pixels of the canvas's last frame whose red exceeds their blue by more
  // than 40: the default surface is grey-blue, the palette's second and
  // third colours are orange and red.
  const warmPixels = (page) => page.evaluate(async () => {
    await new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve)));
    const view = document.querySelector('#view canvas');
    const canvas = document.createElement('canvas');
    canvas.width = view.width;
    canvas.height = view.height;
    const context = canvas.getContext('2d');
    context.drawImage(view, 0, 0);
    const data = context.getImageData(0, 0, canvas.width, canvas.height).data;
    let count = 0;
    for (let i = 0; i < data.length; i += 4) if (data[i] > data[i + 2] + 40) ++count;
    return count;
  });
  const { page, errors } = await openViewer('model=coloured.kdm');
  await page.waitForFunction(() => window.kdmeshViewer.state === 'complete', null, { timeout: 60000 });
  assert.equal(await page.isVisible('#labels'), false, 'no label option for a model without labels');
  await page.selectOption('#model', 'labelled.kdm');
  await page.waitForFunction(() => window.kdmeshViewer.state === 'complete' && window.kdmeshViewer.source.includes('labelled'), null,
    { timeout: 60000 });
  assert.equal(await page.isVisible('#labels'), true);
  let state = await viewerState(page);
  assert.deepEqual({ labelled: state.labelled, labels: state.labels, coloured: state.colouredByLabel },
    { labelled: true, labels: [-1, 10, 20, 30], coloured: false });
  // The status line is written at the next animation frame after the state.
  await page.waitForFunction(() => / · 4 labels · .* bits\/vertex$/.test(document.getElementById('status').textContent), null,
    { timeout: 10000 });
  const plain = await warmPixels(page);
  await page.click('#labels');
  await page.waitForFunction(() => window.kdmeshViewer.colouredByLabel);
  const coloured = await warmPixels(page);
  await page.screenshot({ path: join(screenshots, 'labelled-torus.png') });
  await page.click('#labels');
  await page.waitForFunction(() => !window.kdmeshViewer.colouredByLabel);
  const again = await warmPixels(page);
  assert.ok(plain < 50 && again < 50, `warm pixels without label colours: ${plain}, ${again}`);
  assert.ok(coloured > 2000, `warm pixels with label colours: ${coloured}`);
  // Loading again with the toggle on colours every level as it arrives.
  await page.click('#labels');
  await page.selectOption('#throttle', '256');
  await page.waitForFunction(() => window.kdmeshViewer.state === 'complete', null, { timeout: 60000 });
  state = await viewerState(page);
  assert.equal(state.colouredByLabel, true);
  assert.ok(await warmPixels(page) > 2000);
  assert.deepEqual(errors, []);
  await page.close();
});

test('the status line says how quantized attributes are coded', async () => {
  const { page, errors } = await openViewer('model=quantized.kdm');
  await page.waitForFunction(() => window.kdmeshViewer.state === 'complete', null, { timeout: 60000 });
  await page.waitForFunction(() => !document.getElementById('status').textContent.includes('so far'), null, { timeout: 10000 });
  assert.match(await page.textContent('#status'), / · color, normal \(geometric-octahedral 10 bits\), uv \(uniform 12 bits\), label · /);
  assert.deepEqual(errors, []);
  await page.close();
});
