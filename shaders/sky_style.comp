#version 450
#extension GL_GOOGLE_include_directive : require
// The spectral mode's style pass (SpectralSky): the principles that act on
// the colour of a texel (StyleSkyRadiance: the AOAS saturation clouds and
// shapes, the night floor), applied in place to the linear Rec.709 that the
// wavelength groups combined to. The output scale maps radiance to that
// colour, so the principles see the radiance the sky pass of the
// three-wavelength path would give them.
#include "common.glsl"

vec3 ViewDirection(ivec2 texel) {
  int mapping = push.view.x;
  if (mapping == MAPPING_LATLONG)
    return DirectionFromLatLongPixel(float(texel.x), float(texel.y), push.view.y, push.view.z);
  if (mapping == MAPPING_CUBE_STRIP) return DirectionFromCubeStripPixel(texel.x, texel.y, push.view.y);
  if (mapping == MAPPING_VULKAN_FACE)
    return DirectionFromVulkanCubeTexel(push.view.w, texel.x, texel.y, push.view.y);
  return normalize(output_texels[push.offsets.z + texel.y * push.view.y + texel.x].xyz);
}

void main() {
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  if (texel.x >= push.view.y || texel.y >= push.view.z) return;
  vec3 view = ViewDirection(texel);
  uint index = uint(push.offsets.x + texel.y * push.view.y + texel.x);
  AtmosphereParameters atm = AtmosphereFromUniform();
  AoasParameters aoas = AoasFromUniform();
  vec4 colour = output_texels[index];
  vec3 scale = gpu_atmosphere.output_scale.xyz;
  vec3 radiance = StyleSkyRadiance(atm, aoas, colour.xyz / scale, view, push.sun_direction.xyz);
  output_texels[index] = vec4(radiance * scale, colour.w);
}
