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

// The panorama's texels around `view` (Imf::LatLongMap's grid: row 0 the
// zenith, columns 0 and width - 1 both the meridian behind -Z), bilinear,
// but never across the horizon: a ray just below it meets the ground and no
// cloud in front of it (seen from below the clouds), one just above crosses
// the whole deck edge on, so the clouds' transmittance jumps from 1 to about 0
// there within a texel. A row on the other side of the horizon from `view` is
// left out (its weight goes to the other row, which is on `view`'s side: the
// horizon lies between them).
vec4 CloudPanoramaRead(int first, int width, int height, vec3 view) {
  float latitude = asin(clamp(view.y, -1.0, 1.0));
  float longitude = atan(view.x, view.z);
  float x = clamp((0.5 - longitude / (2.0 * kPi)) * float(width - 1), 0.0, float(width - 1));
  float y = clamp((0.5 - latitude / kPi) * float(height - 1), 0.0, float(height - 1));
  int x0 = min(int(x), width - 2), y0 = min(int(y), height - 2);
  float fx = x - float(x0), fy = y - float(y0);
  // The cosine of the horizon's zenith angle seen from the observer.
  float ratio = gpu_atmosphere.radii.x / (gpu_atmosphere.radii.x + gpu_atmosphere.radii.z);
  float mu_horizon = -sqrt(max(1.0 - ratio * ratio, 0.0));
  bool below = view.y < mu_horizon;
  float mu0 = sin(kPi * (0.5 - float(y0) / float(height - 1)));
  float mu1 = sin(kPi * (0.5 - float(y0 + 1) / float(height - 1)));
  if ((mu0 < mu_horizon) != below) fy = 1.0;
  if ((mu1 < mu_horizon) != below) fy = 0.0;
  int row0 = y0 * width + x0, row1 = row0 + width;
  vec4 a = mix(CloudPanoramaTexel(first, width, row0, y0), CloudPanoramaTexel(first, width, row0 + 1, y0), fx);
  vec4 b = mix(CloudPanoramaTexel(first, width, row1, y0 + 1), CloudPanoramaTexel(first, width, row1 + 1, y0 + 1), fx);
  return mix(a, b, fy);
}

#endif  // SKYBAKE_CLOUD_PANORAMA_GLSL
