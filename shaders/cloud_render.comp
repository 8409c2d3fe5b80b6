#version 450
#extension GL_GOOGLE_include_directive : require
// The cloud pass: for every texel of one output view, after the sky and
// sun-disc passes wrote the clear sky there, the clouds in front of it and
// the sky behind them attenuated by the clouds' transmittance; or, with a
// panorama (cloud_panorama.glsl), the panorama's texels, which
// cloud_resample.comp then reads into every view.
#include "common.glsl"
#include "clouds.glsl"
#include "cloud_panorama.glsl"
#include "cloud_shadow.glsl"

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
  // The panorama's dispatch covers its marched rows only (cloud_panorama.glsl).
  // A row marches its own width of texels (CloudPanoramaRowWidth).
  int row_width = push.view.y;
  if (push.rect.w == CLOUD_MODE_PANORAMA) {
    texel.y = CloudPanoramaRowBlock(int(gl_WorkGroupID.y), int(gl_NumWorkGroups.y)) * SKYBAKE_LOCAL_SIZE_Y +
              int(gl_LocalInvocationID.y) + CloudPanoramaFirstRow();
    if (texel.y >= CloudPanoramaEndRow()) return;
    row_width = CloudPanoramaRowWidth(push.view.y, push.view.z, texel.y);
  }
  if (texel.x >= row_width || texel.y >= push.view.z) return;
  AtmosphereParameters atm = AtmosphereFromUniform();
  vec3 view = push.rect.w == CLOUD_MODE_PANORAMA
                  ? DirectionFromLatLongPixel(float(texel.x), float(texel.y), row_width, push.view.z)
                  : ViewDirection(texel);
  CloudMarch m = MarchClouds(atm, view, push.sun_direction.xyz);
  if (push.rect.w == CLOUD_MODE_PANORAMA) {
    cloud_lut[push.rect.x + texel.y * push.view.y + texel.x] = vec4(m.radiance, m.transmittance);
    return;
  }
  // The clouds' shadow on the ground below the horizon (cloud_shadow.glsl; off: 0).
  vec3 ground_loss = GroundCloudShadowLoss(atm, view, push.sun_direction.xyz);
  if (m.transmittance == 1.0 && ground_loss == vec3(0.0)) return;  // the sky as the sky pass wrote it
  uint index = uint(push.offsets.x + texel.y * push.view.y + texel.x);
  vec4 sky = output_texels[index];
  if (ground_loss != vec3(0.0))
    sky.xyz = max(sky.xyz - ground_loss * atm.solar_irradiance * gpu_atmosphere.output_scale.xyz, vec3(0.0));
  // max: the sky light the clouds scatter may lie outside the output's gamut (ComputeCloudAmbientRow).
  output_texels[index] = vec4(max(m.radiance * atm.solar_irradiance * gpu_atmosphere.output_scale.xyz +
                                      m.transmittance * sky.xyz, vec3(0.0)), sky.w);
}
