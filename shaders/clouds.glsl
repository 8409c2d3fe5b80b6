// Volumetric cloud layers (include/skybake/model/clouds.h, docs/clouds.md), after
// common.glsl: the noise volumes, the density, the aerial-perspective and
// ambient tables, and the ray march that composites the clouds over the sky
// the sky pass wrote.
//
// Frames and units: planet-centred world frame in km (+Y up, the observer
// at (0, bottom_radius + observer_altitude, 0), North = -Z, East = +X);
// extinction in km^-1; radiance per unit solar irradiance until the pass
// multiplies by it.
#ifndef SKYBAKE_CLOUDS_GLSL
#define SKYBAKE_CLOUDS_GLSL

layout(std140, set = 0, binding = BINDING_CLOUDS) uniform CloudBlock {
  GpuClouds gpu_clouds;
};
layout(std430, set = 0, binding = BINDING_CLOUD_NOISE) buffer CloudNoiseBuffer {
  float cloud_noise[];
};
layout(std430, set = 0, binding = BINDING_CLOUD_LUT) buffer CloudLutBuffer {
  vec4 cloud_lut[];
};
// The noise and the tables read through their texel views (common.glsl,
// kTexelViews); the writes, and the light volume's reads of what its own
// dispatch wrote, stay on the storage buffers.
layout(set = 0, binding = BINDING_CLOUD_NOISE_TEXELS) uniform samplerBuffer cloud_noise_view;
layout(set = 0, binding = BINDING_CLOUD_TABLE_TEXELS) uniform samplerBuffer cloud_table_view;
float CloudNoise(int i) { return kTexelViews ? texelFetch(cloud_noise_view, i).x : cloud_noise[i]; }
vec3 CloudTable(int i) { return kTexelViews ? texelFetch(cloud_table_view, i).xyz : cloud_lut[i].xyz; }
// Active layers: the loops over layers have this bound, so a style's layer
// count is compiled in (the cloud pipelines exist only when it is > 0).
layout(constant_id = SPEC_CLOUD_LAYERS) const int kCloudLayers = 1;
// Whether the Sun lights the clouds. Off for a frame whose every band is in
// the Earth's shadow (CloudEarthShadowElevationDeg, clouds.h): the disc's
// visible fraction is exactly 0 at every sample the march can take, so the
// sunlight, and with it the light march, is 0 there; compiled out, since
// lavapipe runs an `if` masked and every lit sample paid for the light march.
// The ambient light of the sky and the ground is the same either way.
layout(constant_id = SPEC_CLOUD_SUN_LIGHT) const bool kCloudSunLight = true;
// Whether the light march reads its far part from the frame's light volume
// (GpuClouds.light_volume, CloudLightVolumeDepth); off: every light sample
// marched (the reference, a style of two or more bands, a low Sun).
layout(constant_id = SPEC_CLOUD_LIGHT_VOLUME) const bool kCloudLightVolume = false;
// Whether some layer's density is a formation's volume (weather.w 2,
// CloudFormationDensityOn in clouds.h). Off, that read is compiled out: both
// sides of an `if` run on lavapipe, so every density call of a style without
// a formation paid for that volume's trilinear read too.
layout(constant_id = SPEC_CLOUD_FORMATION) const bool kCloudFormation = true;
// Whether some layer is cirrus (GpuCloudLayer.streaks.z > 0, CloudCirrusOn in
// clouds.h): its noise read along the streaks (cloud_cirrus.glsl) and its
// samples lit through the ice phase (cloud_ice_phase.glsl). Off, both are
// compiled out: a style without cirrus runs the shader it ran before.
layout(constant_id = SPEC_CLOUD_CIRRUS) const bool kCloudCirrus = false;

// ---------------------------------------------------------------- hashing and tiling noise

// An integer mix with full avalanche (xor-shift-multiply rounds); the noise
// depends on integer cell coordinates and the seed alone, so two bakes give
// the same bytes.
uint CloudHash(uint x) {
  x ^= x >> 16;
  x *= 0x21f0aaadu;
  x ^= x >> 15;
  x *= 0xd35a2d97u;
  x ^= x >> 15;
  return x;
}

uint CloudCellHash(ivec3 cell, uint seed) {
  return CloudHash(uint(cell.x) ^ CloudHash(uint(cell.y) ^ CloudHash(uint(cell.z) ^ CloudHash(seed))));
}

float UnitFromHash(uint h) { return float(h >> 8) * (1.0 / 16777216.0); }

// Cell coordinates wrapped into one tile of `period` cells (c >= -period).
ivec3 WrapCell(ivec3 c, int period) { return (c + ivec3(period)) % ivec3(period); }

// Worley (cellular) noise of a tile of period^3 cells, one feature point per
// cell: 1 - distance to the nearest, in cell units, clamped. x in [0, 1)^3.
float TiledWorley(vec3 x, int period, uint seed) {
  vec3 p = x * float(period);
  vec3 base = floor(p);
  vec3 f = p - base;
  ivec3 cell = ivec3(base);
  float d2 = 1e9;
  for (int k = -1; k <= 1; ++k) {
    for (int j = -1; j <= 1; ++j) {
      for (int i = -1; i <= 1; ++i) {
        ivec3 o = ivec3(i, j, k);
        uint h = CloudCellHash(WrapCell(cell + o, period), seed);
        vec3 feature = vec3(UnitFromHash(h), UnitFromHash(CloudHash(h ^ 0x68e31da4u)),
                            UnitFromHash(CloudHash(h ^ 0xb5297a4du)));
        vec3 d = vec3(o) + feature - f;
        d2 = min(d2, dot(d, d));
      }
    }
  }
  return 1.0 - clamp(sqrt(d2), 0.0, 1.0);
}

// Gradient (Perlin) noise of a tile of period^3 lattice cells; gradients
// are the 12 cube-edge directions, picked by the hash. About [-1, 1].
float LatticeGradient(ivec3 c, int period, uint seed, vec3 d) {
  uint h = CloudCellHash(WrapCell(c, period), seed ^ 0x1b873593u);
  vec3 g = vec3((h & 1u) != 0u ? 1.0 : -1.0, (h & 2u) != 0u ? 1.0 : -1.0, (h & 4u) != 0u ? 1.0 : -1.0);
  uint zero = (h >> 3) % 3u;
  if (zero == 0u) g.x = 0.0;
  else if (zero == 1u) g.y = 0.0;
  else g.z = 0.0;
  return dot(g, d);
}

float TiledPerlin(vec3 x, int period, uint seed) {
  vec3 p = x * float(period);
  vec3 base = floor(p);
  vec3 f = p - base;
  ivec3 c = ivec3(base);
  vec3 u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);  // Perlin 2002's quintic fade
  float n000 = LatticeGradient(c + ivec3(0, 0, 0), period, seed, f - vec3(0, 0, 0));
  float n100 = LatticeGradient(c + ivec3(1, 0, 0), period, seed, f - vec3(1, 0, 0));
  float n010 = LatticeGradient(c + ivec3(0, 1, 0), period, seed, f - vec3(0, 1, 0));
  float n110 = LatticeGradient(c + ivec3(1, 1, 0), period, seed, f - vec3(1, 1, 0));
  float n001 = LatticeGradient(c + ivec3(0, 0, 1), period, seed, f - vec3(0, 0, 1));
  float n101 = LatticeGradient(c + ivec3(1, 0, 1), period, seed, f - vec3(1, 0, 1));
  float n011 = LatticeGradient(c + ivec3(0, 1, 1), period, seed, f - vec3(0, 1, 1));
  float n111 = LatticeGradient(c + ivec3(1, 1, 1), period, seed, f - vec3(1, 1, 1));
  float x00 = mix(n000, n100, u.x), x10 = mix(n010, n110, u.x);
  float x01 = mix(n001, n101, u.x), x11 = mix(n011, n111, u.x);
  return mix(mix(x00, x10, u.y), mix(x01, x11, u.y), u.z);
}

