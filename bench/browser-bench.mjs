// Time to first and final render of the dragon at a simulated 10 Mbit/s in
// headless chromium: kdmesh's progressive viewer against a Draco file of the
// same model loaded with three.js's DRACOLoader (whose first render is its
// full download plus decode). Also lists main-thread long tasks.
//
//   node bench/browser-bench.mjs [--throttle KBPS]
import { execFileSync } from 'node:child_process';
import { mkdtempSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { chromium } from 'playwright-core';
import { startServer } from '../web/server.mjs';

const root = new URL('..', import.meta.url).pathname;
const throttleAt = process.argv.indexOf('--throttle');
const throttle = throttleAt > 0 ? Number(process.argv[throttleAt + 1]) : 10000;
const models = mkdtempSync(join(tmpdir(), 'kdmesh-browser-bench-'));
const dragon = join(root, 'build', 'models', 'dragon_vrip.ply');
execFileSync(join(root, 'build', 'kdmesh'), ['encode', dragon, '-o', join(models, 'dragon.kdm'), '--bits', '12', '-q']);
execFileSync('draco_encoder', ['-i', dragon, '-o', join(models, 'dragon.drc'), '-qp', '12', '-cl', '10'], { stdio: 'ignore' });

const server = await startServer({ port: 0, root: models, host: '127.0.0.1' });
const base = `http://127.0.0.1:${server.address().port}`;
const browser = await chromium.launch({
  executablePath: '/usr/bin/chromium', headless: true,
  args: ['--no-sandbox', '--disable-background-networking', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});

async function run(url, done, read) {
  const page = await browser.newPage({ viewport: { width: 800, height: 600 } });
  await page.goto(url, { waitUntil: 'domcontentloaded' });
  await page.waitForFunction(done, null, { timeout: 300000 });
  const result = await page.evaluate(read);
  await page.close();
  return result;
}

const kdmesh = await run(`${base}/?model=dragon.kdm&throttle=${throttle}`,
  () => window.kdmeshViewer.state === 'error' || window.kdmeshViewer.finalRenderMs !== null,
  () => ({ ...window.kdmeshViewer }));
const draco = await run(`${base}/draco-bench.html?model=models/dragon.drc%3Fthrottle%3D${throttle}`,
  () => window.dracoBench.state === 'complete',
  () => ({ ...window.dracoBench }));
await browser.close();
server.close();

const ms = (v) => (v === null ? '–' : `${(v / 1000).toFixed(2)} s`);
console.log(`| dragon at ${throttle / 1000} Mbit/s | first render | final render | refinements | longest main-thread task | long tasks (> 50 ms) |`);
console.log('|---|---:|---:|---:|---:|---:|');
console.log(`| kdmesh (.kdm, progressive) | ${ms(kdmesh.firstRenderMs)} | ${ms(kdmesh.finalRenderMs)} | ${kdmesh.refinements} | ` +
  `${Math.max(0, ...kdmesh.longTasks)} ms | ${kdmesh.longTasks.length} |`);
console.log(`| three.js DRACOLoader (.drc -cl 10) | ${ms(draco.renderMs)} | ${ms(draco.renderMs)} | 1 | ` +
  `${Math.max(0, ...draco.longTasks)} ms | ${draco.longTasks.length} |`);
