// Loads a skybake KTX2 cube map (sky_specular.ktx2, sky_irradiance.ktx2)
// into three.js as a cube texture with every mip level the file holds.
// Tested with three.js 0.170 (tests/e2e/engine_threejs_test.cc); copy it into
// your project.
//
//   import { loadSkybakeKtx2Cube } from './threejs_ktx2_cube.js';
//   const cube = await loadSkybakeKtx2Cube('sky_specular.ktx2');
//   scene.background = cube;                  // level 0 (roughness 0)
//   // your own shader: textureLod(envMap, vec3(-dir.x, dir.yz), roughness * (levels - 1))
//
// Why not KTX2Loader: three.js's KTX2Loader (0.170, and 0.187) makes a cube
// only of Basis Universal files; an uncompressed file becomes a 2D
// DataTexture holding the six faces one after the other, whatever its
// faceCount, and B10G11R11 or E5B9G9R9 files are refused ("Unsupported
// vkFormat"). The files are as the KTX 2.0 specification has them; this
// reads them with the same KTX2 parser and zstd decoder three.js ships.
//
// What it does:
// - every format skybake writes (rgba16f, b10g11r11, e5b9g9r9; zstd or not)
//   becomes RGBA half floats: the packed formats' values are all exactly
//   half floats (5-bit exponents of bias 15, 9 or fewer mantissa bits), so
//   nothing is rounded; alpha is 1;
// - three.js looks a CubeTexture up at (-x, y, z) of the direction it wants
//   (its "flipEnvMap" of -1 for any cube texture not rendered by itself),
//   while the file holds Vulkan's cube (+X -X +Y -Y +Z -Z, skybake's world
//   frame: +Y up, North -Z, East +X; docs/ibl.md, "Conventions"). So the
//   +X and -X faces trade places and every face is mirrored left to right:
//   then the sky along a direction of three's world is the sky along that
//   direction of skybake's, for scene.background, scene.environment and
//   material.envMap alike (three.js prefilters an environment itself from
//   level 0; the file's levels are for a shader of your own, as above);
// - the values are linear BT.709 (LinearSRGBColorSpace) in the bake's
//   units, divided by the file's skybake:scale (returned as userData).
import {
  CompressedCubeTexture, DataUtils, HalfFloatType, LinearFilter, LinearMipmapLinearFilter, LinearSRGBColorSpace,
  RGBAFormat,
} from 'three';
import { read } from 'three/addons/libs/ktx-parse.module.js';
import { ZSTDDecoder } from 'three/addons/libs/zstddec.module.js';

const VK_FORMAT_R16G16B16A16_SFLOAT = 97;
const VK_FORMAT_B10G11R11_UFLOAT_PACK32 = 122;
const VK_FORMAT_E5B9G9R9_UFLOAT_PACK32 = 123;
const ONE_HALF = 0x3C00;  // 1.0 as a half float

let zstdDecoder = null;

// The texel `i` of a level's bytes as four half floats into `out` at `o`.
function decodeTexel(view, format, i, out, o) {
  if (format === VK_FORMAT_R16G16B16A16_SFLOAT) {
    for (let c = 0; c < 3; c++) out[o + c] = view.getUint16(8 * i + 2 * c, true);
  } else if (format === VK_FORMAT_B10G11R11_UFLOAT_PACK32) {
    // Unsigned 11- and 10-bit floats: a half float's exponent and the top
    // 6 (5) of its 10 mantissa bits.
    const v = view.getUint32(4 * i, true);
    out[o] = (v & 0x7FF) << 4;
    out[o + 1] = ((v >>> 11) & 0x7FF) << 4;
    out[o + 2] = ((v >>> 22) & 0x3FF) << 5;
  } else {
    // Three 9-bit mantissas m and a shared exponent e: m 2^(e - 15 - 9).
    const v = view.getUint32(4 * i, true);
    const scale = Math.pow(2, (v >>> 27) - 24);
    out[o] = DataUtils.toHalfFloat((v & 0x1FF) * scale);
    out[o + 1] = DataUtils.toHalfFloat(((v >>> 9) & 0x1FF) * scale);
    out[o + 2] = DataUtils.toHalfFloat(((v >>> 18) & 0x1FF) * scale);
  }
  out[o + 3] = ONE_HALF;
}

// A CompressedCubeTexture (RGBA, half float; three.js uploads such a cube
// with texSubImage2D, level by level) from a KTX2 file's bytes.
export async function skybakeKtx2Cube(bytes) {
  const container = read(bytes);
  const format = container.vkFormat;
  if (![VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_B10G11R11_UFLOAT_PACK32, VK_FORMAT_E5B9G9R9_UFLOAT_PACK32]
    .includes(format)) throw new Error(`not a skybake KTX2 format: vkFormat ${format}`);
  if (container.faceCount !== 6 || container.layerCount > 1 || container.pixelDepth > 0)
    throw new Error('not a cube map: faceCount must be 6, one layer, 2D faces');
  if (container.supercompressionScheme === 2 && !zstdDecoder) {
    zstdDecoder = new ZSTDDecoder();
    await zstdDecoder.init();
  } else if (container.supercompressionScheme !== 0 && container.supercompressionScheme !== 2) {
    throw new Error(`supercompression scheme ${container.supercompressionScheme} is not none or zstd`);
  }
  const texelBytes = format === VK_FORMAT_R16G16B16A16_SFLOAT ? 8 : 4;
  // Three.js's face k is the file's face FROM[k], mirrored left to right.
  const FROM = [1, 0, 2, 3, 4, 5];
  const faces = FROM.map(() => ({ mipmaps: [], width: container.pixelWidth, height: container.pixelHeight,
                                  format: RGBAFormat, type: HalfFloatType }));
  container.levels.forEach((level, l) => {
    const size = Math.max(1, container.pixelWidth >> l);
    let data = level.levelData;
    if (container.supercompressionScheme === 2) data = zstdDecoder.decode(data, level.uncompressedByteLength);
    if (data.byteLength !== 6 * size * size * texelBytes)
      throw new Error(`level ${l}: ${data.byteLength} bytes where 6 faces of ${size} x ${size} need ` +
                      `${6 * size * size * texelBytes}`);
    const view = new DataView(data.buffer, data.byteOffset, data.byteLength);
    for (let k = 0; k < 6; k++) {
      const out = new Uint16Array(4 * size * size);
      const first = FROM[k] * size * size;
      for (let y = 0; y < size; y++)
        for (let x = 0; x < size; x++)
          decodeTexel(view, format, first + y * size + (size - 1 - x), out, 4 * (y * size + x));
      faces[k].mipmaps.push({ data: out, width: size, height: size });
    }
  });
  const texture = new CompressedCubeTexture(faces, RGBAFormat, HalfFloatType);
  texture.colorSpace = LinearSRGBColorSpace;
  texture.minFilter = container.levels.length > 1 ? LinearMipmapLinearFilter : LinearFilter;
  texture.magFilter = LinearFilter;
  texture.generateMipmaps = false;
  const text = (value) => (typeof value === 'string' ? value : new TextDecoder().decode(value).replace(/\0$/, ''));
  texture.userData.skybake = {};
  for (const [key, value] of Object.entries(container.keyValue))
    if (key.startsWith('skybake:')) texture.userData.skybake[key.slice(8)] = text(value);
  texture.needsUpdate = true;
  return texture;
}

// The same from a URL.
export async function loadSkybakeKtx2Cube(url) {
  const response = await fetch(url);
  if (!response.ok) throw new Error(`${url}: HTTP ${response.status}`);
  return skybakeKtx2Cube(new Uint8Array(await response.arrayBuffer()));
}