// Fractal sums over octaves of doubling period (each octave still tiles).
float TiledPerlinFbm(vec3 x, int period, int octaves, uint seed) {
  float sum = 0.0, weight = 1.0, total = 0.0;
  for (int o = 0; o < octaves; ++o) {
    sum += weight * TiledPerlin(x, period << o, seed + uint(o) * 101u);
    total += weight;
    weight *= 0.5;
  }
  return sum / total;
}

// Schneider 2015's Worley fbm: three octaves weighted 0.625, 0.25, 0.125.
float TiledWorleyFbm(vec3 x, int period, uint seed) {
  return 0.625 * TiledWorley(x, period, seed) + 0.25 * TiledWorley(x, 2 * period, seed + 7u) +
         0.125 * TiledWorley(x, 4 * period, seed + 13u);
}

float Remap(float v, float lo, float hi, float new_lo, float new_hi) {
  return new_lo + (v - lo) / (hi - lo) * (new_hi - new_lo);
}

// The shape volume: Perlin-Worley (Perlin fbm remapped by an inverted
// low-frequency Worley, Schneider 2015), then eroded by a higher-frequency
// Worley fbm; [0, 1].
float ShapeNoiseValue(vec3 x, uint seed) {
  float perlin = clamp(0.5 + 0.75 * TiledPerlinFbm(x, 4, 3, seed), 0.0, 1.0);
  float worley = TiledWorleyFbm(x, 4, seed + 1000u);
  float perlin_worley = clamp(Remap(perlin, worley - 1.0, 1.0, 0.0, 1.0), 0.0, 1.0);
  float erosion = TiledWorleyFbm(x, 8, seed + 2000u);
  float shape = Remap(perlin_worley, erosion - 1.0, 1.0, 0.0, 1.0);
  // Spread over [0, 1] (the remaps leave it at mean 0.78, sd 0.07 for 48^3
  // voxels, tests/model/clouds_test.cc): mean about 0.5, sd about 0.2.
  return clamp((shape - 0.6) / 0.35, 0.0, 1.0);
}

// The detail volume: Worley fbm, [0, 1].
float DetailNoiseValue(vec3 x, uint seed) { return TiledWorleyFbm(x, 4, seed + 3000u); }

// The procedural weather map: 2D Perlin-Worley (the z = 0 plane of the
// tiling 3D noise), spread over [0, 1] so that coverage 0.5 covers about half.
float WeatherNoiseValue(vec2 x, uint seed) {
  vec3 p = vec3(x, 0.0);
  float perlin = clamp(0.5 + 0.9 * TiledPerlinFbm(p, 3, 4, seed + 4000u), 0.0, 1.0);
  float worley = TiledWorleyFbm(p, 3, seed + 5000u);
  float v = smoothstep(0.15, 0.85, clamp(Remap(perlin, worley - 1.0, 1.0, 0.0, 1.0), 0.0, 1.0));
  // Spread over [0, 1] (v has mean 0.81, sd 0.14 on a 128^2 map): mean about 0.5.
  return clamp((v - 0.81) / 0.56 + 0.5, 0.0, 1.0);
}

// ---------------------------------------------------------------- sampling the volumes

// Wrapped neighbours of a texel index for p in [-0.5, n - 0.5): selects, not
// integer modulo, which lavapipe runs lane by lane (a division each).
ivec3 WrapLow(vec3 base, int n) {
  ivec3 i = ivec3(base);
  return mix(i, ivec3(n - 1), lessThan(base, vec3(0.0)));
}
ivec3 WrapHigh(ivec3 i0, int n) { return mix(i0 + ivec3(1), ivec3(0), equal(i0, ivec3(n - 1))); }

// Trilinear read of an n^3 volume at `first`, wrapping (the volume tiles).
float SampleVolume(int first, int n, vec3 uvw) {
  vec3 p = fract(uvw) * float(n) - 0.5;
  vec3 base = floor(p);
  vec3 f = p - base;
  ivec3 i0 = WrapLow(base, n);
  ivec3 i1 = WrapHigh(i0, n);
  int row0 = first + (i0.z * n + i0.y) * n, row1 = first + (i0.z * n + i1.y) * n;
  int row2 = first + (i1.z * n + i0.y) * n, row3 = first + (i1.z * n + i1.y) * n;
  float a = mix(CloudNoise(row0 + i0.x), CloudNoise(row0 + i1.x), f.x);
  float b = mix(CloudNoise(row1 + i0.x), CloudNoise(row1 + i1.x), f.x);
  float c = mix(CloudNoise(row2 + i0.x), CloudNoise(row2 + i1.x), f.x);
  float d = mix(CloudNoise(row3 + i0.x), CloudNoise(row3 + i1.x), f.x);
  return mix(mix(a, b, f.y), mix(c, d, f.y), f.z);
}

// Bilinear read of an n^2 map at `first`, wrapping.
float SampleMap(int first, int n, vec2 uv) {
  vec2 p = fract(uv) * float(n) - 0.5;
  vec2 base = floor(p);
  vec2 f = p - base;
  ivec2 i0 = WrapLow(vec3(base, 0.0), n).xy;
  ivec2 i1 = WrapHigh(ivec3(i0, 0), n).xy;
  float a = mix(CloudNoise(first + i0.y * n + i0.x), CloudNoise(first + i0.y * n + i1.x), f.x);
  float b = mix(CloudNoise(first + i1.y * n + i0.x), CloudNoise(first + i1.y * n + i1.x), f.x);
  return mix(a, b, f.y);
}

// Nearest-voxel reads of an n^3 volume and of an n^2 map (the texel that
// holds the point), wrapping: one load where the trilinear read takes 8.
float SampleVolumeNearest(int first, int n, vec3 uvw) {
  ivec3 i = min(ivec3(fract(uvw) * float(n)), ivec3(n - 1));
  return CloudNoise(first + (i.z * n + i.y) * n + i.x);
}
float SampleMapNearest(int first, int n, vec2 uv) {
  ivec2 i = min(ivec2(fract(uv) * float(n)), ivec2(n - 1));
  return CloudNoise(first + i.y * n + i.x);
}

#include "cloud_cirrus.glsl"
#include "cloud_weather.glsl"

// ---------------------------------------------------------------- density

// The height profile: 0 below `stops.x`, rising to 1 at `stops.y`, 1 up to
// `stops.z`, falling to 0 at `stops.w` (fractions of the thickness).
float HeightProfile(vec4 stops, float hf) {
  float rise = smoothstep(stops.x, max(stops.y, stops.x + 1e-4), hf);
  float fall = 1.0 - smoothstep(stops.z, max(stops.w, stops.z + 1e-4), hf);
  return rise * fall;
}

