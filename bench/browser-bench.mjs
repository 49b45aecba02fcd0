// Time to first and final render of the dragon at a simulated 10 Mbit/s in
// headless chromium: kdmesh's progressive viewer against a Draco file of the
// same model loaded with three.js's DRACOLoader (whose first render is its
// full download plus decode), and the same viewer on a stream encoded with
// --fast-decode. Also lists main-thread long tasks.
//
//   node bench/browser-bench.mjs [--throttle KBPS] [--runs N]
//
// With several runs, one row per run and a summary: long tasks are rare
// events, and one clean run says little.
import { execFileSync } from 'node:child_process';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { launchChromium } from '../tests/browser/chromium.mjs';
import { startServer } from '../web/server.mjs';

const root = new URL('..', import.meta.url).pathname;
function option(name, fallback) {
  const at = process.argv.indexOf(name);
  return at > 0 ? Number(process.argv[at + 1]) : fallback;
}
const throttle = option('--throttle', 10000);
const runs = option('--runs', 1);
const models = mkdtempSync(join(tmpdir(), 'kdmesh-browser-bench-'));
process.on('exit', () => rmSync(models, { recursive: true, force: true }));
const dragon = join(root, 'build', 'models', 'dragon_vrip.ply');
// The CLI that bench/run.sh builds alongside the WebAssembly decoder it
// rebuilds: build/'s may be older, and its streams of another format version.
execFileSync(join(root, 'build-bench', 'kdmesh'), ['encode', dragon, '-o', join(models, 'dragon.kdm'), '--bits', '12', '-q']);
execFileSync(join(root, 'build-bench', 'kdmesh'),
  ['encode', dragon, '-o', join(models, 'dragon-fast.kdm'), '--bits', '12', '--fast-decode', '-q']);
execFileSync('draco_encoder', ['-i', dragon, '-o', join(models, 'dragon.drc'), '-qp', '12', '-cl', '10'], { stdio: 'ignore' });

const server = await startServer({ port: 0, root: models, host: '127.0.0.1' });
const base = `http://127.0.0.1:${server.address().port}`;
const browser = await launchChromium();

async function run(url, done, read) {
  const page = await browser.newPage({ viewport: { width: 800, height: 600 } });
  await page.goto(url, { waitUntil: 'domcontentloaded' });
  await page.waitForFunction(done, null, { timeout: 300000 });
  const result = await page.evaluate(read);
  await page.close();
  return result;
}

const ms = (v) => (v === null ? '–' : `${(v / 1000).toFixed(2)} s`);
const row = (name, first, final, refinements, tasks) =>
  `| ${name} | ${ms(first)} | ${ms(final)} | ${refinements} | ${Math.max(0, ...tasks)} ms | ${tasks.length} |`;
console.log(`| dragon at ${throttle / 1000} Mbit/s | first render | final render | refinements | longest main-thread task | long tasks (> 50 ms) |`);
console.log('|---|---:|---:|---:|---:|---:|');
const all = { kdmesh: [], fast: [], draco: [] };
const viewer = (model) => run(`${base}/?model=${model}&throttle=${throttle}`,
  () => window.kdmeshViewer.state === 'error' || window.kdmeshViewer.finalRenderMs !== null,
  () => ({ ...window.kdmeshViewer }));
for (let i = 1; i <= runs; ++i) {
  const kdmesh = await viewer('dragon.kdm');
  const fast = await viewer('dragon-fast.kdm');
  const draco = await run(`${base}/draco-bench.html?model=models/dragon.drc%3Fthrottle%3D${throttle}`,
    () => window.dracoBench.state === 'complete',
    () => ({ ...window.dracoBench }));
  const run_ = runs > 1 ? `, run ${i}` : '';
  console.log(row(`kdmesh (.kdm, progressive)${run_}`, kdmesh.firstRenderMs, kdmesh.finalRenderMs, kdmesh.refinements, kdmesh.longTasks));
  console.log(row(`kdmesh --fast-decode${run_}`, fast.firstRenderMs, fast.finalRenderMs, fast.refinements, fast.longTasks));
  console.log(row(`three.js DRACOLoader (.drc -cl 10)${run_}`, draco.renderMs, draco.renderMs, 1, draco.longTasks));
  all.kdmesh.push(kdmesh);
  all.fast.push(fast);
  all.draco.push(draco);
}
await browser.close();
server.close();

if (runs > 1) {
  const median = (values) => values.sort((a, b) => a - b)[values.length >> 1];
  const summary = (name, results, first, final) => {
    const withTasks = results.filter((r) => r.longTasks.length > 0).length;
    const longest = Math.max(0, ...results.flatMap((r) => r.longTasks));
    console.log(`${name}: first render median ${ms(median(results.map(first)))}, final render median ` +
      `${ms(median(results.map(final)))}; runs with a main-thread task over 50 ms: ${withTasks} of ${results.length}` +
      ` (longest ${longest} ms)`);
  };
  summary('kdmesh', all.kdmesh, (r) => r.firstRenderMs, (r) => r.finalRenderMs);
  summary('kdmesh --fast-decode', all.fast, (r) => r.firstRenderMs, (r) => r.finalRenderMs);
  summary('DRACOLoader', all.draco, (r) => r.renderMs, (r) => r.renderMs);
}
