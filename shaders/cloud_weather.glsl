// Where a cloud layer's density reads its noise (include/skybake/model/clouds.h,
// docs/clouds.md "Weather without repetition"), after the noise and sampling
// functions of clouds.glsl: the wind's offset, then a non-periodic domain
// warp of the horizontal position, then the coordinates of the weather map
// and of the shape and detail volumes.
//
// Why: the weather map is one tile of weather_size_m (30 km by default) and
// the shape volume one of shape_size_m (4 km); read directly they repeat,
// and a 120 km cloud shadow map shows a 4 x 4 grid of identical fields. Read
// through the warp they do not repeat at any distance:
// - the warp w(q) is gradient noise of the unwrapped integer lattice (its
//   hash never wraps), two octaves per axis: one of amplitude
//   kCloudWarpLargeAmplitude x P over cells of kCloudWarpLargeCell x P (P the
//   weather tile), which moves points one weather tile apart by different
//   amounts (a fraction of a tile, so the copies no longer line up), and one
//   of kCloudWarpSmallAmplitude x S over cells of kCloudWarpSmallCell x S (S
//   the shape tile), which does the same for the shape tiles within one
//   weather tile; the shape and detail volumes are read at q + w(q), so the
//   erosion stays with the shape;
// - the procedural weather is the mean of three reads of its map through the
//   warp: one at the tile P, one at kCloudWeatherSecondScale x P (the golden
//   ratio) turned by atan(3/4) (36.87 deg), one at kCloudWeatherThirdScale x P
//   (1 / sqrt 2) turned by -atan(5/12) (-22.62 deg). Scales of irrational
//   ratios and rotations of rational tangents make the three lattices
//   incommensurate: no shift moves two reads onto themselves, and a shift of
//   one read's tile repeats a third of the variance; the sum of the three
//   centred reads over sqrt 3 has one read's spread (coverage 0.5 still
//   covers about half);
// - a weather image (a placed map, weather_image) is read as it is: only its
//   shape is warped. A formation's volume is read as it is.
// Off (the layer's `tiling = true`, GpuCloudLayer.weather_origin.z = 0) every
// read is the tile's, as before: a shadow map of whole tiles wraps.
//
// Units: km, world x and z (East = +X, North = -Z).
#ifndef SKYBAKE_CLOUD_WEATHER_GLSL
#define SKYBAKE_CLOUD_WEATHER_GLSL

// The warp's octaves (fractions of the weather tile P and the shape tile S).
// The gradient noise below has a standard deviation of 0.18 per axis and an
// RMS slope of 0.72 per cell (measured over 1024^2 points of a numpy mirror),
// so the large octave moves a point by 0.21 P RMS (6.4 km of a 30 km tile),
// two points a tile apart or more differ by about 0.3 P, and its RMS slope is
// 0.29 (0.24 for the small octave, 0.11 S RMS): the map x + w(x) stretches
// the clouds by a few tens of percent and seldom folds.
const float kCloudWarpLargeAmplitude = 1.2;
const float kCloudWarpLargeCell = 3.0;
const float kCloudWarpSmallAmplitude = 0.6;
const float kCloudWarpSmallCell = 1.5;
const float kCloudWeatherSecondScale = 1.6180340;  // the golden ratio
const float kCloudWeatherThirdScale = 0.70710678;  // 1 / sqrt 2
const vec2 kCloudWeatherSecondOffset = vec2(0.3711, 0.7298);  // tile fractions: the reads start apart
const vec2 kCloudWeatherThirdOffset = vec2(0.6180, 0.1547);

// Two gradient-noise values of a point `f` within its cell from the corner at
// offset `o` (0 or 1 per axis): one 32-bit hash of the unwrapped cell (its
// coordinates times two odd constants, one CloudHash round: a quarter of
// CloudCellHash's cost, on every density sample) gives both channels'
// gradients, 8 bits per component in [-1, 1].
vec2 CloudWarpCorner(ivec2 cell, ivec2 o, uint seed, vec2 f) {
  ivec2 c = cell + o;
  uint h = CloudHash((uint(c.x) * 0x8da6b343u) ^ (uint(c.y) * 0xd8163841u) ^ seed);
  vec4 g = vec4(float(h & 255u), float((h >> 8) & 255u), float((h >> 16) & 255u), float(h >> 24)) / 127.5 - 1.0;
  vec2 d = f - vec2(o);
  return vec2(dot(g.xy, d), dot(g.zw, d));
}

// Two channels of 2D gradient noise (Perlin 2002's quintic fade) of the
// integer lattice, not wrapped: it never repeats. About [-0.7, 0.7].
vec2 CloudWarpNoise(vec2 p, uint seed) {
  vec2 base = floor(p);
  vec2 f = p - base;
  ivec2 c = ivec2(base);
  vec2 u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
  vec2 n00 = CloudWarpCorner(c, ivec2(0, 0), seed, f), n10 = CloudWarpCorner(c, ivec2(1, 0), seed, f);
  vec2 n01 = CloudWarpCorner(c, ivec2(0, 1), seed, f), n11 = CloudWarpCorner(c, ivec2(1, 1), seed, f);
  return mix(mix(n00, n10, u.x), mix(n01, n11, u.x), u.y);
}

