#version 450
#extension GL_GOOGLE_include_directive : require
// Transmittance LUT: one texel per (r, mu), Bruneton 2017 parametrisation.
#include "common.glsl"

void main() {
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  if (texel.x >= gpu_atmosphere.lut_sizes.x || texel.y >= gpu_atmosphere.lut_sizes.y) return;
  AtmosphereParameters atm = AtmosphereFromUniform();
  vec3 transmittance = ComputeTransmittanceLutTexel(atm, texel.x, texel.y);
  transmittance_texels[texel.y * gpu_atmosphere.lut_sizes.x + texel.x] = vec4(transmittance, 1.0);
}
