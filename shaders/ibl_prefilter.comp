#version 450
#extension GL_GOOGLE_include_directive : require
// Image-based lighting from the baked sky: one dispatch per output level.
// z of the global id is the cube face (+X -X +Y -Y +Z -Z, Vulkan face
// orientation); the DFG table is one 2D image (z = 0).
#include "glsl_prelude.glsl"
#include "skybake/gpu_shared.h"
#include "envmap.glsl"
#include "ibl.glsl"

layout(local_size_x = SKYBAKE_LOCAL_SIZE_X, local_size_y = SKYBAKE_LOCAL_SIZE_Y, local_size_z = 1) in;
layout(set = 0, binding = IBL_BINDING_SOURCE) uniform samplerCube source_cube;
layout(std430, set = 0, binding = IBL_BINDING_OUTPUT) buffer OutputTexels { vec4 output_texels[]; };
layout(push_constant) uniform Push { IblPush push; };

// The GGX prefilter of direction n from the level's sample table
// (GgxSampleEntry), `samples` entries from output_texels[first].
vec3 PrefilterWithTable(vec3 n, uint first, uint samples) {
  mat3 frame = FrameAround(n);
  vec3 sum = vec3(0.0);
  float weight = 0.0;
  for (uint i = 0u; i < samples; ++i) {
    vec4 entry = output_texels[first + i];
    if (entry.w < 0.0) continue;
    sum += textureLod(source_cube, frame * entry.xyz, entry.w).rgb * entry.z;
    weight += entry.z;
  }
  return weight > 0.0 ? sum / weight : vec3(0.0);
}

void main() {
  ivec3 id = ivec3(gl_GlobalInvocationID);
  int size = push.target.y;
  if (push.target.x == IBL_MODE_GGX_SAMPLES) {
    // One invocation per sample: x the sample index, y = z = 0.
    uint i = uint(id.y * size + id.x);
    if (id.x >= size || id.z != 0 || i >= uint(push.target.w)) return;
    output_texels[uint(push.target.z) + i] =
        GgxSampleEntry(i, uint(push.target.w), push.lobe.x, push.source.x, push.source.y, push.lobe.y);
    return;
  }
  if (id.x >= size || id.y >= size) return;
  uint samples = uint(push.target.w);
  uint index = uint(push.target.z + (id.z * size + id.y) * size + id.x);
  int mode = push.target.x;
  if (mode == IBL_MODE_DFG) {
    float n_dot_v = (float(id.x) + 0.5) / float(size);
    float roughness = (float(id.y) + 0.5) / float(size);
    output_texels[index] = vec4(IntegrateDfg(n_dot_v, roughness * roughness, samples), 0.0, 1.0);
    return;
  }
  vec3 n = DirectionFromVulkanCubeTexel(id.z, id.x, id.y, size);
  vec3 radiance;
  if (mode == IBL_MODE_SPECULAR) {
    radiance = push.lobe.x > 0.0 ? PrefilterWithTable(n, uint(push.source.z), samples) : textureLod(source_cube, n, 0.0).rgb;
    if (push.lobe.w != 0.0)
      radiance += SunThroughGgx(n, push.sun_direction.xyz, push.sun_irradiance.xyz, push.lobe.x, push.lobe.z);
    if (push.lobe.w != 0.0 && push.moon_irradiance.w != 0.0)
      radiance += SunThroughGgx(n, push.moon_direction.xyz, push.moon_irradiance.xyz, push.lobe.x, push.lobe.z);
  } else {
    radiance = FilterCosine(source_cube, n, samples, push.source.x, push.source.y, push.lobe.y);
    if (push.lobe.w != 0.0)
      radiance += push.sun_irradiance.xyz * (max(dot(n, push.sun_direction.xyz), 0.0) / kIblPi);
    if (push.lobe.w != 0.0 && push.moon_irradiance.w != 0.0)
      radiance += push.moon_irradiance.xyz * (max(dot(n, push.moon_direction.xyz), 0.0) / kIblPi);
  }
  output_texels[index] = vec4(radiance, 1.0);
}
