// Image-based lighting: the source mip chain on the CPU, the GGX and cosine
// filtering on the Vulkan device (shaders/ibl_prefilter.comp). The files:
// output/ibl_files.cc.
#include "skybake/gpu/ibl.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "skybake/model/envmap.h"
#include "skybake/model/sh.h"

#include "shaders/kIblPrefilterSpv.spv.h"

namespace skybake {
namespace {

int Log2(int power_of_two) {
  int l = 0;
  while ((2 << l) <= power_of_two) ++l;
  return l;
}

}  // namespace

std::vector<float> StackFaces(const CubeLevel& level) {
  std::vector<float> stacked;
  stacked.reserve(size_t(level.size) * level.size * 4 * 6);
  for (const std::vector<float>& face : level.faces) stacked.insert(stacked.end(), face.begin(), face.end());
  return stacked;
}

int IblLevelCount(const IblSettings& settings) {
  if (settings.levels > 0) return settings.levels;
  return std::max(1, Log2(settings.size) - 2);  // down to 8 x 8
}

int IblLevelSamples(const IblSettings& s, double roughness) {
  if (s.full_samples_roughness <= 0.0) return s.samples;
  const double wanted = std::ceil(s.samples * roughness / s.full_samples_roughness);
  return int(std::clamp(wanted, double(std::min(16, s.samples)), double(s.samples)));
}

double IblRoughness(int level, int levels) { return levels > 1 ? double(level) / double(levels - 1) : 0.0; }

// W = integral over n.l > 0 of (n.l) D(h) / 4 dl with v = n. With l the
// reflection of n about h, dl = 4 (v.h) dh = 4 (n.h) dh and n.l = 2 c^2 - 1
// for c = n.h, so W = 2 pi integral_{1/sqrt2}^{1} (2 c^2 - 1) D(c) c dc.
// With u = c^2 and D = a^2 / (pi (1 + u b)^2), b = a^2 - 1:
//   W = a^2 integral_{1/2}^{1} (2u - 1) / (1 + u b)^2 du
//     = a^2 / b^2 [2 ln q + (2 + b) / q] from q = 1 + b/2 to q = 1 + b.
// At a = 1 (b = 0) D is uniform, 1 / pi, and W = 1/4.
double IblSunKernelNormalization(double alpha) {
  const double a2 = alpha * alpha;
  const double b = a2 - 1.0;
  if (std::abs(b) < 1e-4) {
    // Near b = 0 the closed form cancels; integrate by the midpoint rule
    // (the integrand is smooth there).
    double sum = 0.0;
    const int n = 4096;
    for (int i = 0; i < n; ++i) {
      double u = 0.5 + 0.5 * (i + 0.5) / n;
      double q = 1.0 + u * b;
      sum += (2.0 * u - 1.0) / (q * q);
    }
    return a2 * sum * 0.5 / n;
  }
  auto f = [&](double q) { return 2.0 * std::log(q) + (2.0 + b) / q; };
  return a2 / (b * b) * (f(1.0 + b) - f(1.0 + 0.5 * b));
}

CubeLevel DownsampleCube(const CubeLevel& level) {
  CubeLevel down;
  down.size = std::max(1, level.size / 2);
  const int n = level.size;
  for (int face = 0; face < 6; ++face) {
    const std::vector<float>& src = level.faces[face];
    std::vector<float>& dst = down.faces[face];
    dst.assign(size_t(down.size) * down.size * 4, 0.0f);
    for (int y = 0; y < down.size; ++y)
      for (int x = 0; x < down.size; ++x)
        for (int c = 0; c < 4; ++c) {
          auto at = [&](int sx, int sy) {
            return src[(size_t(std::min(sy, n - 1)) * n + std::min(sx, n - 1)) * 4 + c];
          };
          dst[(size_t(y) * down.size + x) * 4 + c] =
              0.25f * (at(2 * x, 2 * y) + at(2 * x + 1, 2 * y) + at(2 * x, 2 * y + 1) + at(2 * x + 1, 2 * y + 1));
        }
  }
  return down;
}

CubeTexel VulkanCubeTexelFromDirection(const glm::dvec3& d, int face_size) {
  const double ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
  int face;
  double sc, tc, ma;
  if (ax >= ay && ax >= az) {
    face = d.x >= 0 ? 0 : 1;
    sc = d.x >= 0 ? -d.z : d.z;
    tc = -d.y;
    ma = ax;
  } else if (ay >= az) {
    face = d.y >= 0 ? 2 : 3;
    sc = d.x;
    tc = d.y >= 0 ? d.z : -d.z;
    ma = ay;
  } else {
    face = d.z >= 0 ? 4 : 5;
    sc = d.z >= 0 ? d.x : -d.x;
    tc = -d.y;
    ma = az;
  }
  auto texel = [&](double v) {
    return std::clamp(int(std::floor((v / ma + 1.0) * 0.5 * face_size)), 0, face_size - 1);
  };
  return {face, texel(sc), texel(tc)};
}

// --------------------------------------------------------------- the device pass

namespace {

// One dispatch of the filter: a specular level or one of its coarse grids,
// the irradiance cube or the DFG table, written from output texel
// `first_texel` on.
struct Pass {
  int mode, size, level;
  VkDeviceSize first_texel;
  VkDeviceSize table_first = 0;  // IBL_MODE_SPECULAR(_GRID): the first entry of the level's sample table
  VkDeviceSize grids_first = 0;  // IBL_MODE_SPECULAR: the first texel of its coarse grids
  int grid = 0;                  // IBL_MODE_SPECULAR_GRID: k, the grid 2^k texels of the level apart
};

// The passes a request asks for, in the order they are recorded, and the
// output buffer's size in texels (vec4).
struct IblPassList {
  std::vector<Pass> passes;
  VkDeviceSize texels = 0;
};

// The number of coarse grids of a specular level of `size` texels (IblGridCount in ibl.glsl).
int GridCount(int size) { return std::clamp(Log2(size) - 1, 0, IBL_MAX_GRIDS); }

// Output texels: specular levels 1.. (level 0 is the source itself), the
// irradiance cube, the DFG table; then each specular level's GGX sample
// table (GgxSampleEntry, one vec4 a sample) and its coarse grids (IblGridOf
// in ibl.glsl; (size / 2^k + 2)^2 texels a face, a border included), in
// the same buffer. The grids are recorded first: the level's own pass adds
// them.
IblPassList PlanPasses(const IblSettings& s, bool dfg, int levels, const std::vector<double>& roughness) {
  IblPassList list;
  VkDeviceSize& texels = list.texels;
  if (s.specular)
    for (int level = 1; level < levels; ++level) {
      const int size = std::max(1, s.size >> level);
      list.passes.push_back({IBL_MODE_SPECULAR, size, level, texels});
      texels += VkDeviceSize(size) * size * 6;
    }
  if (s.irradiance) {
    list.passes.push_back({IBL_MODE_IRRADIANCE, s.irradiance_size, 0, texels});
    texels += VkDeviceSize(s.irradiance_size) * s.irradiance_size * 6;
  }
  if (dfg) {
    list.passes.push_back({IBL_MODE_DFG, s.dfg_size, 0, texels});
    texels += VkDeviceSize(s.dfg_size) * s.dfg_size;
  }
  std::vector<Pass> grids;
  for (Pass& p : list.passes) {
    if (p.mode != IBL_MODE_SPECULAR) continue;
    p.table_first = texels;  // the table, then its runs (IBL_MODE_GRID_RANGES)
    texels += VkDeviceSize(IblLevelSamples(s, roughness[p.level])) + IBL_MAX_GRIDS + 1;
    if (roughness[p.level] <= 0.0) continue;  // a copy of the source: no samples
    p.grids_first = texels;
    for (int k = 1; k <= GridCount(p.size); ++k) {
      const int m = p.size >> k;
      Pass grid{IBL_MODE_SPECULAR_GRID, m, p.level, texels, p.table_first};
      grid.grid = k;
      grids.push_back(grid);
      texels += VkDeviceSize(m + 2) * (m + 2) * 6;
    }
  }
  list.passes.insert(list.passes.begin(), grids.begin(), grids.end());
  return list;
}

// Source mip chain down to 1 x 1, box-filtered: what the filtered lookups read.
std::vector<CubeLevel> SourceMipChain(const CubeLevel& source) {
  std::vector<CubeLevel> chain{source};
  while (chain.back().size > 1) chain.push_back(DownsampleCube(chain.back()));
  return chain;
}

void CreateHostBuffer(VulkanContext& context, VkDeviceSize size, VkBufferUsageFlags usage, VkBuffer& buffer,
                      VkDeviceMemory& memory, void*& mapped) {
  VkDevice device = context.device();
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VK_CHECK(vkCreateBuffer(device, &info, nullptr, &buffer));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device, buffer, &req);
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = context.FindMemoryType(
      req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
      VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
  VK_CHECK(vkAllocateMemory(device, &alloc, nullptr, &memory));
  VK_CHECK(vkBindBufferMemory(device, buffer, memory, 0));
  VK_CHECK(vkMapMemory(device, memory, 0, VK_WHOLE_SIZE, 0, &mapped));
}

// A barrier on the whole of `buffer`: `src` writes made visible to `dst` reads.
void BufferBarrier(VkCommandBuffer cmd, VkBuffer buffer, VkAccessFlags src_access, VkPipelineStageFlags src_stage,
                   VkAccessFlags dst_access, VkPipelineStageFlags dst_stage) {
  VkBufferMemoryBarrier barrier{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
  barrier.srcAccessMask = src_access;
  barrier.dstAccessMask = dst_access;
  barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.buffer = buffer;
  barrier.size = VK_WHOLE_SIZE;
  vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 0, nullptr, 1, &barrier, 0, nullptr);
}

// A layout transition of every mip and face of `image`, ordering `src` before `dst`.
void ImageBarrier(VkCommandBuffer cmd, VkImage image, uint32_t mip_levels, VkImageLayout old_layout,
                  VkImageLayout new_layout, VkAccessFlags src_access, VkPipelineStageFlags src_stage,
                  VkAccessFlags dst_access, VkPipelineStageFlags dst_stage) {
  VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  barrier.srcAccessMask = src_access;
  barrier.dstAccessMask = dst_access;
  barrier.oldLayout = old_layout;
  barrier.newLayout = new_layout;
  barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = image;
  barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, mip_levels, 0, 6};
  vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 0, nullptr, 0, nullptr, 1, &barrier);
}

