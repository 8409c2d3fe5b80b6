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
#include "cloud_shadow.glsl"

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
  // A latlong of the panorama's own size reads its own row: its own texel
  // where the row is whole, else along the row.
  vec4 c;
  if (push.view.x == MAPPING_LATLONG && push.view.y == push.rect.y && push.view.z == push.rect.z) {
    bool whole = CloudPanoramaRowWidth(push.rect.y, push.rect.z, texel.y) == push.rect.y;
    c = whole ? CloudPanoramaTexel(push.rect.x, push.rect.y, texel.y * push.rect.y + texel.x, texel.y)
              : CloudPanoramaRowRead(push.rect.x, push.rect.y, push.rect.z, texel.y,
                                     float(texel.x) / float(push.rect.y - 1));
  } else {
    c = CloudPanoramaRead(push.rect.x, push.rect.y, push.rect.z, ViewDirection(texel));
  }
  // The clouds' shadow on the ground below the horizon, per texel (cloud_shadow.glsl; off: 0).
  vec3 ground_loss = GroundCloudShadowLoss(AtmosphereFromUniform(), ViewDirection(texel), push.sun_direction.xyz);
  if (c.w == 1.0 && ground_loss == vec3(0.0)) return;  // the sky as the sky pass wrote it
  uint index = uint(push.offsets.x + texel.y * push.view.y + texel.x);
  vec4 sky = output_texels[index];
  if (ground_loss != vec3(0.0))
    sky.xyz = max(sky.xyz - ground_loss * gpu_atmosphere.solar_irradiance.xyz * gpu_atmosphere.output_scale.xyz, vec3(0.0));
  // max: the sky light the clouds scatter may lie outside the output's gamut (ComputeCloudAmbientRow).
  output_texels[index] = vec4(max(c.xyz * gpu_atmosphere.solar_irradiance.xyz * gpu_atmosphere.output_scale.xyz +
                                      c.w * sky.xyz, vec3(0.0)), sky.w);
}