// Extinction (km^-1) of layer `l` at world horizontal position `xz` (km)
// and altitude `h` (km). `detail`: erode with the detail noise (view
// samples; the light march leaves it out).
float LayerExtinction(int l, vec2 xz, float h, bool detail) {
  GpuCloudLayer layer = gpu_clouds.layers[l];
  float hf = (h - layer.shell.x) / (layer.shell.y - layer.shell.x);
  if (hf <= 0.0 || hf >= 1.0) return 0.0;
  float profile = HeightProfile(layer.profile, hf);
  float coverage_key = layer.weather.x;
  // Wind and the non-repeating warp (cloud_weather.glsl).
  CloudPlace place = CloudPlaceOf(layer, xz, h);
  float d;
  if (kCloudFormation && layer.weather.w > 1.5) {
    // A formation's whole density (cloud_formation.h): its volume, x and y
    // over the lattice as the weather map, z the height fraction (texel
    // centres at the bottom and the top: clamped, not wrapped).
    float n = float(gpu_clouds.resolution.x);
    d = SampleVolume(layer.noise.x, gpu_clouds.resolution.x,
                     vec3(place.weather_uv.x, clamp(hf, 0.5 / n, 1.0 - 0.5 / n), place.weather_uv.y));
  } else {
    float weather = CloudWeatherAt(layer, place, false);
    // Local coverage: coverage 0.5 is the weather map as it is, 0 none, 1 all.
    float coverage = clamp(2.0 * coverage_key - 1.0 + weather, 0.0, 1.0);
    // Schneider 2015: remap(shape x profile, 1 - coverage, 1) x coverage; the
    // shape is at most 1, so where the profile alone is below 1 - coverage
    // there is no cloud and no volume is read.
    if (coverage <= 0.0 || profile <= 1.0 - coverage) return 0.0;
    float shape = SampleVolume(layer.noise.x, gpu_clouds.resolution.x, CloudShapeUvw(layer, place, h - layer.shell.x));
    float base = mix(1.0, shape, layer.shape.x) * profile;
    d = clamp((base - (1.0 - coverage)) / coverage, 0.0, 1.0) * coverage;
  }
  if (d <= 0.0) return 0.0;
  float lift = h - layer.shell.x;
  if (detail && layer.shape.z > 0.0) {
    float n = SampleVolume(layer.noise.y, gpu_clouds.resolution.y, CloudDetailUvw(layer, place, lift));
    // Wispy at the base (inverted noise), billowy above (Schneider 2015).
    float modifier = mix(1.0 - n, n, clamp(hf * 5.0, 0.0, 1.0));
    float threshold = 0.35 * layer.shape.z * modifier;
    d = clamp((d - threshold) / (1.0 - threshold), 0.0, 1.0);
  }
  return d * layer.shell.z;
}

float CloudExtinction(vec2 xz, float h, bool detail) {
  float sigma = 0.0;
  for (int l = 0; l < kCloudLayers; ++l) sigma += LayerExtinction(l, xz, h, detail);
  return sigma;
}

// ---------------------------------------------------------------- empty space

// The empty-space bounds after every layer's noise (FillCloudSkipMaps,
// clouds.h): per layer the maximum of its weather map over each cell between
// 2 x 2 texel centres, then of its shape volume over each cell between 2^3
// voxel centres (one cell per texel).
int CloudSkipFirst(int l) {
  int ns = gpu_clouds.resolution.x, nd = gpu_clouds.resolution.y, nw = gpu_clouds.resolution.z;
  return gpu_clouds.counts.x * (ns * ns * ns + nd * nd * nd + nw * nw) + l * (nw * nw + ns * ns * ns);
}
// The cells that hold coordinates u (wrapped) of n-texel axes: the read's
// first texels, as SampleVolume and SampleMap find them; `edge` is set where
// a point lies within CLOUD_SKIP_EDGE of its cell's edge along any axis
// (rounding could put the read in the next cell: such a point is not bounded).
ivec3 CloudSkipCell(vec3 u, int n, inout bool edge) {
  vec3 p = fract(u) * float(n) - 0.5;
  vec3 base = floor(p);
  vec3 f = p - base;
  edge = edge || any(lessThan(f, vec3(CLOUD_SKIP_EDGE))) || any(greaterThan(f, vec3(1.0 - CLOUD_SKIP_EDGE)));
  return WrapLow(base, n);
}

// Above 0 where layer l may hold cloud at (xz, h); at most 0 where
// LayerExtinction is 0 there. LayerExtinction's density is 0 where the
// shape times the profile stays at or below 1 - the local coverage
// (Schneider's remap); here the shape and the weather are their cells'
// maxima (each one load, nearest), both sides of the test only grow, and
// 1e-4 more keeps it on the safe side of rounding. A formation's density
// volume has no bound: inside such a layer every sample is marched.
float LayerCloudMargin(int l, vec2 xz, float h) {
  GpuCloudLayer layer = gpu_clouds.layers[l];
  float hf = (h - layer.shell.x) / (layer.shell.y - layer.shell.x);
  bool inside = hf > 0.0 && hf < 1.0;
  if (kCloudFormation && layer.weather.w > 1.5) return inside ? 1.0 : -1.0;
  float profile = HeightProfile(layer.profile, hf);
  CloudPlace place = CloudPlaceOf(layer, xz, h);
  int first = CloudSkipFirst(l);
  int nw = gpu_clouds.resolution.z, ns = gpu_clouds.resolution.x;
  bool edge = false;
  ivec2 wcell = CloudSkipCell(vec3(place.weather_uv, 0.0), nw, edge).xy;  // z: mid-cell, never an edge
  float weather = CloudNoise(first + wcell.y * nw + wcell.x);
  if (place.three_reads) {
    // The weather of the three reads grows with each (CloudWeatherOfReads):
    // of the cells' maxima it bounds the weather of any point in all three.
    ivec2 wcell2 = CloudSkipCell(vec3(place.weather_uv2, 0.0), nw, edge).xy;
    ivec2 wcell3 = CloudSkipCell(vec3(place.weather_uv3, 0.0), nw, edge).xy;
    weather = CloudWeatherOfReads(weather, CloudNoise(first + wcell2.y * nw + wcell2.x),
                                  CloudNoise(first + wcell3.y * nw + wcell3.x));
  }
  float coverage = clamp(2.0 * layer.weather.x - 1.0 + weather, 0.0, 1.0);
  ivec3 cell = CloudSkipCell(CloudShapeUvw(layer, place, h - layer.shell.x), ns, edge);
  float shape = CloudNoise(first + nw * nw + (cell.z * ns + cell.y) * ns + cell.x);
  float base = mix(1.0, shape, layer.shape.x) * profile;
  if (edge) return inside ? 1.0 : -1.0;
  return inside && coverage > 0.0 ? base - (1.0 - coverage) + 1e-4 : -1.0;
}

// Above 0 where some layer may hold cloud; every sample when the bounds are
// off (GpuClouds.range.w 0).
float CloudMargin(vec2 xz, float h) {
  if (gpu_clouds.range.w < 0.5) return 1.0;
  float m = -1.0;
  for (int l = 0; l < kCloudLayers; ++l) m = max(m, LayerCloudMargin(l, xz, h));
  return m;
}

// ---------------------------------------------------------------- the tables

// Aerial-perspective LUT texel (x, y): x the azimuth from the Sun in [0, pi],
// y the zenith angle in [0, pi], both with texel centres on the ends; slice
// k at distance max_distance ((k + 1) / slices)^2.
int CloudApWidth() { return gpu_clouds.lut.x; }
int CloudApHeight() { return gpu_clouds.lut.y; }
int CloudApSlices() { return gpu_clouds.lut.z; }
float CloudApSliceDistance(int k) {
  float s = float(k + 1) / float(CloudApSlices());
  return gpu_clouds.range.x * s * s;
}
int CloudApIndex(int x, int y, int k) { return (k * CloudApHeight() + y) * CloudApWidth() + x; }
int CloudApTexels() { return CloudApWidth() * CloudApHeight() * CloudApSlices(); }
// Ambient rows after the LUT's in-scattering and transmittance halves:
// altitude row i at range.y i / (rows - 1); two texels (sky above, ground below).
int CloudAmbientIndex(int row, int half_) { return 2 * CloudApTexels() + 2 * row + half_; }

vec3 CloudApDirection(int x, int y, out vec3 sun_frame_sun, float mu_s) {
  float azimuth = kPi * float(x) / float(CloudApWidth() - 1);
  float zenith = kPi * float(y) / float(CloudApHeight() - 1);
  sun_frame_sun = SunInSkyViewFrame(mu_s);
  return vec3(sin(zenith) * cos(azimuth), cos(zenith), sin(zenith) * sin(azimuth));
}

