// Renders a glTF scene in headless Chromium with three.js and saves a
// screenshot:   node view.mjs <scene.glb|gltf> <screenshot.png>
// A loopback HTTP server serves this folder (the page, node_modules) and the
// scene's folder; the page reports whether the scene loaded. Prints one JSON
// line with the page's report; exits non-zero if the scene did not load.
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { spawn } from 'node:child_process';
import { fileURLToPath } from 'node:url';

import { serveFile } from './static_files.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const [sceneArg, screenshotArg] = process.argv.slice(2);
if (!sceneArg || !screenshotArg) {
  console.error('usage: node view.mjs <scene.glb|gltf> <screenshot.png>');
  process.exit(2);
}
const sceneFile = path.resolve(sceneArg);
const screenshot = path.resolve(screenshotArg);
let pageReport = null;

const server = http.createServer((req, res) => {
  const url = new URL(req.url, 'http://127.0.0.1');
  if (url.pathname === '/report') {
    pageReport = Object.fromEntries(url.searchParams);
    res.end('ok');
    return;
  }
  // /scene/<file> comes from the scene's folder, anything else from here.
  serveFile(res, url.pathname, 'scene', path.dirname(sceneFile), here);
});
await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
const port = server.address().port;
const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'skybake-chromium-'));
const url = `http://127.0.0.1:${port}/view.html?scene=/scene/${encodeURIComponent(path.basename(sceneFile))}`;
const args = ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
              '--disable-background-networking', '--disable-component-update', '--disable-sync',
              '--use-angle=swiftshader', '--enable-unsafe-swiftshader', `--user-data-dir=${profile}`,
              '--window-size=320,240', '--hide-scrollbars', '--virtual-time-budget=20000',
              `--screenshot=${screenshot}`, url];
const chromium = spawn(process.env.CHROMIUM ?? 'chromium', args, { stdio: ['ignore', 'ignore', 'pipe'] });
let stderr = '';
chromium.stderr.on('data', (d) => { stderr += d; });
const timer = setTimeout(() => chromium.kill('SIGKILL'), 90000);
const code = await new Promise((resolve) => chromium.on('close', resolve));
clearTimeout(timer);
server.close();
fs.rmSync(profile, { recursive: true, force: true });
console.log(JSON.stringify({ chromium_exit: code, report: pageReport, screenshot }));
if (!pageReport || pageReport.ok !== '1' || !fs.existsSync(screenshot)) {
  console.error(stderr.split('\n').slice(-20).join('\n'));
  process.exit(1);
}