// One push-constant block and one dispatch of groups_x x groups_y x groups_z workgroups.
void PushAndDispatch(VkCommandBuffer cmd, VkPipelineLayout layout, const gpu::IblPush& push, uint32_t groups_x,
                     uint32_t groups_y, uint32_t groups_z) {
  vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
  vkCmdDispatch(cmd, groups_x, groups_y, groups_z);
}

uint32_t Groups(int invocations, int local_size) { return uint32_t((invocations + local_size - 1) / local_size); }

gpu::vec4 Vec4(const glm::dvec3& v, float w) { return {float(v.x), float(v.y), float(v.z), w}; }
gpu::vec4 Vec4(const Rgb& v, float w) { return {float(v[0]), float(v[1]), float(v[2]), w}; }

// Roughness 0 with ibl.include_sun: a point source's energy into the texel
// that holds its centre (a disc a fraction of a texel wide), E / the
// texel's solid angle.
void AddPointSource(CubeLevel& level, const glm::dvec3& direction, const Rgb& irradiance) {
  const CubeTexel t = VulkanCubeTexelFromDirection(direction, level.size);
  const double solid_angle = CubeTexelSolidAngle(t.x, t.y, level.size);
  float* texel = &level.faces[t.face][(size_t(t.y) * level.size + t.x) * 4];
  for (int c = 0; c < 3; ++c) texel[c] += float(irradiance[c] / solid_angle);
}