// The cloud pass converts its light as direct sunlight (output_scale); sky
// light in its tables (the air's in-scattering in front of the clouds, the
// sky light the clouds scatter) is held in the terms that give it the sky's
// conversion instead.
vec3 AmbientToDirect(vec3 sky_radiance) {
  return vec3(dot(gpu_atmosphere.ambient_to_direct[0].xyz, sky_radiance),
              dot(gpu_atmosphere.ambient_to_direct[1].xyz, sky_radiance),
              dot(gpu_atmosphere.ambient_to_direct[2].xyz, sky_radiance));
}

// The atmosphere's in-scattering and transmittance from the observer along
// the texel's direction to every slice distance (Hillaire 2020's aerial
// perspective, in the sky-view LUT's sun frame), 4 analytic steps per slice.
void ComputeCloudApColumn(IN(AtmosphereParameters) atm, int x, int y, vec3 sun_world) {
  vec3 sun;
  vec3 view = CloudApDirection(x, y, sun, ClampCosine(sun_world.y));
  SkyRay ray = SkyRayAtObserver(atm, view, sun);
  ray.t_max = gpu_clouds.range.x;
  float rayleigh_phase = RayleighPhase(ray.nu);
  float mie_phase = atm.mie ? MiePhase(atm.mie_g, view, sun) : 0.0;
  vec3 radiance = vec3(0.0);
  vec3 transmittance = vec3(1.0);
  float t_start = 0.0;
  const int kSubsteps = 4;
  for (int k = 0; k < CloudApSlices(); ++k) {
    float t_end = CloudApSliceDistance(k);
    float dt = (t_end - t_start) / float(kSubsteps);
    for (int s = 0; s < kSubsteps; ++s) {
      float t_mid = t_start + (float(s) + 0.5) * dt;
      ScatteringSample sample_ = SampleScattering(atm, ray, rayleigh_phase, mie_phase, t_mid);
      radiance += transmittance * sample_.source * (dt * OneMinusExpOverX3(sample_.extinction * dt));
      transmittance *= exp(-sample_.extinction * dt);
    }
    t_start = t_end;
    cloud_lut[CloudApIndex(x, y, k)] = vec4(AmbientToDirect(radiance), 0.0);
    cloud_lut[CloudApTexels() + CloudApIndex(x, y, k)] = vec4(transmittance, 0.0);
  }
}

// Mean sky radiance over the upper hemisphere and mean radiance from below
// (the sunlit ground through the air, and the air) at altitude row `row`:
// 8 azimuths x 4 rings of equal solid angle per hemisphere, 16 steps each.
void ComputeCloudAmbientRow(IN(AtmosphereParameters) atm_in, int row, vec3 sun) {
  AtmosphereParameters atm = atm_in;
  int rows = gpu_clouds.lut.w;
  atm.observer_altitude = gpu_clouds.range.y * float(row) / float(rows - 1);
  atm.view_steps = 16;
  atm.integrator = INTEGRATOR_ANALYTIC;
  vec3 up = vec3(0.0), down = vec3(0.0);
  for (int ring = 0; ring < 4; ++ring) {
    float mu = (float(ring) + 0.5) / 4.0;
    float s = sqrt(1.0 - mu * mu);
    for (int a = 0; a < 8; ++a) {
      float phi = 2.0 * kPi * (float(a) + 0.5) / 8.0;
      up += ComputeSkyRadianceWithoutSun(atm, vec3(s * cos(phi), mu, s * sin(phi)), sun).radiance;
      down += ComputeSkyRadianceWithoutSun(atm, vec3(s * cos(phi), -mu, s * sin(phi)), sun).radiance;
    }
  }
  // The sky's light keeps the sky's spectrum when a cloud scatters it.
  up = AmbientToDirect(up);
  cloud_lut[CloudAmbientIndex(row, 0)] = vec4(up / 32.0, 0.0);
  cloud_lut[CloudAmbientIndex(row, 1)] = vec4(down / 32.0, 0.0);
}

// ---------------------------------------------------------------- lighting

float HenyeyGreenstein(float g, float cos_theta) {
  float denom = 1.0 + g * g - 2.0 * g * cos_theta;
  return (1.0 - g * g) / (4.0 * kPi * denom * sqrt(denom));
}

// Dual-lobe Henyey-Greenstein, both lobes' g scaled by `eccentricity`.
float CloudPhase(float cos_theta, float eccentricity) {
  return mix(HenyeyGreenstein(gpu_clouds.phase.y * eccentricity, cos_theta),
             HenyeyGreenstein(gpu_clouds.phase.x * eccentricity, cos_theta), gpu_clouds.phase.z);
}

#include "cloud_ice_phase.glsl"

// Distance along the ray (r0, mu) to altitude H on the descending (sign
// -1) or ascending (+1) branch; r_H^2 - r0^2 formed from altitudes.
float CloudRayToAltitude(IN(AtmosphereParameters) atm, float r0, float h0, float mu, float H, float branch) {
  float disc = r0 * r0 * mu * mu + (H - h0) * (2.0 * atm.bottom_radius + H + h0);
  return -r0 * mu + branch * sqrt(max(disc, 0.0));
}

// LayerExtinction without the detail erosion (the light march's density),
// its volumes and weather map read at the nearest voxel: the light march's
// far samples (CloudOpticalDepthToSun), where a step is about a voxel long
// or longer, so the sample is a point estimate of the step either way.
float LayerLightExtinctionNearest(int l, vec2 xz, float h) {
  GpuCloudLayer layer = gpu_clouds.layers[l];
  float hf = (h - layer.shell.x) / (layer.shell.y - layer.shell.x);
  float profile = HeightProfile(layer.profile, hf);
  CloudPlace place = CloudPlaceOf(layer, xz, h);
  float d;
  if (kCloudFormation && layer.weather.w > 1.5) {
    float n = float(gpu_clouds.resolution.x);
    d = SampleVolumeNearest(layer.noise.x, gpu_clouds.resolution.x,
                            vec3(place.weather_uv.x, clamp(hf, 0.5 / n, 1.0 - 0.5 / n), place.weather_uv.y));
  } else {
    float weather = CloudWeatherAt(layer, place, true);
    float coverage = clamp(2.0 * layer.weather.x - 1.0 + weather, 0.0, 1.0);
    float shape = SampleVolumeNearest(layer.noise.x, gpu_clouds.resolution.x, CloudShapeUvw(layer, place, h - layer.shell.x));
    float base = mix(1.0, shape, layer.shape.x) * profile;
    d = coverage > 0.0 ? clamp((base - (1.0 - coverage)) / coverage, 0.0, 1.0) * coverage : 0.0;
  }
  return hf > 0.0 && hf < 1.0 ? d * layer.shell.z : 0.0;
}

float CloudLightExtinction(vec2 xz, float h, bool nearest) {
  if (!nearest) return CloudExtinction(xz, h, false);
  float sigma = 0.0;
  for (int l = 0; l < kCloudLayers; ++l) sigma += LayerLightExtinctionNearest(l, xz, h);
  return sigma;
}

// The light march's place: the next sample's distance `s` along the Sun and
// its length (0: it adds nothing). Own band first (n samples placed
// quadratically over `distance`), then n_above uniform samples over each
// band the Sun's ray crosses above band_top. s0, b, i_above: the march's
// state from the previous sample.
struct CloudLightState {
  float s0;
  int b, i_above;
  float depth, depth_above;
};

