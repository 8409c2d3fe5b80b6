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

// The sum of L (n.l) over the entries of the level's sample table
// (GgxSampleEntry, `samples` entries from output_texels[first]) that grid
// `grid` holds (IblGridOf), around direction n; and in `weight` the sum of
// (n.l) over every entry above the horizon. The table is in order of
// growing mip (IBL_MODE_GGX_SAMPLES), the entries below the horizon last, so
// a grid's entries are one run of it, which IBL_MODE_GRID_RANGES wrote after
// the table: only the run's entries are read (a lookup skipped by a branch
// would still cost its time on a CPU device, which runs both sides of a
// branch).
vec3 PartialPrefilter(vec3 n, uint first, uint samples, int grid, out float weight) {
  vec4 range = output_texels[first + samples + uint(grid)];
  weight = range.z;
  mat3 frame = FrameAround(n);
  vec3 sum = vec3(0.0);
  for (uint i = uint(range.x); i < uint(range.y); ++i) {
    vec4 entry = output_texels[first + i];
    sum += textureLod(source_cube, frame * entry.xyz, entry.w).rgb * entry.z;
  }
  return sum;
}

// Grid k's sum bilinearly at texel (x, y) of `face` of a level of `size`
// texels. The grid of m = size / 2^k texels a face is stored with a border
// of one texel on every side ((m + 2)^2 a face, from output_texels[first]),
// its directions those of the face's plane continued, so every texel of the
// level interpolates within its own face.
vec3 GridSum(uint first, int size, int k, int face, int x, int y) {
  int m = size >> k, stride = m + 2;
  vec2 u = (vec2(x, y) + 0.5) / float(1 << k) - 0.5;
  ivec2 i0 = ivec2(floor(u));
  vec2 f = u - vec2(i0);
  uint base = first + uint(face * stride * stride + (i0.y + 1) * stride + i0.x + 1);
  vec3 a = output_texels[base].rgb, b = output_texels[base + 1u].rgb;
  vec3 c = output_texels[base + uint(stride)].rgb, d = output_texels[base + uint(stride) + 1u].rgb;
  return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}

// The GGX prefilter of texel (x, y) of `face`, direction n, of a level of
// `size` texels: its own samples' lookups plus each coarse grid's sum
// (first texel grids_first, grid after grid), over the weight.
vec3 PrefilterWithGrids(vec3 n, int face, int x, int y, int size, uint first, uint samples, uint grids_first) {
  float weight;
  vec3 sum = PartialPrefilter(n, first, samples, 0, weight);
  for (int k = 1; k <= IblGridCount(size); ++k) {
    sum += GridSum(grids_first, size, k, face, x, y);
    int stride = (size >> k) + 2;
    grids_first += uint(6 * stride * stride);
  }
  return weight > 0.0 ? sum / weight : vec3(0.0);
}

void main() {
  ivec3 id = ivec3(gl_GlobalInvocationID);
  int size = push.target.y;
  if (push.target.x == IBL_MODE_GGX_SAMPLES) {
    // One invocation per sample: x the sample index, y = z = 0. Sample i
    // goes to the slot of its rank by its second Hammersley coordinate: the
    // mip grows with it (a wider h, a smaller pdf) and the samples below the
    // horizon have the largest, so the table is in order of growing mip.
    uint i = uint(id.y * size + id.x), samples = uint(push.target.w);
    if (id.x >= size || id.z != 0 || i >= samples) return;
    float xi = RadicalInverseVdC(i);
    uint rank = 0u;
    for (uint j = 0u; j < samples; ++j) rank += RadicalInverseVdC(j) < xi ? 1u : 0u;
    output_texels[uint(push.target.z) + rank] =
        GgxSampleEntry(i, samples, push.lobe.x, push.source.x, push.source.y, push.lobe.y);
    return;
  }
  uint samples = uint(push.target.w);
  if (push.target.x == IBL_MODE_SPECULAR_GRID) {
    // Grid k of a level: (size + 2)^2 texels a face, the border included.
    int stride = size + 2, k = push.source.w;
    if (id.x >= stride || id.y >= stride) return;
    float weight;
    vec3 n = DirectionFromVulkanCubeTexel(id.z, id.x - 1, id.y - 1, size);
    output_texels[uint(push.target.z + (id.z * stride + id.y) * stride + id.x)] =
        vec4(PartialPrefilter(n, uint(push.source.z), samples, k, weight), 0.0);
    return;
  }
  if (push.target.x == IBL_MODE_GRID_RANGES) {
    // One invocation per grid k = 0 .. IBL_MAX_GRIDS of a level of `size`
    // texels: the run of the sorted table it holds, [x, y), and in z the
    // weight of the whole table (the sum of n.l above the horizon).
    if (id.x > IBL_MAX_GRIDS || id.y != 0 || id.z != 0) return;
    int level = findMSB(push.source.x) - findMSB(size), grids = IblGridCount(size);
    uint first = uint(push.source.z), begin = 0u, end = 0u;
    float weight = 0.0;
    for (uint i = 0u; i < samples; ++i) {
      vec4 entry = output_texels[first + i];
      bool valid = entry.w >= 0.0;
      int g = IblGridOf(entry.w, level, grids);
      weight += valid ? entry.z : 0.0;
      begin += valid && g < id.x ? 1u : 0u;
      end += valid && g <= id.x ? 1u : 0u;
    }
    output_texels[first + samples + uint(id.x)] = vec4(float(begin), float(end), weight, 0.0);
    return;
  }
  if (id.x >= size || id.y >= size) return;
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
    radiance = push.lobe.x > 0.0 ? PrefilterWithGrids(n, id.z, id.x, id.y, size, uint(push.source.z), samples,
                                                      uint(push.source.w))
                                 : textureLod(source_cube, n, 0.0).rgb;
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