// The push constants of pass `p` of a bake of `request` from a source cube
// of `source_size` texels and `source_levels` mips.
gpu::IblPush PushFor(const IblRequest& request, const Pass& p, double roughness, int source_size,
                     uint32_t source_levels) {
  const IblSettings& s = request.settings;
  const double alpha = roughness * roughness;
  const bool specular = p.mode == IBL_MODE_SPECULAR || p.mode == IBL_MODE_SPECULAR_GRID;
  const int samples = specular                        ? IblLevelSamples(s, roughness)
                      : p.mode == IBL_MODE_IRRADIANCE ? s.irradiance_samples
                                                      : s.dfg_samples;
  gpu::IblPush push{};
  push.target = {p.mode, p.size, int32_t(p.first_texel), samples};
  push.source = {source_size, int32_t(source_levels), int32_t(p.table_first),
                 p.mode == IBL_MODE_SPECULAR_GRID ? p.grid : int32_t(p.grids_first)};
  push.lobe = {float(alpha), float(s.lod_bias),
               p.mode == IBL_MODE_SPECULAR ? float(IblSunKernelNormalization(alpha)) : 0.0f,
               s.include_sun ? 1.0f : 0.0f};
  push.sun_direction = Vec4(request.sun_direction, 0.0f);
  push.sun_irradiance = Vec4(request.sun_irradiance, 0.0f);
  push.moon_direction = Vec4(request.moon_direction, 0.0f);
  push.moon_irradiance = Vec4(request.moon_irradiance, request.moon ? 1.0f : 0.0f);
  return push;
}

