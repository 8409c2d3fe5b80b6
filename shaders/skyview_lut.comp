#version 450
#extension GL_GOOGLE_include_directive : require
// Sky-view LUT (Hillaire 2020 section 5.3) for the current Sun: one texel per
// (azimuth from the Sun, zenith angle); reads the transmittance and
// multiple-scattering LUTs.
#include "common.glsl"

void main() {
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  if (texel.x >= gpu_atmosphere.render.y || texel.y >= gpu_atmosphere.render.z) return;
  AtmosphereParameters atm = AtmosphereFromUniform();
  vec3 radiance = ComputeSkyViewLutTexel(atm, texel.x, texel.y, push.sun_direction.y);
  skyview_texels[texel.y * gpu_atmosphere.render.y + texel.x] = PackSkyViewTexel(radiance);
}