// Where layer `layer` reads its noise at world (xz, h), km.
struct CloudPlace {
  vec2 q;           // the position the shape and detail read (wind and warp applied)
  vec2 weather_uv;  // the weather map (or image, or formation lattice), in tiles
  vec2 weather_uv2; // the second and third weather reads (non-repeating procedural weather only)
  vec2 weather_uv3;
  bool three_reads; // whether the weather is the three reads' combination (CloudWeatherOfReads)
};

CloudPlace CloudPlaceOf(GpuCloudLayer layer, vec2 xz, float h) {
  CloudPlace p;
  // Wind moves the whole layer (shear: more with height).
  vec2 q = xz - layer.wind_offset.xy - layer.wind_offset.zw * (h - layer.shell.x);
  // Cirrus: every read below in the frame squeezed along the streaks (cloud_cirrus.glsl).
  if (kCloudCirrus && layer.streaks.z > 0.0) q = CirrusStreakPosition(layer, q, h);
  p.weather_uv = (q - layer.weather_origin.xy) * layer.weather.yz;
  p.weather_uv2 = p.weather_uv;
  p.weather_uv3 = p.weather_uv;
  p.three_reads = false;
  p.q = q;
  float large_km = layer.weather_origin.z;
  if (large_km <= 0.0) return p;
  uint seed = CloudHash(uint(layer.noise.w) ^ 0x5bd1e995u);
  float small_km = 1.0 / layer.shape.y;
  vec2 warp_large = (kCloudWarpLargeAmplitude * large_km) * CloudWarpNoise(q / (kCloudWarpLargeCell * large_km), seed);
  vec2 warp_small = (kCloudWarpSmallAmplitude * small_km) *
                    CloudWarpNoise(q / (kCloudWarpSmallCell * small_km), seed ^ 0x27d4eb2fu);
  p.q = q + warp_large + warp_small;
  if (layer.weather_origin.w > 0.5) {
    vec2 qw = q + warp_large;
    p.weather_uv = (qw - layer.weather_origin.xy) * layer.weather.yz;
    // Turned by atan(3/4) (cos 0.8, sin 0.6) and by -atan(5/12) (cos 12/13, sin -5/13).
    vec2 turned2 = vec2(0.8 * qw.x - 0.6 * qw.y, 0.6 * qw.x + 0.8 * qw.y);
    vec2 turned3 = vec2(qw.x * (12.0 / 13.0) + qw.y * (5.0 / 13.0), qw.y * (12.0 / 13.0) - qw.x * (5.0 / 13.0));
    p.weather_uv2 = turned2 * (layer.weather.yz / kCloudWeatherSecondScale) + kCloudWeatherSecondOffset;
    p.weather_uv3 = turned3 * (layer.weather.yz / kCloudWeatherThirdScale) + kCloudWeatherThirdOffset;
    p.three_reads = true;
  }
  return p;
}

// The weather of three reads (each in [0, 1]): their centred sum over
// sqrt 3, one read's spread about the mean 1/2. Increasing in each, so the
// empty-space bound may take it of the reads' cell maxima.
float CloudWeatherOfReads(float a, float b, float c) { return clamp(0.5 + 0.57735027 * (a + b + c - 1.5), 0.0, 1.0); }

// The weather map read bilinearly (nearest: the texel that holds the point).
float CloudWeatherRead(GpuCloudLayer layer, vec2 uv, bool nearest) {
  return nearest ? SampleMapNearest(layer.noise.z, gpu_clouds.resolution.z, uv)
                 : SampleMap(layer.noise.z, gpu_clouds.resolution.z, uv);
}
float CloudWeatherAt(GpuCloudLayer layer, CloudPlace p, bool nearest) {
  float a = CloudWeatherRead(layer, p.weather_uv, nearest);
  if (!p.three_reads) return a;
  return CloudWeatherOfReads(a, CloudWeatherRead(layer, p.weather_uv2, nearest),
                             CloudWeatherRead(layer, p.weather_uv3, nearest));
}

// The shape volume's and the detail volume's coordinates at lift `lift` (km
// above the layer's bottom).
vec3 CloudShapeUvw(GpuCloudLayer layer, CloudPlace p, float lift) { return vec3(p.q.x, lift, p.q.y) * layer.shape.y; }
vec3 CloudDetailUvw(GpuCloudLayer layer, CloudPlace p, float lift) { return vec3(p.q.x, lift, p.q.y) * layer.shape.w; }

#endif  // SKYBAKE_CLOUD_WEATHER_GLSL
