// Reads a KTX2 file with the npm package ktx-parse (an independent reader)
// and prints what it found as JSON: the header, the key/value data, the data
// format descriptor, and each mip level (its data written to PREFIX.levelN,
// after zstd decompression by the zstd command when supercompressed). Also
// writes the container back with ktx-parse and says whether the bytes are
// the same as the file's.
//   node ktx2_dump.mjs file.ktx2 PREFIX
import fs from 'node:fs';
import { execFileSync } from 'node:child_process';
import { read, write } from 'ktx-parse';

const [file, prefix] = process.argv.slice(2);
const bytes = new Uint8Array(fs.readFileSync(file));
const ktx = read(bytes);
const keyValue = {};
for (const [key, value] of Object.entries(ktx.keyValue))
  keyValue[key] = typeof value === 'string' ? value : new TextDecoder().decode(value).replace(/\0$/, '');
const levels = ktx.levels.map((level, i) => {
  let data = level.levelData;
  if (ktx.supercompressionScheme === 2) data = new Uint8Array(execFileSync('zstd', ['-d', '-c', '-q'], { input: data }));
  fs.writeFileSync(`${prefix}.level${i}`, data);
  return { byteLength: level.levelData.byteLength, uncompressedByteLength: level.uncompressedByteLength,
           decodedByteLength: data.byteLength };
});
const rewritten = write(ktx, { keepWriter: true });
console.log(JSON.stringify({
  vkFormat: ktx.vkFormat, typeSize: ktx.typeSize, pixelWidth: ktx.pixelWidth, pixelHeight: ktx.pixelHeight,
  pixelDepth: ktx.pixelDepth, layerCount: ktx.layerCount, faceCount: ktx.faceCount, levelCount: ktx.levelCount,
  supercompressionScheme: ktx.supercompressionScheme, keyValue, dfd: ktx.dataFormatDescriptor, levels,
  rewrittenIdentical: Buffer.compare(Buffer.from(rewritten), Buffer.from(bytes)) === 0,
}));
