// Runs the Khronos glTF-Validator (npm gltf-validator) on every file given
// and fails unless each has 0 errors and 0 warnings.
//   node validate.mjs scene.gltf scene.glb ...
import fs from 'node:fs';
import path from 'node:path';
import validator from 'gltf-validator';

let failed = false;
for (const file of process.argv.slice(2)) {
  const data = new Uint8Array(fs.readFileSync(file));
  const report = await validator.validateBytes(data, {
    uri: path.basename(file),
    maxIssues: 100,
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        const resource = path.resolve(path.dirname(file), decodeURIComponent(uri));
        fs.readFile(resource, (err, bytes) => (err ? reject(err.toString()) : resolve(new Uint8Array(bytes))));
      }),
  });
  const issues = report.issues;
  console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ` +
              `${issues.numInfos} infos, ${issues.numHints} hints`);
  for (const message of issues.messages)
    console.log(`  [${['error', 'warning', 'info', 'hint'][message.severity]}] ${message.code} ` +
                `${message.pointer ?? ''}: ${message.message}`);
  if (issues.numErrors > 0 || issues.numWarnings > 0) failed = true;
}
process.exit(failed ? 1 : 0);