void CloudLightStep(IN(AtmosphereParameters) atm, vec2 xz, float h, float mu_s, vec3 sun, float band_top,
                    float distance, int n, int n_above, int j, bool nearest, inout CloudLightState st) {
  float r = atm.bottom_radius + h;
  float s, length_;
  bool own = j < n;
  if (own) {
    float u1 = float(j + 1) / float(n);
    float s1 = distance * u1 * u1;
    s = 0.5 * (st.s0 + s1);
    length_ = s1 - st.s0;
    st.s0 = s1;
  } else {
    float lo = gpu_clouds.bands[st.b].x, hi = gpu_clouds.bands[st.b].y;
    float s_lo = CloudRayToAltitude(atm, r, h, mu_s, lo, 1.0);
    float s_hi = CloudRayToAltitude(atm, r, h, mu_s, hi, 1.0);
    float ds = (s_hi - s_lo) / float(n_above);
    s = s_lo + (float(st.i_above) + 0.5) * ds;
    // A band below the sample's own (or the own one) adds nothing.
    length_ = lo < band_top ? 0.0 : ds;
    if (++st.i_above == n_above) {
      st.i_above = 0;
      ++st.b;
    }
  }
  float sigma = length_ > 0.0
                    ? CloudLightExtinction(xz + s * sun.xz, AltitudeAlongRay(atm, r, h, mu_s, s), nearest) * length_
                    : 0.0;
  if (own) st.depth += sigma;
  else st.depth_above += sigma;
}

// ---------------------------------------------------------------- the light volume

// The light volume (clouds.h, CloudLightVolume): columns i, j along world x
// and z of the band's bottom, each holding `slices` floats in the noise
// buffer, slice k at the altitude k / (slices - 1) through the band.
int CloudLightVolumeColumns() { return gpu_clouds.light_volume.x; }
int CloudLightVolumeSlices() { return gpu_clouds.light_volume.y; }

// Column i's world coordinate (km) along its axis: L sinh(u), u uniform
// over [-U, U] with the first and last columns on the ends.
float CloudLightVolumeCoordinate(int i) {
  float last = float(max(CloudLightVolumeColumns() - 1, 1));
  return gpu_clouds.light_volume_grid.x * sinh(gpu_clouds.light_volume_grid.y * (2.0 * float(i) / last - 1.0));
}

// The continuous column index of world coordinate x (clamped to the grid).
float CloudLightVolumeIndex(float x) {
  float last = float(max(CloudLightVolumeColumns() - 1, 1));
  float u = asinh(x / gpu_clouds.light_volume_grid.x) / gpu_clouds.light_volume_grid.y;
  return clamp(0.5 * (u + 1.0) * last, 0.0, last);
}

// The light march's own distance toward the Sun from altitude h in a band of
// top `band_top`, mu_s the Sun's cosine zenith there (CloudOpticalDepthToSun).
const float kCloudLightDistanceKm = 8.0;
float CloudLightDistance(float h, float mu_s, float band_top) {
  float reach = (band_top - h) / max(mu_s, 0.1);
  return min(max(reach, 0.05), kCloudLightDistanceKm);
}

// Distance along the column of foot radius rb (altitude `bottom`, the Sun's
// cosine zenith mu there) to altitude H, ascending.
float CloudLightColumnDistance(IN(AtmosphereParameters) atm, float rb, float bottom, float mu, float H) {
  return CloudRayToAltitude(atm, rb, bottom, mu, H, 1.0);
}

// Column (i, j) of the light volume (CLOUD_PASS_LIGHT_VOLUME): the cloud's
// optical depth (without the detail erosion, nearest-voxel reads as the
// exact march's far samples: a slice interval is about a voxel long) from the
// column's foot up to each slice, light_volume_grid.z samples per slice
// interval; then, in place, each slice's depth over the light march's
// distance from it (CloudLightDistance), to the band's top at most: the
// cumulative depth there less the slice's own, linear between slices.
// The samples whose bound says no cloud (CloudMargin) are skipped as the
// view march skips them (their density is 0): an inner loop finds the next
// sample with cloud, since lavapipe runs an `if` masked, so each interval's
// depth is summed in its slice first and the slices made cumulative after.
void ComputeCloudLightColumn(IN(AtmosphereParameters) atm, int i, int j, vec3 sun) {
  int n = CloudLightVolumeSlices();
  int first = gpu_clouds.light_volume.w + (j * CloudLightVolumeColumns() + i) * n;
  float bottom = gpu_clouds.bands[0].x, top = gpu_clouds.bands[0].y;
  vec2 foot = vec2(CloudLightVolumeCoordinate(i), CloudLightVolumeCoordinate(j));
  float rb = atm.bottom_radius + bottom;
  float y = sqrt(max(rb * rb - dot(foot, foot), 0.0));
  float mu = dot(vec3(foot.x, y, foot.y), sun) / rb;
  const int substeps = CLOUD_LIGHT_VOLUME_SUBSTEPS;  // kCloudLightVolumeSubsteps (clouds.h)
  for (int k = 0; k < n; ++k) cloud_noise[first + k] = 0.0;
  int total = (n - 1) * substeps;
  // The interval being summed (its slice, 0: none yet) and its sum so far,
  // stored when the march moves on to the next interval with cloud: the
  // slices only grow along the column, so each is stored once.
  int slice = 0;
  float sum = 0.0;
  for (int next = 0; next < total;) {
    int m = next;
    vec2 xz = vec2(0.0);
    float h = 0.0, ds = 0.0;
    for (; m < total; ++m) {
      int k = m / substeps;  // the interval from slice k to k + 1
      float s0 = k == 0 ? 0.0 : CloudLightColumnDistance(atm, rb, bottom, mu, mix(bottom, top, float(k) / float(n - 1)));
      float s1 = CloudLightColumnDistance(atm, rb, bottom, mu, mix(bottom, top, float(k + 1) / float(n - 1)));
      ds = (s1 - s0) / float(substeps);
      float s = s0 + (float(m - k * substeps) + 0.5) * ds;
      xz = foot + s * sun.xz;
      h = AltitudeAlongRay(atm, rb, bottom, mu, s);
      if (CloudMargin(xz, h) > 0.0) break;
    }
    if (m >= total) break;
    next = m + 1;
    int k = 1 + m / substeps;
    if (k != slice) {
      if (slice > 0) cloud_noise[first + slice] = sum;
      slice = k;
      sum = 0.0;
    }
    sum += CloudLightExtinction(xz, h, true) * ds;
  }
  if (slice > 0) cloud_noise[first + slice] = sum;
  float depth = 0.0;
  for (int k = 1; k < n; ++k) {
    depth += cloud_noise[first + k];
    cloud_noise[first + k] = depth;
  }
  float s_top = CloudLightColumnDistance(atm, rb, bottom, mu, top);
  // The slice interval [k2, k2 + 1] that holds slice k's end; the ends do
  // not decrease with k, and no slice below k2 is read again.
  int k2 = 0;
  float s_lo = 0.0, s_hi = CloudLightColumnDistance(atm, rb, bottom, mu, mix(bottom, top, 1.0 / float(n - 1)));
  for (int k = 0; k < n; ++k) {
    float h_k = mix(bottom, top, float(k) / float(n - 1));
    float s_k = k == 0 ? 0.0 : CloudLightColumnDistance(atm, rb, bottom, mu, h_k);
    float mu_k = (rb * mu + s_k) / (atm.bottom_radius + h_k);
    float end = min(s_k + CloudLightDistance(h_k, mu_k, top), s_top);
    while (k2 < n - 2 && end > s_hi) {
      ++k2;
      s_lo = s_hi;
      s_hi = CloudLightColumnDistance(atm, rb, bottom, mu, mix(bottom, top, float(k2 + 1) / float(n - 1)));
    }
    float f = clamp((end - s_lo) / max(s_hi - s_lo, 1e-9), 0.0, 1.0);
    float d_end = mix(cloud_noise[first + k2], cloud_noise[first + k2 + 1], f);
    cloud_noise[first + k] = max(d_end - cloud_noise[first + k], 0.0);
  }
}

