#version 450
#extension GL_GOOGLE_include_directive : require
// In-scattered radiance for every texel of one output view (latlong, cube
// strip, Vulkan cube face, or a list of directions).
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
  if (kSunDiscPass) {
    texel += push.rect.xy;
    if (texel.x >= push.rect.z || texel.y >= push.rect.w) return;
  } else if (push.rect.w > 0) {
    // One run of the view's rows, [rect.y, rect.w) (SkyRenderer::AddSkyRows).
    texel.y += push.rect.y;
    if (texel.y >= push.rect.w) return;
  }
  if (texel.x >= push.view.y || texel.y >= push.view.z) return;
  vec3 view = ViewDirection(texel);
  uint index = uint(push.offsets.x + texel.y * push.view.y + texel.x);
  if (kOutputDirection) {
    output_texels[index] = vec4(view, 0.0);
    return;
  }
  AtmosphereParameters atm = AtmosphereFromUniform();
  if (kSunDiscPass) {
    // Every branch costs every SIMD lane on lavapipe, so the disc's test and
    // transmittance read run here, on the few texels near the Sun, and not
    // in the sky pass (which then has the disc compiled out).
    vec3 sun = push.sun_direction.xyz;
    vec3 disc = SunDiscThroughAtmosphere(atm, view, sun) * atm.solar_irradiance;
    if (atm.night) disc *= 1.0 - NightDimmingWeight(atm, sun);
    output_texels[index].xyz += disc * gpu_atmosphere.output_scale.xyz;
    return;
  }
  // The sky alone (for the SH of the sky without the Sun): the disc switched
  // off per dispatch, so one pipeline serves both.
  if (push.offsets.y != 0) atm.sun_disc = false;
  AoasParameters aoas = AoasFromUniform();
  vec3 radiance = ComputeStyledSkyRadiance(atm, aoas, view, push.sun_direction.xyz, kUseSkyView);
  // A ray that meets the ground shows the sunlit ground, direct sunlight's
  // spectrum, through the air between: converted as direct sunlight
  // (colour_conversion.h); the air's own light along it is small from near
  // the ground (aerial perspective from altitude takes the same conversion).
  vec3 colour = atm.ground && SeesGround(atm, view) ? radiance * gpu_atmosphere.output_scale.xyz : SkyToOutput(radiance);
  // Colours outside the output's gamut (a deep twilight blue) are clamped to it.
  output_texels[index] = vec4(max(colour, vec3(0.0)), 1.0);
}
