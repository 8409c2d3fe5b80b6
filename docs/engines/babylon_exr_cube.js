// Loads the babylon preset's six EXR faces (BASE_babylon_{px,py,pz,nx,ny,nz}.exr,
// `--engine babylon`) into Babylon.js as one float cube texture, the right
// way up in Babylon's default (left-handed) scene with a skybake glTF scene
// loaded by its glTF loader. Tested with Babylon.js 9.31
// (tests/e2e/engine_babylon_test.cc); copy it into your project.
//
//   import { loadSkybakeBabylonCube } from './babylon_exr_cube.js';
//   const sky = await loadSkybakeBabylonCube(BABYLON, scene, 'sky_babylon');
//   const box = BABYLON.MeshBuilder.CreateBox('skybox', { size: 1000 }, scene);
//   const material = new BABYLON.StandardMaterial('skybox', scene);
//   material.backFaceCulling = false;
//   material.disableLighting = true;
//   material.reflectionTexture = sky;
//   material.reflectionTexture.coordinatesMode = BABYLON.Texture.SKYBOX_MODE;
//   box.material = material;
//   // or: scene.environmentTexture = sky; scene.createDefaultSkybox(sky, false);
//
// `BABYLON` is the namespace: the `babylonjs` package's global, or
// `import * as BABYLON from '@babylonjs/core'`.
//
// Why not CubeTexture('sky_babylon', scene, ['_px.exr', ...]): Babylon's
// CubeTexture loads six files as images, and a browser decodes no EXR
// image, so the texture never becomes ready; with one .exr file it throws
// ".exr not supported in Cube." (Babylon 9.31). EXRCubeTexture takes one
// equirect panorama, not faces. So each face is decoded with Babylon's own
// EXR decoder (ReadExrDataAsync) and the six are uploaded as a
// RawCubeTexture (in OpenGL's face order; the files are in CubeTexture's).
//
// - skybake's EXRs are ZIP-compressed: Babylon's decoder then needs fflate,
//   which it loads from a CDN (BABYLON.ExrLoaderGlobalConfiguration.FFLATEUrl)
//   unless `window.fflate` is set; serve your own copy where there is no
//   network.
// - The values are linear BT.709 in the bake's units (cd/m^2 by default),
//   divided by the files' skybake:scale (1 for a default bake).
// - Float textures: a device without float-texture filtering (WebGL 1
//   without OES_texture_float_linear) shows them unfiltered.
export async function loadSkybakeBabylonCube(BABYLON, scene, base) {
  const suffixes = ['px', 'py', 'pz', 'nx', 'ny', 'nz'];
  const faces = await Promise.all(suffixes.map(async (suffix) => {
    const response = await fetch(`${base}_${suffix}.exr`);
    if (!response.ok) throw new Error(`${base}_${suffix}.exr: HTTP ${response.status}`);
    const face = await BABYLON.ReadExrDataAsync(await response.arrayBuffer());
    if (!face.data) throw new Error(`${base}_${suffix}.exr: not an EXR Babylon can decode`);
    return face;
  }));
  const size = faces[0].width;
  for (const face of faces)
    if (face.width !== size || face.height !== size) throw new Error(`${base}: faces of different sizes`);
  const channels = faces[0].data.length / (size * size);
  const format = channels === 4 ? BABYLON.Constants.TEXTUREFORMAT_RGBA : BABYLON.Constants.TEXTUREFORMAT_RGB;
  // The decoder hands rows bottom first (as OpenGL's 2D textures want them);
  // a cube face's first row is its top.
  const rows = faces.map((face) => {
    const flipped = new Float32Array(face.data.length);
    const stride = size * channels;
    for (let y = 0; y < size; ++y)
      flipped.set(face.data.subarray((size - 1 - y) * stride, (size - y) * stride), y * stride);
    return flipped;
  });
  // RawCubeTexture takes its faces in OpenGL's order, +X -X +Y -Y +Z -Z.
  const gl = ['px', 'nx', 'py', 'ny', 'pz', 'nz'].map((suffix) => rows[suffixes.indexOf(suffix)]);
  const texture = new BABYLON.RawCubeTexture(scene, gl, size, format, BABYLON.Constants.TEXTURETYPE_FLOAT,
                                             false, false, BABYLON.Constants.TEXTURE_BILINEAR_SAMPLINGMODE);
  texture.gammaSpace = false;  // linear values (a raw texture is taken as sRGB-encoded otherwise)
  return texture;
}
