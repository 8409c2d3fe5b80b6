#version 450
#extension GL_GOOGLE_include_directive : require
// The cloud pass of one view from the cloud panorama (cloud_panorama.glsl):
// the clouds' radiance and transmittance read back, the sky the sky and
// sun-disc passes wrote attenuated by them. A shader of its own: the march
// shader's per-texel cost (0.6 us on lavapipe even for a texel it leaves at
// once) would be most of a read.
#include "common.glsl"
#include "clouds.glsl"
#include "cloud_panorama.glsl"

vec3 ViewDirection(ivec2 texel) {
  int mapping = push.view.x;
  if (mapping == MAPPING_LATLONG)
    return DirectionFromLatLongPixel(float(texel.x), float(texel.y), push.view.y, push.view.z);
  if (mapping == MAPPING_CUBE_STRIP) return DirectionFromCubeStripPixel(texel.x, texel.y, push.view.y);
  return DirectionFromVulkanCubeTexel(push.view.w, texel.x, texel.y, push.view.y);
}

void main() {
  ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
  if (texel.x >= push.view.y || texel.y >= push.view.z) return;
  // A latlong of the panorama's own size reads its own texel.
  vec4 c = push.view.x == MAPPING_LATLONG && push.view.y == push.rect.y && push.view.z == push.rect.z
               ? CloudPanoramaTexel(push.rect.x, push.rect.y, texel.y * push.rect.y + texel.x, texel.y)
               : CloudPanoramaRead(push.rect.x, push.rect.y, push.rect.z, ViewDirection(texel));
  if (c.w == 1.0) return;  // no cloud along this texel: the sky as the sky pass wrote it
  uint index = uint(push.offsets.x + texel.y * push.view.y + texel.x);
  vec4 sky = output_texels[index];
  output_texels[index] = vec4(c.xyz * gpu_atmosphere.solar_irradiance.xyz * gpu_atmosphere.output_scale.xyz +
                                  c.w * sky.xyz, sky.w);
}
