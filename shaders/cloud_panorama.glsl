// The cloud panorama (include/skybake/cloud_panorama.h), after clouds.glsl:
// a frame's clouds marched once into a latlong of (radiance per unit solar
// irradiance, transmittance) texels, held in the cloud table buffer after
// the tables, and read back by every view. SkyPush.rect of a cloud pass:
// x the panorama's first texel in cloud_lut, y, z its width and height,
// w the mode (CLOUD_MODE_*, gpu_shared.h).
#ifndef SKYBAKE_CLOUD_PANORAMA_GLSL
#define SKYBAKE_CLOUD_PANORAMA_GLSL

// The rows marched (SkyPush.offsets.w): [first, end); every other row holds
// no cloud (cloud_panorama.h, CloudPanoramaRowsSeeingBands) and is read as such.
int CloudPanoramaFirstRow() { return push.offsets.w & 0xffff; }
int CloudPanoramaEndRow() { return push.offsets.w >> 16; }

// Texel `index` (row y) of the panorama at `first`: radiance 0 and
// transmittance 1 in the rows not marched.
vec4 CloudPanoramaTexel(int first, int width, int index, int y) {
  if (y < CloudPanoramaFirstRow() || y >= CloudPanoramaEndRow()) return vec4(0.0, 0.0, 0.0, 1.0);
  return cloud_lut[first + index];
}

// The block of rows workgroup row g of n marches: g x stride mod n, the
// stride SkyPush.view.w of the panorama pass (CloudPanoramaBlockStride in
// cloud_panorama.h: coprime with n, so every block is marched once).
int CloudPanoramaRowBlock(int g, int n) { return (g * push.view.w) % n; }

// The texels row y of a width x height panorama marches: one more than
// width x cos(latitude), so its texels are no farther apart in longitude
// than the equator's (a latlong row holds 1 / cos(latitude) times the texels
// its angular resolution needs); at least CLOUD_PANORAMA_MIN_ROW_WIDTH, at
// most width (CloudPanoramaRowWidth in cloud_panorama.h). The row keeps
// its place (texels y x width on) and its first and last texels are the
// meridian behind -Z, as in a latlong of this width.
int CloudPanoramaRowWidth(int width, int height, int y) {
  float cos_latitude = sin(kPi * float(y) / float(height - 1));
  return clamp(int(ceil(float(width) * cos_latitude)) + 1, min(CLOUD_PANORAMA_MIN_ROW_WIDTH, width), width);
}

// Row y at `u` in [0, 1] along it (column 0 at 0, its last column at 1),
// linear between its two nearest texels.
vec4 CloudPanoramaRowRead(int first, int width, int height, int y, float u) {
  int w = CloudPanoramaRowWidth(width, height, y);
  float x = u * float(w - 1);
  int x0 = min(int(x), w - 2);
  int row = y * width + x0;
  return mix(CloudPanoramaTexel(first, width, row, y), CloudPanoramaTexel(first, width, row + 1, y), x - float(x0));
}

// The panorama's texels around `view` (Imf::LatLongMap's grid, each row
// with its own width: row 0 the zenith, a row's first and last columns both
// the meridian behind -Z), bilinear,
// but never across the horizon: a ray just below it meets the ground and no
// cloud in front of it (seen from below the clouds), one just above crosses
// the whole deck edge on, so the clouds' transmittance jumps from 1 to about 0
// there within a texel. A row on the other side of the horizon from `view` is
// left out (its weight goes to the other row, which is on `view`'s side: the
// horizon lies between them).
vec4 CloudPanoramaRead(int first, int width, int height, vec3 view) {
  float latitude = asin(clamp(view.y, -1.0, 1.0));
  float longitude = atan(view.x, view.z);
  float u = clamp(0.5 - longitude / (2.0 * kPi), 0.0, 1.0);
  float y = clamp((0.5 - latitude / kPi) * float(height - 1), 0.0, float(height - 1));
  int y0 = min(int(y), height - 2);
  float fy = y - float(y0);
  // The cosine of the horizon's zenith angle seen from the observer.
  float ratio = gpu_atmosphere.radii.x / (gpu_atmosphere.radii.x + gpu_atmosphere.radii.z);
  float mu_horizon = -sqrt(max(1.0 - ratio * ratio, 0.0));
  bool below = view.y < mu_horizon;
  float mu0 = sin(kPi * (0.5 - float(y0) / float(height - 1)));
  float mu1 = sin(kPi * (0.5 - float(y0 + 1) / float(height - 1)));
  if ((mu0 < mu_horizon) != below) fy = 1.0;
  if ((mu1 < mu_horizon) != below) fy = 0.0;
  return mix(CloudPanoramaRowRead(first, width, height, y0, u), CloudPanoramaRowRead(first, width, height, y0 + 1, u), fy);
}

#endif  // SKYBAKE_CLOUD_PANORAMA_GLSL