float CloudLightVolumeAt(int i, int j, int k) {
  return CloudNoise(gpu_clouds.light_volume.w + (j * CloudLightVolumeColumns() + i) * CloudLightVolumeSlices() + k);
}

// The optical depth toward the Sun from the point `s` along it from a view
// sample at (xz, h), mu_s the Sun's cosine zenith at the sample: the light
// volume read trilinearly at that point's column (traced back along the
// Sun to the band's bottom) and altitude.
float CloudLightVolumeDepth(IN(AtmosphereParameters) atm, vec2 xz, float h, float mu_s, vec3 sun, float s) {
  float r = atm.bottom_radius + h;
  float hq = AltitudeAlongRay(atm, r, h, mu_s, s);
  float rq = atm.bottom_radius + hq;
  float b = rq * ((r * mu_s + s) / rq);  // rq times the Sun's cosine zenith there
  float bottom = gpu_clouds.bands[0].x, top = gpu_clouds.bands[0].y;
  // Back along the Sun to the bottom: the smaller root of
  // back^2 - 2 b back + (rq^2 - rb^2) = 0, in the product form.
  float c = (hq - bottom) * (2.0 * atm.bottom_radius + hq + bottom);
  float back = c / max(b + sqrt(max(b * b - c, 0.0)), 1e-6);
  vec2 foot = xz + (s - back) * sun.xz;
  float x = CloudLightVolumeIndex(foot.x), z = CloudLightVolumeIndex(foot.y);
  int n = CloudLightVolumeSlices();
  float y = clamp((hq - bottom) / (top - bottom), 0.0, 1.0) * float(n - 1);
  int last = max(CloudLightVolumeColumns() - 2, 0);
  int x0 = min(int(x), last), z0 = min(int(z), last), y0 = min(int(y), n - 2);
  int x1 = min(x0 + 1, CloudLightVolumeColumns() - 1), z1 = min(z0 + 1, CloudLightVolumeColumns() - 1);
  float fx = x - float(x0), fz = z - float(z0), fy = y - float(y0);
  float a = mix(mix(CloudLightVolumeAt(x0, z0, y0), CloudLightVolumeAt(x1, z0, y0), fx),
                mix(CloudLightVolumeAt(x0, z1, y0), CloudLightVolumeAt(x1, z1, y0), fx), fz);
  float d = mix(mix(CloudLightVolumeAt(x0, z0, y0 + 1), CloudLightVolumeAt(x1, z0, y0 + 1), fx),
                mix(CloudLightVolumeAt(x0, z1, y0 + 1), CloudLightVolumeAt(x1, z1, y0 + 1), fx), fz);
  return max(mix(a, d, fy), 0.0);
}

// Optical depth (dimensionless) toward the Sun from a view sample, in two
// parts. Its own band: light_steps samples placed quadratically (dense near
// the sample) over the distance to the top of the band along the Sun, at
// most kCloudLightDistanceKm. The bands above (layers shadow each other: a
// deck above darkens the sunlight of the clouds below it): each band the
// Sun's ray crosses on its way up, min(light_steps, 4) uniform samples over
// the crossing (a band above is crossed whole). Both without the detail
// erosion. The first phase.w samples (the nearest the view sample) read the
// volumes trilinearly, the others the nearest voxel
// (quality.cloud_light_trilinear_steps). Two loops, each with one density
// call, their trip counts the samples there are: lavapipe inlines every
// call, never branches over an `if` (a block no lane takes still runs,
// masked; a per-sample choice of read would run both), and runs a loop's
// body at least once, so a loop per band (the four a one-band style does not
// have among them) cost four density reads per view sample for nothing.
// With the light volume (kCloudLightVolume, one band): the first
// light_volume.z samples, kCloudLightVolumeNearStepKm each (midpoints,
// trilinear), within `distance`, then the volume from where they end.
float CloudOpticalDepthToSun(IN(AtmosphereParameters) atm, vec2 xz, float h, float mu_s, vec3 sun, float band_top) {
  float distance = CloudLightDistance(h, mu_s, band_top);
  if (kCloudLightVolume) {
    int near_steps = gpu_clouds.light_volume.z;
    float near = min(distance, 0.1 * float(near_steps));  // kCloudLightVolumeNearStepKm
    float ds = near / float(max(near_steps, 1));
    float r = atm.bottom_radius + h;
    float depth = 0.0;
    for (int j = 0; j < near_steps; ++j) {
      float s = (float(j) + 0.5) * ds;
      depth += CloudLightExtinction(xz + s * sun.xz, AltitudeAlongRay(atm, r, h, mu_s, s), false) * ds;
    }
    return depth + CloudLightVolumeDepth(atm, xz, h, mu_s, sun, near);
  }
  int n = gpu_clouds.counts.z;
  int bands = gpu_clouds.resolution.w > 1 ? gpu_clouds.resolution.w : 0;
  int n_above = min(n, 4);
  int total = n + bands * n_above;
  int trilinear = min(int(gpu_clouds.phase.w), total);
  CloudLightState st = CloudLightState(0.0, 0, 0, 0.0, 0.0);
  for (int j = 0; j < trilinear; ++j)
    CloudLightStep(atm, xz, h, mu_s, sun, band_top, distance, n, n_above, j, false, st);
  for (int j = trilinear; j < total; ++j)
    CloudLightStep(atm, xz, h, mu_s, sun, band_top, distance, n, n_above, j, true, st);
  return bands > 1 ? st.depth + st.depth_above : st.depth;
}

// The ambient table at altitude h: the mean radiance of the sky above
// (`up`) and of what lies below (`down`).
void CloudAmbientRows(float h, out vec3 up, out vec3 down) {
  int rows = gpu_clouds.lut.w;
  float y = clamp(h / gpu_clouds.range.y, 0.0, 1.0) * float(rows - 1);
  int y0 = min(int(y), rows - 2);
  float f = y - float(y0);
  up = mix(CloudTable(CloudAmbientIndex(y0, 0)), CloudTable(CloudAmbientIndex(y0 + 1, 0)), f);
  down = mix(CloudTable(CloudAmbientIndex(y0, 1)), CloudTable(CloudAmbientIndex(y0 + 1, 1)), f);
}

// Mean incident radiance over the sphere at height fraction hf, the sky half
// occluded towards the cloud's base and the ground half towards its top
// (takram's height factor hf / 2 + 1 / 2).
vec3 CloudAmbient(vec3 up, vec3 down, float hf) { return 0.5 * up * (0.5 + 0.5 * hf) + 0.5 * down * (1.0 - 0.5 * hf); }

// ---------------------------------------------------------------- the march

struct CloudApTexel {
  int x0, x1, y0, y1;
  float fx, fy;
};

CloudApTexel CloudApTexelOf(vec3 view, vec3 sun) {
  float horizontal = length(vec2(view.x, view.z));
  float zenith = atan(horizontal, view.y);
  float cos_part = view.x * sun.x + view.z * sun.z;
  float sin_part = abs(view.x * sun.z - view.z * sun.x);
  float azimuth = (sin_part > 0.0 || cos_part != 0.0) ? atan(sin_part, cos_part) : 0.0;
  CloudApTexel t;
  float x = clamp(azimuth / kPi, 0.0, 1.0) * float(CloudApWidth() - 1);
  float y = clamp(zenith / kPi, 0.0, 1.0) * float(CloudApHeight() - 1);
  t.x0 = min(int(x), CloudApWidth() - 2);
  t.y0 = min(int(y), CloudApHeight() - 2);
  t.x1 = t.x0 + 1;
  t.y1 = t.y0 + 1;
  t.fx = x - float(t.x0);
  t.fy = y - float(t.y0);
  return t;
}

