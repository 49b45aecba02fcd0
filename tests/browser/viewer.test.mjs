// The viewer in a real browser: Debian's chromium, headless, WebGL through
// SwiftShader, driven by playwright-core. Run with `node --test tests/browser/`.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { chromium } from 'playwright-core';
import { decode } from 'kdmesh';
import { startServer } from '../../web/server.mjs';
import { modelChecksum } from '../../web/model-checksum.js';
import { root, cli } from '../js/fixtures.mjs';

const models = mkdtempSync(join(tmpdir(), 'kdmesh-browser-'));
const screenshots = join(root, 'build', 'screenshots');
let server, browser, base;

before(async () => {
  execFileSync(cli, ['encode', join(root, 'build', 'models', 'dragon_vrip.ply'), '-o', join(models, 'dragon.kdm'), '--bits', '12', '-q']);
  const bytes = readFileSync(join(models, 'dragon.kdm'));
  const corrupt = Uint8Array.from(bytes);
  corrupt[bytes.length >> 1] ^= 0x5a;
  writeFileSync(join(models, 'corrupt.kdm'), corrupt);
  execFileSync('mkdir', ['-p', screenshots]);
  server = await startServer({ port: 0, root: models, host: '127.0.0.1' });
  base = `http://127.0.0.1:${server.address().port}`;
  browser = await chromium.launch({
    executablePath: '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--disable-background-networking', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
});

after(async () => {
  await browser?.close();
  server?.close();
});

async function openViewer(query) {
  const page = await browser.newPage({ viewport: { width: 800, height: 600 } });
  const errors = [];
  page.on('pageerror', (error) => errors.push(error.message));
  await page.goto(`${base}/?${query}`, { waitUntil: 'domcontentloaded' });
  return { page, errors };
}

const viewerState = (page) => page.evaluate(() => ({ ...window.kdmeshViewer }));

test('the dragon streams through a throttled route, refines at least 5 times and ends exact', async () => {
  const { page, errors } = await openViewer('model=dragon.kdm&throttle=2000');
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
