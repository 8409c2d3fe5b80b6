#version 450
#extension GL_GOOGLE_include_directive : require
// Multiple-scattering LUT (Hillaire 2020 section 5.5): one texel per
// (mu_s, altitude); reads the transmittance LUT.
#include "common.glsl"

void main() {
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  if (texel.x >= gpu_atmosphere.lut_sizes.z || texel.y >= gpu_atmosphere.lut_sizes.w) return;
  AtmosphereParameters atm = AtmosphereFromUniform();
  vec3 psi = ComputeMultipleScatteringLutTexel(atm, texel.x, texel.y);
  multiscattering_texels[texel.y * gpu_atmosphere.lut_sizes.z + texel.x] = vec4(psi, 1.0);
}