const char* TimingName(int mode) {
  return mode == IBL_MODE_SPECULAR || mode == IBL_MODE_SPECULAR_GRID ? "IBL specular"
         : mode == IBL_MODE_IRRADIANCE                               ? "IBL irradiance"
                                                                     : "IBL DFG";
}

}  // namespace

IblBaker::IblBaker(VulkanContext& context) : context_(context) {
  VkDevice device = context_.device();
  try {
    VkFormatProperties format{};
    vkGetPhysicalDeviceFormatProperties(context_.physical_device(), VK_FORMAT_R32G32B32A32_SFLOAT, &format);
    const VkFormatFeatureFlags needed = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT |
                                        VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT |
                                        VK_FORMAT_FEATURE_TRANSFER_DST_BIT;
    if ((format.optimalTilingFeatures & needed) != needed)
      throw VulkanError(fmt::format("{} cannot sample filtered RGBA float cube maps, which the IBL pass needs: "
                                    "turn the ibl outputs off or choose another device",
                                    context_.device_info().name),
                        VK_ERROR_FORMAT_NOT_SUPPORTED);

    VkDescriptorSetLayoutBinding bindings[2] = {};
    bindings[0] = {IBL_BINDING_SOURCE, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_COMPUTE_BIT,
                   nullptr};
    bindings[1] = {IBL_BINDING_OUTPUT, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    const ComputeLayouts layouts = CreateComputeLayouts(device, bindings, 2, sizeof(gpu::IblPush));
    set_layout_ = layouts.set;
    pipeline_layout_ = layouts.pipeline;
    pipeline_ = CreateComputePipeline(device, kIblPrefilterSpv, sizeof(kIblPrefilterSpv), pipeline_layout_, nullptr,
                                      context_.pipeline_cache());

    // Trilinear, clamped at the face edges (Vulkan filters across cube faces).
    VkSamplerCreateInfo sampler_info{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    sampler_info.magFilter = VK_FILTER_LINEAR;
    sampler_info.minFilter = VK_FILTER_LINEAR;
    sampler_info.mipmapMode = VK_SAMPLER_MIPMAP_MODE_LINEAR;
    sampler_info.addressModeU = sampler_info.addressModeV = sampler_info.addressModeW =
        VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    sampler_info.maxLod = VK_LOD_CLAMP_NONE;
    VK_CHECK(vkCreateSampler(device, &sampler_info, nullptr, &sampler_));

    VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool_info.queueFamilyIndex = context_.queue_family();
    VK_CHECK(vkCreateCommandPool(device, &pool_info, nullptr, &command_pool_));

    timestamps_ = context_.SupportsTimestamps();
    if (timestamps_) {
      VkQueryPoolCreateInfo query_info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
      query_info.queryType = VK_QUERY_TYPE_TIMESTAMP;
      query_info.queryCount = kTimestampQueries;
      VK_CHECK(vkCreateQueryPool(device, &query_info, nullptr, &query_pool_));
    }
  } catch (...) {
    Release();
    throw;
  }
}

IblBaker::~IblBaker() { Release(); }

void IblBaker::Release() {
  VkDevice device = context_.device();
  if (query_pool_) vkDestroyQueryPool(device, query_pool_, nullptr);
  if (command_pool_) vkDestroyCommandPool(device, command_pool_, nullptr);
  if (sampler_) vkDestroySampler(device, sampler_, nullptr);
  if (pipeline_) vkDestroyPipeline(device, pipeline_, nullptr);
  if (pipeline_layout_) vkDestroyPipelineLayout(device, pipeline_layout_, nullptr);
  if (set_layout_) vkDestroyDescriptorSetLayout(device, set_layout_, nullptr);
  query_pool_ = VK_NULL_HANDLE;
  command_pool_ = VK_NULL_HANDLE;
  sampler_ = VK_NULL_HANDLE;
  pipeline_ = VK_NULL_HANDLE;
  pipeline_layout_ = VK_NULL_HANDLE;
  set_layout_ = VK_NULL_HANDLE;
}

// The per-call objects: the source cube image, the staging and output
// buffers, the descriptor set, the command buffer and its fence. Freed by
// the destructor whatever happens.
struct IblBaker::Resources {
  VkDevice device;
  VkCommandPool command_pool;
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory image_memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  uint32_t image_levels = 0;
  std::vector<VkBufferImageCopy> copies;  // staging -> image, one a source mip
  VkBuffer staging = VK_NULL_HANDLE, output = VK_NULL_HANDLE;
  VkDeviceMemory staging_memory = VK_NULL_HANDLE, output_memory = VK_NULL_HANDLE;
  void* staging_mapped = nullptr;
  void* output_mapped = nullptr;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  Resources(VkDevice d, VkCommandPool p) : device(d), command_pool(p) {}
  ~Resources() {
    if (cmd) vkFreeCommandBuffers(device, command_pool, 1, &cmd);
    if (fence) vkDestroyFence(device, fence, nullptr);
    if (pool) vkDestroyDescriptorPool(device, pool, nullptr);
    if (view) vkDestroyImageView(device, view, nullptr);
    if (image) vkDestroyImage(device, image, nullptr);
    if (image_memory) vkFreeMemory(device, image_memory, nullptr);
    if (staging) vkDestroyBuffer(device, staging, nullptr);
    if (staging_memory) vkFreeMemory(device, staging_memory, nullptr);
    if (output) vkDestroyBuffer(device, output, nullptr);
    if (output_memory) vkFreeMemory(device, output_memory, nullptr);
  }
};

// The source mip chain into a staging buffer, and the cube image (all its
// mips, six faces) the copies will fill.
void IblBaker::CreateSourceImage(Resources& r, const std::vector<CubeLevel>& chain) {
  VkDevice device = context_.device();
  VkDeviceSize staging_bytes = 0;
  for (const CubeLevel& level : chain) staging_bytes += VkDeviceSize(level.size) * level.size * 16 * 6;
  CreateHostBuffer(context_, staging_bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, r.staging, r.staging_memory,
                   r.staging_mapped);
  char* dst = static_cast<char*>(r.staging_mapped);
  VkDeviceSize offset = 0;
  r.image_levels = uint32_t(chain.size());
  for (uint32_t level = 0; level < r.image_levels; ++level) {
    const CubeLevel& l = chain[level];
    VkBufferImageCopy copy{};
    copy.bufferOffset = offset;
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, level, 0, 6};
    copy.imageExtent = {uint32_t(l.size), uint32_t(l.size), 1};
    r.copies.push_back(copy);
    for (const std::vector<float>& face : l.faces) {
      std::memcpy(dst + offset, face.data(), face.size() * sizeof(float));
      offset += face.size() * sizeof(float);
    }
  }

  VkImageCreateInfo image_info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  image_info.flags = VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT;
  image_info.imageType = VK_IMAGE_TYPE_2D;
  image_info.format = VK_FORMAT_R32G32B32A32_SFLOAT;
  image_info.extent = {uint32_t(chain[0].size), uint32_t(chain[0].size), 1};
  image_info.mipLevels = r.image_levels;
  image_info.arrayLayers = 6;
  image_info.samples = VK_SAMPLE_COUNT_1_BIT;
  image_info.tiling = VK_IMAGE_TILING_OPTIMAL;
  image_info.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  image_info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  image_info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VK_CHECK(vkCreateImage(device, &image_info, nullptr, &r.image));
  VkMemoryRequirements image_req;
  vkGetImageMemoryRequirements(device, r.image, &image_req);
  VkMemoryAllocateInfo image_alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  image_alloc.allocationSize = image_req.size;
  image_alloc.memoryTypeIndex =
      context_.FindMemoryType(image_req.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  VK_CHECK(vkAllocateMemory(device, &image_alloc, nullptr, &r.image_memory));
  VK_CHECK(vkBindImageMemory(device, r.image, r.image_memory, 0));
  VkImageViewCreateInfo view_info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  view_info.image = r.image;
  view_info.viewType = VK_IMAGE_VIEW_TYPE_CUBE;
  view_info.format = VK_FORMAT_R32G32B32A32_SFLOAT;
  view_info.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, r.image_levels, 0, 6};
  VK_CHECK(vkCreateImageView(device, &view_info, nullptr, &r.view));
}

// The host-visible output buffer of `texels` vec4, the descriptor set that
// binds it and the source cube, the command buffer and its fence.
void IblBaker::CreateOutputAndSet(Resources& r, VkDeviceSize texels) {
  VkDevice device = context_.device();
  const uint64_t max_range = context_.properties().limits.maxStorageBufferRange;
  if (texels * 16 > max_range)
    throw VulkanError(fmt::format("the IBL maps need {} MiB in one storage buffer; {} allows {} MiB: lower ibl.size",
                                  (texels * 16) >> 20, context_.device_info().name, max_range >> 20),
                      VK_ERROR_OUT_OF_DEVICE_MEMORY);
  CreateHostBuffer(context_, std::max<VkDeviceSize>(texels, 1) * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, r.output,
                   r.output_memory, r.output_mapped);

  VkDescriptorPoolSize pool_sizes[2] = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1},
                                        {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}};
  VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool_info.maxSets = 1;
  pool_info.poolSizeCount = 2;
  pool_info.pPoolSizes = pool_sizes;
  VK_CHECK(vkCreateDescriptorPool(device, &pool_info, nullptr, &r.pool));
  VkDescriptorSetAllocateInfo set_alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  set_alloc.descriptorPool = r.pool;
  set_alloc.descriptorSetCount = 1;
  set_alloc.pSetLayouts = &set_layout_;
  VK_CHECK(vkAllocateDescriptorSets(device, &set_alloc, &r.set));
  VkDescriptorImageInfo image_descriptor{sampler_, r.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  VkDescriptorBufferInfo buffer_descriptor{r.output, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet writes[2] = {};
  writes[0] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  writes[0].dstSet = r.set;
  writes[0].dstBinding = IBL_BINDING_SOURCE;
  writes[0].descriptorCount = 1;
  writes[0].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  writes[0].pImageInfo = &image_descriptor;
  writes[1] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  writes[1].dstSet = r.set;
  writes[1].dstBinding = IBL_BINDING_OUTPUT;
  writes[1].descriptorCount = 1;
  writes[1].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  writes[1].pBufferInfo = &buffer_descriptor;
  vkUpdateDescriptorSets(device, 2, writes, 0, nullptr);

  VkCommandBufferAllocateInfo cmd_alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cmd_alloc.commandPool = command_pool_;
  cmd_alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cmd_alloc.commandBufferCount = 1;
  VK_CHECK(vkAllocateCommandBuffers(device, &cmd_alloc, &r.cmd));
  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VK_CHECK(vkCreateFence(device, &fence_info, nullptr, &r.fence));
}

// Records the whole bake into r.cmd: the source upload, the sample tables,
// every filter pass (one push-constant block each, PushFor), timestamps
// around each run of passes of one mode.
// Returns the mode of each timestamp pair.
std::vector<int> IblBaker::RecordPasses(const Resources& r, const std::vector<gpu::IblPush>& passes) {
  VkCommandBuffer cmd = r.cmd;
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(cmd, &begin));
  if (timestamps_) vkCmdResetQueryPool(cmd, query_pool_, 0, kTimestampQueries);
  // The whole image to transfer-destination layout before the copy; the
  // copy's writes made visible to the compute shader's sampling.
  ImageBarrier(cmd, r.image, r.image_levels, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
               VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
  vkCmdCopyBufferToImage(cmd, r.staging, r.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, uint32_t(r.copies.size()),
                         r.copies.data());
  ImageBarrier(cmd, r.image, r.image_levels, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
               VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
               VK_ACCESS_SHADER_READ_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout_, 0, 1, &r.set, 0, nullptr);

  // The sample tables first (rows of 64 samples), then a barrier: the
  // specular passes read them.
  bool tables = false;
  for (gpu::IblPush push : passes) {
    if (push.target.x != IBL_MODE_SPECULAR) continue;
    const int width = 64, rows = (push.target.w + width - 1) / width;
    push.target.x = IBL_MODE_GGX_SAMPLES;
    push.target.y = width;
    push.target.z = push.source.z;
    PushAndDispatch(cmd, pipeline_layout_, push, Groups(width, SKYBAKE_LOCAL_SIZE_X),
                    Groups(rows, SKYBAKE_LOCAL_SIZE_Y), 1);
    tables = true;
  }
  if (tables) {
    BufferBarrier(cmd, r.output, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                  VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
    // Each table's runs, one per grid, then a barrier: every filter pass reads them.
    for (gpu::IblPush push : passes) {
      if (push.target.x != IBL_MODE_SPECULAR) continue;
      push.target.x = IBL_MODE_GRID_RANGES;
      PushAndDispatch(cmd, pipeline_layout_, push, 1, 1, 1);
    }
    BufferBarrier(cmd, r.output, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                  VK_ACCESS_SHADER_READ_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
  }

  // Passes write disjoint texels and read only the image and the tables,
  // but a specular level's own pass reads its coarse grids: one barrier
  // after the grids.
  int open_mode = -1;
  std::vector<int> modes;  // the mode of each timestamp pair
  for (const gpu::IblPush& push : passes) {
    const int mode = push.target.x, size = push.target.y;
    if (mode != open_mode) {
      if (timestamps_ && open_mode >= 0)
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, query_pool_, uint32_t(2 * modes.size() - 1));
      if (open_mode == IBL_MODE_SPECULAR_GRID)
        BufferBarrier(cmd, r.output, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      VK_ACCESS_SHADER_READ_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
      if (timestamps_) {
        modes.push_back(mode);
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, query_pool_, uint32_t(2 * modes.size() - 2));
      }
      open_mode = mode;
    }
    const uint32_t groups = Groups(mode == IBL_MODE_SPECULAR_GRID ? size + 2 : size, SKYBAKE_LOCAL_SIZE_X);
    PushAndDispatch(cmd, pipeline_layout_, push, groups, groups, mode == IBL_MODE_DFG ? 1 : 6);
  }
  if (timestamps_ && open_mode >= 0)
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, query_pool_, uint32_t(2 * modes.size() - 1));
  // The shader's writes made visible to the host's read-back.
  BufferBarrier(cmd, r.output, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                VK_ACCESS_HOST_READ_BIT, VK_PIPELINE_STAGE_HOST_BIT);
  VK_CHECK(vkEndCommandBuffer(cmd));
  return modes;
}

// The GPU time of each run of passes of one mode, from the timestamps.
void IblBaker::ReadTimings(const std::vector<int>& modes) {
  if (!timestamps_ || modes.empty()) return;
  std::vector<uint64_t> stamps(2 * modes.size());
  VK_CHECK(vkGetQueryPoolResults(context_.device(), query_pool_, 0, uint32_t(stamps.size()), stamps.size() * 8,
                                 stamps.data(), 8, VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  const double period_ms = context_.properties().limits.timestampPeriod * 1e-6;
  for (size_t i = 0; i < modes.size(); ++i)
    timings_.push_back({TimingName(modes[i]), double(stamps[2 * i + 1] - stamps[2 * i]) * period_ms});
}

namespace {

// The maps from the output buffer `out`: level 0 is the source (with the
// point sources when they go into the maps), the other levels, the
// irradiance cube and the DFG table as the passes wrote them.
IblMaps ReadMaps(const IblRequest& request, const CubeLevel& source, const std::vector<Pass>& passes,
                 const float* out) {
  IblMaps maps;
  auto read_cube = [&](const Pass& p) {
    CubeLevel level;
    level.size = p.size;
    const size_t face_floats = size_t(p.size) * p.size * 4;
    for (int face = 0; face < 6; ++face) {
      const float* begin = out + p.first_texel * 4 + face * face_floats;
      level.faces[face].assign(begin, begin + face_floats);
    }
    return level;
  };
  if (request.settings.specular) {
    maps.specular.push_back(source);
    if (request.settings.include_sun) {
      AddPointSource(maps.specular[0], request.sun_direction, request.sun_irradiance);
      if (request.moon) AddPointSource(maps.specular[0], request.moon_direction, request.moon_irradiance);
    }
  }
  for (const Pass& p : passes) {
    if (p.mode == IBL_MODE_SPECULAR) maps.specular.push_back(read_cube(p));
    if (p.mode == IBL_MODE_IRRADIANCE) maps.irradiance = read_cube(p);
    if (p.mode == IBL_MODE_DFG) {
      maps.dfg_size = p.size;
      const float* begin = out + p.first_texel * 4;
      maps.dfg.assign(begin, begin + size_t(p.size) * p.size * 4);
    }
  }
  return maps;
}

}  // namespace

IblMaps IblBaker::Bake(const IblRequest& request, const CubeLevel& source) {
  timings_.clear();
  const int levels = request.roughness.empty() ? IblLevelCount(request.settings) : int(request.roughness.size());
  std::vector<double> roughness = request.roughness;
  if (roughness.empty())
    for (int level = 0; level < levels; ++level) roughness.push_back(IblRoughness(level, levels));
  const IblPassList list = PlanPasses(request.settings, request.dfg, levels, roughness);

  Resources r(context_.device(), command_pool_);
  CreateSourceImage(r, SourceMipChain(source));
  CreateOutputAndSet(r, list.texels);
  std::vector<gpu::IblPush> pushes;
  for (const Pass& p : list.passes)
    pushes.push_back(PushFor(request, p, roughness[p.level], source.size, r.image_levels));
  const std::vector<int> modes = RecordPasses(r, pushes);
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &r.cmd;
  VK_CHECK(vkQueueSubmit(context_.queue(), 1, &submit, r.fence));
  VK_CHECK(vkWaitForFences(context_.device(), 1, &r.fence, VK_TRUE, UINT64_MAX));
  ReadTimings(modes);
  return ReadMaps(request, source, list.passes, static_cast<const float*>(r.output_mapped));
}

}  // namespace skybake
