// Opens one of this folder's pages in headless Chromium (three.js from
// node_modules, no network) with a folder of bake files served under /bake/,
// and prints the page's report as one JSON line:
//   node run_page.mjs <page.html> <bake folder> [screenshot.png] [query]
// The page reports by POSTing JSON to /report. Exits non-zero when it did
// not report ok.
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { spawn } from 'node:child_process';
import { fileURLToPath } from 'node:url';

import { serveFile } from './static_files.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const [pageArg, bakeArg, screenshotArg, query] = process.argv.slice(2);
if (!pageArg || !bakeArg) {
  console.error('usage: node run_page.mjs <page.html> <bake folder> [screenshot.png] [query]');
  process.exit(2);
}
const bakeDir = path.resolve(bakeArg);
const screenshot = path.resolve(screenshotArg ?? path.join(os.tmpdir(), `skybake-page-${process.pid}.png`));
let pageReport = null;
const requests = [];  // every path the page asked for, in order

const server = http.createServer((req, res) => {
  const url = new URL(req.url, 'http://127.0.0.1');
  requests.push(url.pathname);
  if (url.pathname === '/report' && req.method === 'POST') {
    let body = '';
    req.on('data', (d) => { body += d; });
    req.on('end', () => {
      try { pageReport = JSON.parse(body); } catch (e) { pageReport = { ok: false, error: 'bad report: ' + body }; }
      res.end('ok');
    });
    return;
  }
  serveFile(res, url.pathname, 'bake', bakeDir, here);
});
await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
const port = server.address().port;
const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'skybake-chromium-'));
const url = `http://127.0.0.1:${port}/${pageArg}${query ? '?' + query : ''}`;
const args = ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
              '--disable-background-networking', '--disable-component-update', '--disable-sync',
              '--use-angle=swiftshader', '--enable-unsafe-swiftshader', `--user-data-dir=${profile}`,
              '--window-size=320,240', '--hide-scrollbars', '--virtual-time-budget=60000',
              `--screenshot=${screenshot}`, url];
const chromium = spawn(process.env.CHROMIUM ?? 'chromium', args, { stdio: ['ignore', 'ignore', 'pipe'] });
let stderr = '';
chromium.stderr.on('data', (d) => { stderr += d; });
const timer = setTimeout(() => chromium.kill('SIGKILL'), 180000);
const code = await new Promise((resolve) => chromium.on('close', resolve));
clearTimeout(timer);
server.close();
fs.rmSync(profile, { recursive: true, force: true });
console.log(JSON.stringify({ chromium_exit: code, report: pageReport, screenshot, requests }));
if (!pageReport || pageReport.ok !== true) {
  console.error(stderr.split('\n').slice(-20).join('\n'));
  process.exit(1);
}