vec3 CloudApRead(IN(CloudApTexel) t, int k, int half_) {
  int o = half_ * CloudApTexels();
  vec3 a = mix(CloudTable(o + CloudApIndex(t.x0, t.y0, k)), CloudTable(o + CloudApIndex(t.x1, t.y0, k)), t.fx);
  vec3 b = mix(CloudTable(o + CloudApIndex(t.x0, t.y1, k)), CloudTable(o + CloudApIndex(t.x1, t.y1, k)), t.fx);
  return mix(a, b, t.fy);
}

// In-scattering (half 0) or transmittance (half 1) of the atmosphere from
// the viewer to distance t along the texel's direction.
vec3 CloudAerialPerspective(IN(CloudApTexel) texel, float t, int half_) {
  float s = sqrt(clamp(t / gpu_clouds.range.x, 0.0, 1.0)) * float(CloudApSlices()) - 1.0;
  vec3 at_zero = half_ == 0 ? vec3(0.0) : vec3(1.0);
  if (s < 0.0) return mix(at_zero, CloudApRead(texel, 0, half_), s + 1.0);
  int k0 = min(int(s), CloudApSlices() - 2);
  return mix(CloudApRead(texel, k0, half_), CloudApRead(texel, k0 + 1, half_), s - float(k0));
}

struct CloudMarch {
  vec3 radiance;        // clouds and the air in front of them, per unit solar irradiance
  float transmittance;  // of the clouds along the whole ray (grey)
};

// The tables along one segment of the view ray, read at its start, middle
// and end (nodes 0, 1, 2, at u = 0, 1/2, 1 of the segment) and interpolated
// per sample (CloudSegmentAir, CloudSegmentAt). Read per sample, the aerial
// perspective alone was 16 LUT texels (two slices of two bilinear halves)
// and the ambient 4 more at every view sample: lavapipe runs a sample's
// whole lighting, masked, whether or not it holds cloud.
// - The air's optical depth from the viewer, quadratic in u: its
//   transmittance is exp(-depth), and the depth is nearly linear in distance
//   where the transmittance is not.
// - The air's in-scattering: S(t) - S(t0) = the integral of T J over
//   [t0, t], = g (T(t0) - T(t)) with g = J / extinction where that ratio is
//   constant along the ray; g is taken linear in u through its values at
//   nodes 1 and 2 (exact for a uniform medium, where a polynomial in t is
//   not: S saturates as 1 - exp).
// - The ambient rows at the ray's altitude there, quadratic in u.
struct CloudSegmentTables {
  vec3 air_depth[3];
  vec3 air_inscatter[3];
  vec3 up[3];
  vec3 down[3];
  vec3 air_start;  // the air's transmittance at node 0
  vec3 g1, g2;     // g at nodes 1 and 2
};

void CloudSegmentNode(IN(AtmosphereParameters) atm, vec3 view, IN(CloudApTexel) ap, float t, int k,
                      inout CloudSegmentTables tables) {
  float r0 = atm.bottom_radius + atm.observer_altitude;
  tables.air_depth[k] = -log(max(CloudAerialPerspective(ap, t, 1), vec3(1e-30)));
  tables.air_inscatter[k] = CloudAerialPerspective(ap, t, 0);
  CloudAmbientRows(AltitudeAlongRay(atm, r0, atm.observer_altitude, view.y, t), tables.up[k], tables.down[k]);
}

// Lagrange weights of the nodes at u = 0, 1/2, 1.
vec3 CloudSegmentWeights(float u) { return vec3((1.0 - u) * (1.0 - 2.0 * u), 4.0 * u * (1.0 - u), u * (2.0 * u - 1.0)); }
vec3 CloudSegmentAt(vec3 v[3], vec3 w) { return max(v[0] * w.x + v[1] * w.y + v[2] * w.z, vec3(0.0)); }

// The segment's tables at its three distances.
CloudSegmentTables CloudSegmentRead(IN(AtmosphereParameters) atm, vec3 view, IN(CloudApTexel) ap, float t0, float t1) {
  CloudSegmentTables tables;
  CloudSegmentNode(atm, view, ap, t0, 0, tables);
  CloudSegmentNode(atm, view, ap, 0.5 * (t0 + t1), 1, tables);
  CloudSegmentNode(atm, view, ap, t1, 2, tables);
  tables.air_start = exp(-tables.air_depth[0]);
  tables.g1 = (tables.air_inscatter[1] - tables.air_inscatter[0]) /
              max(tables.air_start - exp(-tables.air_depth[1]), vec3(1e-6));
  tables.g2 = (tables.air_inscatter[2] - tables.air_inscatter[0]) /
              max(tables.air_start - exp(-tables.air_depth[2]), vec3(1e-6));
  return tables;
}

// The air's transmittance and in-scattering from the viewer at u.
void CloudSegmentAir(IN(CloudSegmentTables) tables, float u, vec3 w, out vec3 transmittance, out vec3 inscatter) {
  transmittance = exp(-CloudSegmentAt(tables.air_depth, w));
  vec3 g = max(mix(tables.g1, tables.g2, 2.0 * u - 1.0), vec3(0.0));
  inscatter = tables.air_inscatter[0] + g * max(tables.air_start - transmittance, vec3(0.0));
}

// The atmosphere's transmittance to the Sun along one segment of the view
// ray: its optical depth (the transmittance LUT's) at the segment's start,
// middle and end, quadratic in u between them as the air's tables above
// (CloudSegmentWeights); the visible fraction of the disc, which falls from
// 1 to 0 within a sample or two at the Earth's shadow, per sample. Read per
// sample, the LUT was 4 texels and its parametrisation at every view sample
// (lavapipe runs it, masked, whether or not the sample holds cloud).
struct CloudSunSegment {
  vec3 depth[3];
};

CloudSunSegment CloudSunSegmentRead(IN(AtmosphereParameters) atm, vec3 view, vec3 sun, float t0, float t1) {
  CloudSunSegment seg;
  float r0 = atm.bottom_radius + atm.observer_altitude;
  for (int k = 0; k < 3; ++k) {
    float t = mix(t0, t1, 0.5 * float(k));
    float h = AltitudeAlongRay(atm, r0, atm.observer_altitude, view.y, t);
    float r = atm.bottom_radius + h;
    float mu_s = dot(vec3(t * view.x, r0 + t * view.y, t * view.z), sun) / r;
    seg.depth[k] = -log(max(GetTransmittanceToTopBoundary(atm, r, h, ClampCosine(mu_s)), vec3(1e-30)));
  }
  return seg;
}

// The Sun's light at a sample (weights w of its u): the segment's
// transmittance times the visible fraction of the disc at (r, h, mu_s), as
// GetTransmittanceToSun.
vec3 CloudSunLight(IN(AtmosphereParameters) atm, IN(CloudSunSegment) seg, vec3 w, float r, float h, float mu_s) {
  float sin_theta_h = atm.bottom_radius / r;
  float cos_theta_h = -sqrt(max(h * (r + atm.bottom_radius), 0.0)) / r;
  float visible = smoothstep(-sin_theta_h * atm.sun_angular_radius, sin_theta_h * atm.sun_angular_radius,
                             mu_s - cos_theta_h);
  return exp(-CloudSegmentAt(seg.depth, w)) * visible;
}

