#version 450
#extension GL_GOOGLE_include_directive : require
// The cloud passes' tables, one kind per dispatch (CLOUD_PASS_* in
// SkyPush.view.x): the noise volumes and weather map of layer view.w (once
// per renderer, from the seed alone), and the aerial-perspective LUT and the
// ambient table (once per sun position), and the light volume (once per
// frame: the Sun and the wind).
#include "common.glsl"
#include "clouds.glsl"

void main() {
  ivec2 id = ivec2(gl_GlobalInvocationID.xy);
  int pass = push.view.x;
  if (pass == CLOUD_PASS_AERIAL) {
    if (id.x >= CloudApWidth() || id.y >= CloudApHeight()) return;
    ComputeCloudApColumn(AtmosphereFromUniform(), id.x, id.y, push.sun_direction.xyz);
    return;
  }
  if (pass == CLOUD_PASS_AMBIENT) {
    if (id.x >= gpu_clouds.lut.w || id.y > 0) return;
    ComputeCloudAmbientRow(AtmosphereFromUniform(), id.x, push.sun_direction.xyz);
    return;
  }
  if (pass == CLOUD_PASS_LIGHT_VOLUME) {
    if (id.x >= CloudLightVolumeColumns() || id.y >= CloudLightVolumeColumns()) return;
    ComputeCloudLightColumn(AtmosphereFromUniform(), id.x, id.y, push.sun_direction.xyz);
    return;
  }
  GpuCloudLayer layer = gpu_clouds.layers[push.view.w];
  uint seed = uint(layer.noise.w);
  if (pass == CLOUD_PASS_WEATHER) {
    int n = gpu_clouds.resolution.z;
    if (id.x >= n || id.y >= n) return;
    cloud_noise[layer.noise.z + id.y * n + id.x] = WeatherNoiseValue((vec2(id) + 0.5) / float(n), seed);
    return;
  }
  // Volumes: x along x, y over (y, z) rows.
  bool shape = pass == CLOUD_PASS_SHAPE;
  int n = shape ? gpu_clouds.resolution.x : gpu_clouds.resolution.y;
  if (id.x >= n || id.y >= n * n) return;
  vec3 x = (vec3(id.x, id.y % n, id.y / n) + 0.5) / float(n);
  int first = shape ? layer.noise.x : layer.noise.y;
  cloud_noise[first + id.y * n + id.x] = shape ? ShapeNoiseValue(x, seed) : DetailNoiseValue(x, seed);
}
