// Pictures of the dragon's early levels as the viewer draws them, with the
// vertices of unfinished cells on their neighbours' planes (the default) and
// at their cells' centres: each prefix of the stream (the whole chunks of its
// first N bytes) is served as a file of its own, loaded in headless chromium,
// and the view is captured once the viewer has drawn its last level.
//
//   node bench/coarse-levels.mjs [--out DIR] [BYTES...]   (default 8000 16000 50000)
//
// Writes DIR/dragon-BYTES-predicted.jpg and DIR/dragon-BYTES-centre.jpg
// (DIR: build-bench/coarse-levels; 640 × 480, JPEG quality 85).
import { execFileSync } from 'node:child_process';
import { mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { launchChromium } from '../tests/browser/chromium.mjs';
import { startServer } from '../web/server.mjs';

const root = new URL('..', import.meta.url).pathname;
const args = process.argv.slice(2);
const outAt = args.indexOf('--out');
const out = outAt >= 0 ? args.splice(outAt, 2)[1] : join(root, 'build-bench', 'coarse-levels');
const prefixes = args.length ? args.map(Number) : [8000, 16000, 50000];
mkdirSync(out, { recursive: true });

const models = mkdtempSync(join(tmpdir(), 'kdmesh-coarse-levels-'));
process.on('exit', () => rmSync(models, { recursive: true, force: true }));
const stream = join(models, 'dragon.kdm');
execFileSync(join(root, 'build', 'kdmesh'),
             ['encode', join(root, 'build', 'models', 'dragon_vrip.ply'), '-o', stream, '--bits', '12', '-q']);
const bytes = readFileSync(stream);
for (const size of prefixes) writeFileSync(join(models, `dragon-${size}.kdm`), bytes.subarray(0, size));

const server = await startServer({ port: 0, root: models, host: '127.0.0.1' });
const base = `http://127.0.0.1:${server.address().port}`;
const browser = await launchChromium();
try {
  for (const size of prefixes) {
    for (const placement of ['predicted', 'centre']) {
      const page = await browser.newPage({ viewport: { width: 640, height: 540 } });
      await page.goto(`${base}/?model=dragon-${size}.kdm&placement=${placement}`, { waitUntil: 'domcontentloaded' });
      // A prefix ends mid-stream: the viewer reports the truncation and keeps
      // the last whole level on screen.
      await page.waitForFunction(() => ['complete', 'error'].includes(window.kdmeshViewer.state) &&
                                       window.kdmeshViewer.refinements > 0, null, { timeout: 120000 });
      await page.waitForTimeout(1500);  // the last level's frame
      const { vertexCount, triangleCount } = await page.evaluate(() => ({ ...window.kdmeshViewer }));
      const file = join(out, `dragon-${size}-${placement}.jpg`);
      await (await page.$('#view')).screenshot({ path: file, type: 'jpeg', quality: 85 });
      console.log(`${file}: ${size} bytes, ${vertexCount} vertices, ${triangleCount} triangles`);
      await page.close();
    }
  }
} finally {
  await browser.close();
  server.close();
}