// Marches the view ray through the part [t0, t1] of a band of thickness
// `band_thickness`: steps of a third of view_steps per thickness crossed,
// at most view_steps (a vertical crossing takes a third of them, a
// crossing near the horizon all).
void MarchCloudSegment(IN(AtmosphereParameters) atm, vec3 view, vec3 sun, IN(CloudApTexel) ap, float t0, float t1,
                       float band_top, float band_thickness, inout CloudMarch m) {
  if (t1 <= t0 || m.transmittance <= 0.0) return;
  float r0 = atm.bottom_radius + atm.observer_altitude;
  int max_steps = gpu_clouds.counts.y;
  float crossings = (t1 - t0) / band_thickness;
  int n = clamp(int(ceil(crossings * float(max_steps) / 3.0)), 1, max_steps);
  float dt = (t1 - t0) / float(n);
  float cos_theta = dot(view, sun);
  int octaves = gpu_clouds.counts.w;
  CloudSegmentTables tables = CloudSegmentRead(atm, view, ap, t0, t1);
  CloudSunSegment sun_segment = CloudSunSegmentRead(atm, view, sun, t0, t1);
  // Two loops: the inner one finds the ray's next sample with cloud (the
  // density alone), the outer one lights it. lavapipe runs a vector of 8
  // rays in lockstep and never branches over an `if`, so with one loop every
  // sample paid for the whole lighting, masked, when it held no cloud; now
  // the lighting runs once per lit sample of the vector's busiest ray.
  for (int next = 0; next < n;) {
    int i = next;
    float t = 0.0, h = 0.0, sigma_t = 0.0;
    vec2 xz = vec2(0.0);
    for (; i < n; ++i) {
      // Empty space first: the samples whose bound says no cloud (CloudMargin)
      // cost two loads each, not the density's twenty; the density is 0 there,
      // so the march is the same.
      for (; i < n; ++i) {
        t = t0 + (float(i) + 0.5) * dt;
        h = AltitudeAlongRay(atm, r0, atm.observer_altitude, view.y, t);
        xz = t * view.xz;
        if (CloudMargin(xz, h) > 0.0) break;
      }
      if (i >= n) break;
      sigma_t = CloudExtinction(xz, h, true);
      if (!(sigma_t <= 0.0)) break;
    }
    if (i >= n) break;
    next = i + 1;
    // The sample's local vertical and the Sun's cosine zenith there.
    vec3 p = vec3(xz.x, r0 + t * view.y, xz.y);
    float mu_s = dot(p, sun) / (atm.bottom_radius + h);
    float r = atm.bottom_radius + h;
    float u = (float(i) + 0.5) / float(n);
    vec3 w = CloudSegmentWeights(u);
    vec3 sun_light = kCloudSunLight ? CloudSunLight(atm, sun_segment, w, r, h, ClampCosine(mu_s)) : vec3(0.0);
    // The layer the sample is in decides albedo, the height factor and the
    // phase (overlapping layers: the first that has density there).
    float albedo = gpu_clouds.layers[0].shell.w;
    float hf = 0.5;
    bool ice = false;
    for (int l = 0; l < kCloudLayers; ++l) {
      GpuCloudLayer layer = gpu_clouds.layers[l];
      float f = (h - layer.shell.x) / (layer.shell.y - layer.shell.x);
      if (f > 0.0 && f < 1.0) {
        albedo = layer.shell.w;
        hf = f;
        ice = kCloudCirrus && layer.streaks.z > 0.0;
        break;
      }
    }
    vec3 scattered = vec3(0.0);
    if (kCloudSunLight && max(sun_light.x, max(sun_light.y, sun_light.z)) > 0.0) {
      float tau = CloudOpticalDepthToSun(atm, xz, h, mu_s, sun, band_top);
      // Wrenninge 2013: octave o scatters a^o of the light, sees b^o of the
      // optical depth and a phase of eccentricity c^o.
      float a = 1.0, b = 1.0, c = 1.0, sum = 0.0;
      for (int o = 0; o < octaves; ++o) {
        float phase = (kCloudCirrus && ice) ? IceCrystalPhase(cos_theta, c) : CloudPhase(cos_theta, c);
        sum += a * exp(-b * tau) * phase;
        a *= gpu_clouds.octave.x;
        b *= gpu_clouds.octave.y;
        c *= gpu_clouds.octave.z;
      }
      scattered = sun_light * sum;
    }
    vec3 source = albedo * (scattered + CloudAmbient(CloudSegmentAt(tables.up, w), CloudSegmentAt(tables.down, w), hf));
    // Hillaire 2016 section 5.6.3: the in-scattering integrated over the step
    // with the transmittance inside it, S (1 - exp(-sigma_t dt)) / sigma_t,
    // here with S = sigma_s J = albedo sigma_t J.
    float step_transmittance = exp(-sigma_t * dt);
    float absorbed = m.transmittance * (1.0 - step_transmittance);
    // The air between the viewer and the sample: the cloud's light through
    // its transmittance, and the air's own in-scattering in front of the
    // cloud where the cloud hides what lies behind.
    vec3 air_transmittance, air_inscatter;
    CloudSegmentAir(tables, u, w, air_transmittance, air_inscatter);
    m.radiance += (air_transmittance * source + air_inscatter) * absorbed;
    m.transmittance *= step_transmittance;
    // Early exit: what lies behind would add less than 1e-3 of itself; it
    // is dropped (transmittance 0), so a thick deck hides the sun disc.
    if (m.transmittance < 1e-3) {
      m.transmittance = 0.0;
      return;
    }
  }
}

// The clouds along `view`: every band the ray crosses, in order, before the
// ground and within range.x of the viewer. The segments are listed first and
// marched by one call site: lavapipe inlines every call, and one inlined march
// per band and branch made the shader eight marches long.
CloudMarch MarchClouds(IN(AtmosphereParameters) atm, vec3 view, vec3 sun) {
  CloudMarch m;
  m.radiance = vec3(0.0);
  m.transmittance = 1.0;
  CloudApTexel ap = CloudApTexelOf(view, sun);
  float h0 = atm.observer_altitude;
  float r0 = atm.bottom_radius + h0;
  float mu = ClampCosine(view.y);
  float t_far = gpu_clouds.range.x;
  int bands = gpu_clouds.resolution.w;
  // Segments in order along the ray: x, y the distances; z the band's top, w its thickness.
  vec4 segments[2 * kCloudLayers];
  int count = 0;
  // The descending branch (mu < 0): altitude falls to the perigee, or to
  // the ground.
  float t_perigee = 0.0;
  float h_perigee = h0;
  bool ground = false;
  if (mu < 0.0) {
    t_perigee = -r0 * mu;
    h_perigee = AltitudeAlongRay(atm, r0, h0, mu, t_perigee);
    ground = h_perigee <= 0.0;
    float t_end = ground ? CloudRayToAltitude(atm, r0, h0, mu, 0.0, -1.0) : t_perigee;
    for (int b = kCloudLayers - 1; b >= 0; --b) {
      if (b >= bands) continue;
      float lo = gpu_clouds.bands[b].x, hi = gpu_clouds.bands[b].y;
      if (h0 <= lo || h_perigee >= hi) continue;
      float ta = h0 > hi ? CloudRayToAltitude(atm, r0, h0, mu, hi, -1.0) : 0.0;
      float tb = h_perigee < lo ? CloudRayToAltitude(atm, r0, h0, mu, lo, -1.0) : t_end;
      segments[count++] = vec4(ta, min(min(tb, t_end), t_far), hi, hi - lo);
    }
  }
  if (!ground) {
    // The ascending branch, from the perigee (or the viewer) up.
    float t_start = max(t_perigee, 0.0);
    for (int b = 0; b < kCloudLayers; ++b) {
      if (b >= bands) continue;
      float lo = gpu_clouds.bands[b].x, hi = gpu_clouds.bands[b].y;
      if (hi <= h_perigee) continue;
      float ta = h_perigee < lo ? CloudRayToAltitude(atm, r0, h0, mu, lo, 1.0) : t_start;
      float tb = CloudRayToAltitude(atm, r0, h0, mu, hi, 1.0);
      segments[count++] = vec4(max(ta, t_start), min(tb, t_far), hi, hi - lo);
    }
  }
  for (int i = 0; i < count; ++i)
    MarchCloudSegment(atm, view, sun, ap, segments[i].x, segments[i].y, segments[i].z, segments[i].w, m);
  return m;
}

#endif  // SKYBAKE_CLOUDS_GLSL
