#version 450
#extension GL_GOOGLE_include_directive : require
// The cloud shadow map (include/skybake/model/cloud_shadow.h): for every texel of
// a horizontal receiver plane, the transmittance of sunlight through every
// cloud layer along the sun direction, exp(-strength tau).
//
// Push constants (SkyPush): sun_direction.xyz towards the Sun, .w the
// strength (a multiplier of the optical depth); view.y = view.z the map's
// edge in texels, view.w the samples per band crossing; offsets.x the first
// output texel; rect the floats (bit patterns) x: world x of the map's west
// edge, y: world z of its north edge, z: texel edge, w: receiver altitude,
// all km. The optical depth and its flat geometry: shaders/cloud_shadow.glsl.
#include "common.glsl"
#include "clouds.glsl"
#include "cloud_shadow.glsl"

void main() {
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  int n = push.view.y;
  if (texel.x >= n || texel.y >= push.view.z) return;
  float west = intBitsToFloat(push.rect.x), north = intBitsToFloat(push.rect.y);
  float texel_km = intBitsToFloat(push.rect.z), receiver = intBitsToFloat(push.rect.w);
  // Row 0 is the north edge (most negative z), column 0 the west edge.
  vec2 xz = vec2(west + (float(texel.x) + 0.5) * texel_km, north + (float(texel.y) + 0.5) * texel_km);
  vec3 sun = push.sun_direction.xyz;
  float t = 0.0;  // the Sun's centre at or below the horizon: no direct sunlight
  if (sun.y > 0.0) t = exp(-push.sun_direction.w * CloudShadowOpticalDepth(xz, receiver, sun, push.view.w));
  output_texels[push.offsets.x + texel.y * n + texel.x] = vec4(t, t, t, 1.0);
}
