// Headless chromium as the browser tests and benchmarks run it: Debian's
// build, WebGL through SwiftShader, no background traffic.
import { chromium } from 'playwright-core';
import { startServer } from '../../web/server.mjs';

export function launchChromium() {
  return chromium.launch({
    executablePath: '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--disable-background-networking', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  });
}

// A page served at `${base}/${name}` with `html` as its body (the server
// serves the models and the package beside it); resolves once the page sets
// window.ready. `errors` collects uncaught page errors.
export async function openTestPage(browser, base, name, html) {
  const page = await browser.newPage();
  const errors = [];
  page.on('pageerror', (error) => errors.push(error.message));
  await page.route(`${base}/${name}`, (route) => route.fulfill({ body: html, contentType: 'text/html' }));
  await page.goto(`${base}/${name}`);
  await page.waitForFunction(() => window.ready);
  return { page, errors };
}

// The dev server on a free local port serving `root` (a test's models), and
// a browser: { base, browser, close() }, close() ending both.
export async function serveAndLaunch(root) {
  const server = await startServer({ port: 0, root, host: '127.0.0.1' });
  try {
    const browser = await launchChromium();
    const close = async () => {
      await browser.close();
      server.close();
    };
    return { base: `http://127.0.0.1:${server.address().port}`, browser, close };
  } catch (error) {
    server.close();
    throw error;
  }
}
