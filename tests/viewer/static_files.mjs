// Serving a test page's files from a local folder: the one piece of HTTP the
// headless-Chromium harnesses (view.mjs, run_page.mjs) share.
import fs from 'node:fs';
import path from 'node:path';

const types = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript',
                '.gltf': 'model/gltf+json', '.glb': 'model/gltf-binary', '.bin': 'application/octet-stream',
                '.png': 'image/png', '.wasm': 'application/wasm', '.usda': 'text/plain' };

// Answers with the file `urlPath` names: below `mountedDir` when it starts
// with `/<mount>/`, else below `defaultDir`; 404 for anything outside them,
// missing or a folder.
export function serveFile(res, urlPath, mount, mountedDir, defaultDir) {
  const prefix = `/${mount}/`;
  const root = urlPath.startsWith(prefix) ? mountedDir : defaultDir;
  const rel = decodeURIComponent(urlPath.startsWith(prefix) ? urlPath.slice(prefix.length - 1) : urlPath);
  const file = path.join(root, path.normalize(rel));
  if (!file.startsWith(root) || !fs.existsSync(file) || fs.statSync(file).isDirectory()) {
    res.statusCode = 404;
    res.end();
    return;
  }
  res.setHeader('Content-Type', types[path.extname(file)] ?? 'application/octet-stream');
  fs.createReadStream(file).pipe(res);
}
