#include "skybake/gpu/sky_renderer.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <future>
#include <stdexcept>

#include <glm/geometric.hpp>
#include <sys/mman.h>

#include "shaders/kCloudLutSpv.spv.h"
#include "shaders/kCloudRenderSpv.spv.h"
#include "shaders/kCloudResampleSpv.spv.h"
#include "shaders/kMultiscatteringLutSpv.spv.h"
#include "shaders/kSkyRenderSpv.spv.h"
#include "shaders/kSkyStyleSpv.spv.h"
#include "shaders/kSkyviewLutSpv.spv.h"
#include "shaders/kTransmittanceLutSpv.spv.h"
#include "shaders/kMultiscatteringLutAnalyticSpv.spv.h"
#include "shaders/kSkyRenderSkyViewSpv.spv.h"
#include "shaders/kSkyRenderSkyViewTwilightSpv.spv.h"
#include "shaders/kSkyRenderSunDiscPassSpv.spv.h"
#include "shaders/kSkyviewLutAnalyticSpv.spv.h"
#include "shaders/kTransmittanceLutAnalyticSpv.spv.h"
#include "skybake/gpu/cloud_panorama.h"
#include "skybake/gpu/spectral_sky.h"
#include "skybake/model/shared_glsl.h"

namespace skybake {
namespace {

// Of the bindings of gpu_shared.h, the atmosphere, AOAS and cloud blocks are
// uniform buffers, the texel views uniform texel buffers and the rest storage
// buffers.
bool IsTexelView(uint32_t binding) {
  return binding >= BINDING_CLOUD_NOISE_TEXELS && binding < BINDING_CLOUD_NOISE_TEXELS + TEXEL_VIEW_COUNT;
}
VkDescriptorType BindingType(uint32_t binding) {
  if (binding == BINDING_ATMOSPHERE || binding == BINDING_AOAS || binding == BINDING_CLOUDS)
    return VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  if (IsTexelView(binding)) return VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
}

// Texels of the cloud tables: the aerial-perspective LUT's in-scattering and
// transmittance halves, then two per ambient altitude (clouds.glsl).
size_t CloudLutTexels(const gpu::GpuClouds& c) { return 2 * size_t(c.lut.x) * c.lut.y * c.lut.z + 2 * size_t(c.lut.w); }

uint32_t GroupCount(int texels, int local_size) { return uint32_t((texels + local_size - 1) / local_size); }

// The push constants of a dispatch over one view: the Sun and the view's
// mapping, size and face (the offsets are the caller's).
gpu::SkyPush ViewPush(const glm::dvec3& sun, const ViewRequest& v) {
  gpu::SkyPush push{};
  push.sun_direction = {float(sun.x), float(sun.y), float(sun.z), 0.0f};
  push.view = {v.mapping, v.width, v.height, v.face};
  return push;
}

}  // namespace

SkyRenderer::SkyRenderer(VulkanContext& context, const AtmosphereParams& atmosphere, const QualitySettings& quality,
                         const EffectSettings& effects, const Rgb& output_scale, bool output_directions,
                         const AoasInputs& aoas, const CloudInputs& clouds, const ShaderSwitches& shaders)
    : SkyRenderer(Role::kSky, context, atmosphere, quality, effects, output_scale, output_directions, aoas, clouds,
                  shaders) {}

std::unique_ptr<SkyRenderer> SkyRenderer::StylePass(VulkanContext& context, const AtmosphereParams& atmosphere,
                                                    const QualitySettings& quality, const EffectSettings& effects,
                                                    const Rgb& output_scale, const AoasInputs& aoas) {
  QualitySettings three = quality;
  three.wavelengths = kRgbWavelengths;
  return std::unique_ptr<SkyRenderer>(new SkyRenderer(Role::kStylePass, context, atmosphere, three, effects,
                                                      output_scale, false, aoas, CloudInputs(), ShaderSwitches()));
}

SkyRenderer::SkyRenderer(Role role, VulkanContext& context, const AtmosphereParams& atmosphere,
                         const QualitySettings& quality, const EffectSettings& effects, const Rgb& output_scale,
                         bool output_directions, const AoasInputs& aoas, const CloudInputs& clouds,
                         const ShaderSwitches& shaders)
    : context_(context),
      quality_(quality),
      effects_(effects),
      aoas_switches_(aoas.switches),
      output_directions_(output_directions),
      style_pass_(role == Role::kStylePass),
      shadowed_clouds_(shaders.shadowed_clouds),
      twilight_rows_(shaders.twilight_rows),
      texel_views_allowed_(shaders.texel_views),
      formation_read_always_(shaders.formation_read_always) {
  if (quality.wavelengths > kRgbWavelengths && !output_directions && !style_pass_) {
    spectral_ = std::make_unique<SpectralSky>(context, atmosphere, quality, effects, aoas, clouds, shaders);
    SyncSpectral();
    return;
  }
  gpu_atmosphere_ = ToGpuAtmosphere(atmosphere, quality, effects, output_scale);
  disc_pass_ = !output_directions && !style_pass_ && UsesSunDiscPass(quality, effects, aoas.switches, shaders);
  // Clouds (clouds.h): a style without layers gets no cloud pipeline, no
  // noise and no cloud pass; its buffers are placeholders.
  cloud_layers_ = output_directions || style_pass_ ? 0 : clouds.layers();
  gpu_clouds_ = clouds.uniform;
  cloud_weather_images_ = clouds.weather_images;

  // Every buffer a texel view reads (gpu_shared.h) is a texel buffer too.
  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  atmosphere_buffer_ = CreateBuffer(sizeof(gpu::GpuAtmosphere), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  std::memcpy(atmosphere_buffer_.mapped, &gpu_atmosphere_, sizeof(gpu_atmosphere_));
  aoas_buffer_ = CreateBuffer(sizeof(gpu::GpuAoas), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  std::memcpy(aoas_buffer_.mapped, &aoas.uniform, sizeof(gpu::GpuAoas));
  transmittance_buffer_ =
      CreateBuffer(VkDeviceSize(quality.transmittance_width) * quality.transmittance_height * 16, storage);
  multiscattering_buffer_ =
      CreateBuffer(VkDeviceSize(quality.multiscattering_size) * quality.multiscattering_size * 16, storage);
  output_buffer_ = CreateBuffer(16 * 64, storage);
  skyview_buffer_ = CreateBuffer(
      quality.sky_view_lut ? VkDeviceSize(quality.sky_view_width) * quality.sky_view_height * 8 : 16, storage);
  clouds_buffer_ = CreateBuffer(sizeof(gpu::GpuClouds), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  std::memcpy(clouds_buffer_.mapped, &gpu_clouds_, sizeof(gpu_clouds_));
  // The light volume (clouds.h, CloudLightVolume) after the noise.
  cloud_light_volume_ = cloud_layers_ > 0 && CloudLightVolumeOn(gpu_clouds_);
  cloud_formation_ = cloud_layers_ > 0 && CloudFormationRead(gpu_clouds_);
  cloud_cirrus_ = cloud_layers_ > 0 && CloudCirrusOn(gpu_clouds_);
  cloud_noise_buffer_ =
      CreateBuffer(cloud_layers_ > 0 ? VkDeviceSize(CloudNoiseFloats(gpu_clouds_) +
                                                    (cloud_light_volume_ ? CloudLightVolumeFloats(gpu_clouds_) : 0)) *
                                           4
                                     : 16,
                   storage);
  cloud_lut_buffer_ = CreateBuffer(cloud_layers_ > 0 ? VkDeviceSize(CloudLutTexels(gpu_clouds_)) * 16 : 16, storage);
  dispatch_buffer_ = CreateBuffer(64 * sizeof(gpu::SkyPush), storage);  // grown by Submit when a submission needs more
  // The shaders read through texel views, not the storage buffers (the same
  // values): lavapipe loads a storage buffer's value lane by lane, behind a
  // bounds test per lane, where a texel fetch is one gather for all lanes
  // (docs/performance.md). The views hold their whole ranges where the
  // device's texel buffers are large enough (lavapipe: 2^27 texels), which
  // only a noise of several 256^3 layers is not; else, or with
  // ShaderSwitches::texel_views off, each is a view of one texel, never read,
  // and the shaders read the storage buffers.
  texel_views_whole_ = texel_views_allowed_;
  for (int i = 0; i < TEXEL_VIEW_COUNT; ++i)
    texel_views_whole_ =
        texel_views_whole_ && TexelViewRange(i).texels <= context_.properties().limits.maxTexelBufferElements;
  for (int i = 0; i < TEXEL_VIEW_COUNT; ++i) CreateTexelView(i);

  CreateDescriptorSet();

  CompilePipelines(quality, effects, aoas.switches, shaders);
  CreateCommandObjects();
  timestamps_supported_ = context_.SupportsTimestamps();
}

void SkyRenderer::CompilePipelines(const QualitySettings& quality, const EffectSettings& effects,
                                   const AoasSwitches& aoas, const ShaderSwitches& shaders) {
  // Pipelines are built once per renderer, never per frame, and only those
  // the effects need. Compiling is most of a short bake's start-up on
  // lavapipe (LLVM), and pipeline creation may run on several threads at once
  // (the device is not externally synchronized for it): one thread each.
  struct PipelineJob {
    VkPipeline* pipeline;
    const uint32_t* code;
    size_t bytes;
    bool sun_disc = false;
    bool sun_disc_pass = false;
    bool cloud_light_volume = false;
  };
  // The variants built with the presets' settings fixed (CMakeLists.txt)
  // compile 10-20 times faster; they compute the same values to float
  // rounding (tests/gpu/sky_renderer_test.cc). shaders.generic turns them off,
  // to tell a variant's fault from the shader's.
  const ShaderSources sources = ChooseShaderSources(quality, aoas.skydome, shaders);
  const bool analytic = sources.analytic_luts;
  const bool sky_view = quality.sky_view_lut && !aoas.skydome;
  auto job = [this](VkPipeline* pipeline, bool variant, const auto& variant_code, const auto& generic_code) {
    if (variant) ++counters_.variant_pipelines;
    return variant ? PipelineJob{pipeline, variant_code, sizeof(variant_code)}
                   : PipelineJob{pipeline, generic_code, sizeof(generic_code)};
  };
  std::vector<PipelineJob> jobs;
  if (style_pass_) jobs.push_back({&style_pipeline_, kSkyStyleSpv, sizeof(kSkyStyleSpv)});
  else if (NeedsTransmittanceLut(quality, effects) || cloud_layers_ > 0)
    jobs.push_back(job(&transmittance_pipeline_, analytic, kTransmittanceLutAnalyticSpv, kTransmittanceLutSpv));
  if (effects.multiple_scattering && !style_pass_)
    jobs.push_back(job(&multiscattering_pipeline_, analytic, kMultiscatteringLutAnalyticSpv, kMultiscatteringLutSpv));
  if (sky_view && !style_pass_)
    jobs.push_back(job(&skyview_pipeline_, analytic, kSkyviewLutAnalyticSpv, kSkyviewLutSpv));
  if (!style_pass_) jobs.push_back(job(&sky_pipeline_, sources.sky_view_render, kSkyRenderSkyViewSpv, kSkyRenderSpv));
  sky_view_variant_ = sources.sky_view_render && !style_pass_;
  for (PipelineJob& j : jobs) j.sun_disc = effects.sun_disc;
  if (disc_pass_) {
    // The sky pass without the disc, and the disc pass that adds it.
    jobs.back().sun_disc = false;
    jobs.push_back(job(&disc_pipeline_, sources.sky_view_render, kSkyRenderSunDiscPassSpv, kSkyRenderSpv));
    jobs.back().sun_disc = true;
    jobs.back().sun_disc_pass = true;
  }
  if (cloud_layers_ > 0) {
    // Built from the analytic variant alone: their own marches of the air
    // use the analytic step whatever the style's integrator.
    jobs.push_back(job(&cloud_lut_pipeline_, true, kCloudLutSpv, kCloudLutSpv));
    jobs.push_back(job(&cloud_pipeline_, true, kCloudRenderSpv, kCloudRenderSpv));
    jobs.back().cloud_light_volume = cloud_light_volume_;
    jobs.push_back(job(&cloud_resample_pipeline_, true, kCloudResampleSpv, kCloudResampleSpv));
  }
  std::vector<std::future<VkPipeline>> compiled;
  for (const PipelineJob& job : jobs)
    compiled.push_back(std::async(std::launch::async, [this, job] {
      return CreatePipeline(job.code, job.bytes, job.sun_disc, job.sun_disc_pass, false, true, job.cloud_light_volume);
    }));
  std::exception_ptr failure;
  for (size_t i = 0; i < jobs.size(); ++i) {
    try {
      *jobs[i].pipeline = compiled[i].get();
      ++counters_.pipelines;
    } catch (...) {
      if (!failure) failure = std::current_exception();
    }
  }
  if (failure) {
    DestroyAll();
    std::rethrow_exception(failure);
  }
}

void SkyRenderer::CreateCommandObjects() {
  VkDevice device = context_.device();
  VkCommandPoolCreateInfo command_pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  command_pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  command_pool_info.queueFamilyIndex = context_.queue_family();
  VK_CHECK(vkCreateCommandPool(device, &command_pool_info, nullptr, &command_pool_));
  VkCommandBufferAllocateInfo cb_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cb_info.commandPool = command_pool_;
  cb_info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cb_info.commandBufferCount = 1;
  VK_CHECK(vkAllocateCommandBuffers(device, &cb_info, &command_buffer_));
  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VK_CHECK(vkCreateFence(device, &fence_info, nullptr, &fence_));
}

void SkyRenderer::CreateDescriptorSet() {
  VkDevice device = context_.device();
  VkDescriptorSetLayoutBinding bindings[kBindingCount] = {};
  for (uint32_t i = 0; i < kBindingCount; ++i) {
    bindings[i].binding = i;
    bindings[i].descriptorType = BindingType(i);
    bindings[i].descriptorCount = 1;
    bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  const ComputeLayouts layouts = CreateComputeLayouts(device, bindings, kBindingCount, sizeof(uint32_t));
  set_layout_ = layouts.set;
  pipeline_layout_ = layouts.pipeline;

  VkDescriptorPoolSize pool_sizes[3] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 3},
                                        {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, TEXEL_VIEW_COUNT},
                                        {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kBindingCount - 3 - TEXEL_VIEW_COUNT}};
  VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool_info.maxSets = 1;
  pool_info.poolSizeCount = 3;
  pool_info.pPoolSizes = pool_sizes;
  VK_CHECK(vkCreateDescriptorPool(device, &pool_info, nullptr, &descriptor_pool_));
  VkDescriptorSetAllocateInfo alloc_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  alloc_info.descriptorPool = descriptor_pool_;
  alloc_info.descriptorSetCount = 1;
  alloc_info.pSetLayouts = &set_layout_;
  VK_CHECK(vkAllocateDescriptorSets(device, &alloc_info, &descriptor_set_));
  UpdateDescriptors();
}

bool UsesSunDiscPass(const QualitySettings& quality, const EffectSettings& effects, const AoasSwitches& aoas,
                     const ShaderSwitches& shaders) {
  return shaders.sun_disc_pass && effects.sun_disc && quality.sky_view_lut && !aoas.skydome && !aoas.ambiguity &&
         !aoas.cloud_noise && !aoas.cloud_shapes;
}

std::vector<TexelRect> TexelsNearDirection(const ViewRequest& view, const glm::dvec3& direction, double angle) {
  if (view.mapping == MAPPING_DIRECTIONS) return {{0, 0, view.width, view.height}};
  constexpr int kTile = 16;
  auto angle_between = [](const glm::dvec3& a, const glm::dvec3& b) {
    // atan2 of |a x b| and a . b: accurate at small angles, unlike acos.
    return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
  };
  std::vector<TexelRect> rects;
  for (int ty = 0; ty < view.height; ty += kTile) {
    const int y1 = std::min(ty + kTile, view.height);
    int first = -1, last = -1;
    for (int tx = 0; tx < view.width; tx += kTile) {
      const int x1 = std::min(tx + kTile, view.width);
      const glm::dvec3 centre = ViewTexelDirection(view, (tx + x1 - 1) / 2, (ty + y1 - 1) / 2);
      double radius = 0.0;
      for (int corner = 0; corner < 4; ++corner) {
        const int x = corner & 1 ? x1 - 1 : tx;
        const int y = corner & 2 ? y1 - 1 : ty;
        radius = std::max(radius, angle_between(centre, ViewTexelDirection(view, x, y)));
      }
      if (angle_between(centre, direction) <= angle + 1.5 * radius) {
        if (first < 0) first = tx;
        last = x1;
      }
    }
    if (first >= 0) {
      // Joined with the row of tiles above when they span the same columns.
      if (!rects.empty() && rects.back().y1 == ty && rects.back().x0 == first && rects.back().x1 == last)
        rects.back().y1 = y1;
      else rects.push_back({first, ty, last, y1});
    }
  }
  return rects;
}

ShaderSources ChooseShaderSources(const QualitySettings& quality, bool skydome, const ShaderSwitches& shaders) {
  if (shaders.generic) return {};
  ShaderSources sources;
  sources.analytic_luts = quality.integrator == INTEGRATOR_ANALYTIC;
  sources.sky_view_render = quality.sky_view_lut && !skydome;
  return sources;
}

SkyRenderer::~SkyRenderer() {
  vkDeviceWaitIdle(context_.device());
  DestroyAll();
}

void SkyRenderer::DestroyAll() {
  VkDevice device = context_.device();
  if (query_pool_) vkDestroyQueryPool(device, query_pool_, nullptr);
  if (fence_) vkDestroyFence(device, fence_, nullptr);
  if (command_pool_) vkDestroyCommandPool(device, command_pool_, nullptr);
  for (VkPipeline* p :
       {&sky_pipeline_, &disc_pipeline_, &skyview_pipeline_, &multiscattering_pipeline_, &transmittance_pipeline_,
        &cloud_lut_pipeline_, &cloud_pipeline_, &cloud_resample_pipeline_, &cloud_shadow_pipeline_,
        &twilight_sky_pipeline_, &shadowed_cloud_pipeline_, &marched_light_cloud_pipeline_, &style_pipeline_}) {
    if (*p) vkDestroyPipeline(device, *p, nullptr);
    *p = VK_NULL_HANDLE;
  }
  query_pool_ = VK_NULL_HANDLE;
  fence_ = VK_NULL_HANDLE;
  command_pool_ = VK_NULL_HANDLE;
  vkDestroyDescriptorPool(device, descriptor_pool_, nullptr);
  vkDestroyPipelineLayout(device, pipeline_layout_, nullptr);
  vkDestroyDescriptorSetLayout(device, set_layout_, nullptr);
  descriptor_pool_ = VK_NULL_HANDLE;
  pipeline_layout_ = VK_NULL_HANDLE;
  set_layout_ = VK_NULL_HANDLE;
  DestroyBuffer(skyview_buffer_);
  DestroyBuffer(cloud_lut_buffer_);
  DestroyBuffer(dispatch_buffer_);
  for (VkBufferView& view : texel_views_) {
    vkDestroyBufferView(device, view, nullptr);
    view = VK_NULL_HANDLE;
  }
  DestroyBuffer(cloud_noise_buffer_);
  DestroyBuffer(clouds_buffer_);
  DestroyBuffer(output_buffer_);
  for (std::unique_ptr<FrameSlot>& slot : frame_slots_) DestroyBuffer(slot->buffer);
  frame_slots_.clear();
  DestroyBuffer(multiscattering_buffer_);
  DestroyBuffer(transmittance_buffer_);
  DestroyBuffer(aoas_buffer_);
  DestroyBuffer(atmosphere_buffer_);
}

namespace {

// Where each view's texels start in a buffer holding them all, in texels;
// `total` gets the texels of all.
std::vector<size_t> TexelOffsets(const std::vector<ViewRequest>& views, size_t& total) {
  std::vector<size_t> offsets;
  total = 0;
  for (const ViewRequest& v : views) {
    offsets.push_back(total);
    total += size_t(v.width) * v.height;
  }
  return offsets;
}

// Asks the kernel for 2 MiB pages behind a large mapping (transparent huge
// pages, where the system allows them on request). A CPU device's buffers
// are ordinary memory that the shaders touch first; a 4 KiB page fault cost
// about 12 us on the development VM (the 84 MB of a W1 frame: 250 ms of
// faults, 9 ms with huge pages). Advice only: an error (device memory, no
// huge pages) changes nothing.
void AdviseHugePages(void* mapped, VkDeviceSize size) {
  constexpr uintptr_t kHuge = uintptr_t(2) << 20;
  if (!mapped || size < 2 * kHuge) return;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(mapped) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(mapped) + uintptr_t(size)) & ~(kHuge - 1);
  if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
}

}  // namespace

SkyRenderer::TexelRange SkyRenderer::TexelViewRange(int i) const {
  switch (BINDING_CLOUD_NOISE_TEXELS + i) {
    case BINDING_CLOUD_NOISE_TEXELS:
      return {&cloud_noise_buffer_, VK_FORMAT_R32_SFLOAT, 4, cloud_noise_buffer_.size / 4};
    case BINDING_CLOUD_TABLE_TEXELS:  // the tables only: the panorama after them may outgrow a view
      return {&cloud_lut_buffer_, VK_FORMAT_R32G32B32A32_SFLOAT, 16,
              cloud_layers_ > 0 ? VkDeviceSize(CloudLutTexels(gpu_clouds_)) : 1};
    case BINDING_TRANSMITTANCE_TEXELS:
      return {&transmittance_buffer_, VK_FORMAT_R32G32B32A32_SFLOAT, 16, transmittance_buffer_.size / 16};
    case BINDING_MULTISCATTERING_TEXELS:
      return {&multiscattering_buffer_, VK_FORMAT_R32G32B32A32_SFLOAT, 16, multiscattering_buffer_.size / 16};
    default:
      return {&skyview_buffer_, VK_FORMAT_R32G32_UINT, 8, skyview_buffer_.size / 8};
  }
}

void SkyRenderer::CreateTexelView(int i) {
  vkDestroyBufferView(context_.device(), texel_views_[i], nullptr);
  const TexelRange r = TexelViewRange(i);
  VkBufferViewCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
  info.buffer = r.buffer->buffer;
  info.format = r.format;
  info.offset = 0;
  info.range = (texel_views_whole_ ? r.texels : 1) * r.texel_bytes;
  VK_CHECK(vkCreateBufferView(context_.device(), &info, nullptr, &texel_views_[i]));
}

SkyRenderer::Buffer SkyRenderer::CreateBuffer(VkDeviceSize size, VkBufferUsageFlags usage) {
  VkDevice device = context_.device();
  Buffer b;
  b.size = size;
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VK_CHECK(vkCreateBuffer(device, &info, nullptr, &b.buffer));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device, b.buffer, &req);
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  // Host-visible so results are read without a staging copy; cached memory
  // makes the read-back fast where the device offers it.
  alloc.memoryTypeIndex = context_.FindMemoryType(
      req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
      VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
  VkResult result = vkAllocateMemory(device, &alloc, nullptr, &b.memory);
  if (result != VK_SUCCESS) {
    vkDestroyBuffer(device, b.buffer, nullptr);
    throw VulkanError("cannot allocate " + std::to_string(size >> 20) + " MiB of Vulkan memory (" +
                          VkResultName(result) + "): lower render.cube_size or render.latlong_height",
                      result);
  }
  VK_CHECK(vkBindBufferMemory(device, b.buffer, b.memory, 0));
  VK_CHECK(vkMapMemory(device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped));
  AdviseHugePages(b.mapped, size);
  return b;
}

void SkyRenderer::DestroyBuffer(Buffer& b) {
  VkDevice device = context_.device();
  if (b.mapped) vkUnmapMemory(device, b.memory);
  if (b.buffer) vkDestroyBuffer(device, b.buffer, nullptr);
  if (b.memory) vkFreeMemory(device, b.memory, nullptr);
  // A new buffer may get the same handle: the binding must be written again.
  if (b.buffer != VK_NULL_HANDLE && b.buffer == bound_output_) bound_output_ = VK_NULL_HANDLE;
  b = Buffer{};
}

void SkyRenderer::EnsureCloudLutCapacity(size_t texels) {
  if (VkDeviceSize(texels) * 16 <= cloud_lut_buffer_.size) return;
  DestroyBuffer(cloud_lut_buffer_);
  cloud_lut_buffer_ = CreateBuffer(VkDeviceSize(texels) * 16,
                                   VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT);
  CreateTexelView(BINDING_CLOUD_TABLE_TEXELS - BINDING_CLOUD_NOISE_TEXELS);
  UpdateDescriptors();
  cloud_tables_ready_ = false;  // the new buffer holds no tables yet
}

void SkyRenderer::EnsureOutputCapacity(VkDeviceSize bytes) {
  if (bytes <= output_buffer_.size) return;
  DestroyBuffer(output_buffer_);
  output_buffer_ = CreateBuffer(bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  UpdateDescriptors();
}

void SkyRenderer::EnsureDispatchCapacity(size_t dispatches) {
  const VkDeviceSize bytes = VkDeviceSize(dispatches) * sizeof(gpu::SkyPush);
  if (bytes <= dispatch_buffer_.size) return;
  DestroyBuffer(dispatch_buffer_);
  dispatch_buffer_ = CreateBuffer(2 * bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  // Only this binding: the output binding may point at a frame slot.
  WriteStorageBinding(BINDING_DISPATCH, dispatch_buffer_.buffer);
}

void SkyRenderer::WriteStorageBinding(uint32_t binding, VkBuffer buffer) {
  const VkDescriptorBufferInfo info{buffer, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  write.dstSet = descriptor_set_;
  write.dstBinding = binding;
  write.descriptorCount = 1;
  write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  write.pBufferInfo = &info;
  vkUpdateDescriptorSets(context_.device(), 1, &write, 0, nullptr);
}

void SkyRenderer::UpdateDescriptors() {
  VkDescriptorBufferInfo infos[kBindingCount] = {
      {atmosphere_buffer_.buffer, 0, VK_WHOLE_SIZE},
      {transmittance_buffer_.buffer, 0, VK_WHOLE_SIZE},
      {multiscattering_buffer_.buffer, 0, VK_WHOLE_SIZE},
      {output_buffer_.buffer, 0, VK_WHOLE_SIZE},
      {skyview_buffer_.buffer, 0, VK_WHOLE_SIZE},
      {aoas_buffer_.buffer, 0, VK_WHOLE_SIZE},
      {clouds_buffer_.buffer, 0, VK_WHOLE_SIZE},
      {cloud_noise_buffer_.buffer, 0, VK_WHOLE_SIZE},
      {cloud_lut_buffer_.buffer, 0, VK_WHOLE_SIZE},
      {dispatch_buffer_.buffer, 0, VK_WHOLE_SIZE},
      {},
      {},
      {},
      {},
      {},  // the texel views
  };
  VkWriteDescriptorSet writes[kBindingCount] = {};
  for (uint32_t i = 0; i < kBindingCount; ++i) {
    writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[i].dstSet = descriptor_set_;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = BindingType(i);
    if (IsTexelView(i)) writes[i].pTexelBufferView = &texel_views_[i - BINDING_CLOUD_NOISE_TEXELS];
    else writes[i].pBufferInfo = &infos[i];
  }
  vkUpdateDescriptorSets(context_.device(), kBindingCount, writes, 0, nullptr);
  bound_output_ = output_buffer_.buffer;
}

void SkyRenderer::BindOutput(const Buffer& target) {
  if (target.buffer == bound_output_) return;
  WriteStorageBinding(BINDING_OUTPUT, target.buffer);
  bound_output_ = target.buffer;
}

bool SkyRenderer::MarchesTwilight(const glm::dvec3& sun) const { return MarchesTwilightBand(sun); }

bool SkyRenderer::MarchesTwilightBand(const glm::dvec3& sun) const {
  const double below = TwilightSunElevationDeg(quality_) * M_PI / 180.0;
  if (aoas_switches_.skydome || output_directions_ || !(below > 0.0) || !(sun.y < std::sin(below))) return false;
  // Texels that read the sky-view LUT march only along rays that see sunlit
  // air (TwilightMarchWeight); with the Sun too low for any, none does, and
  // the day pipeline gives the same values without the march's cost (on
  // lavapipe every branch of a shader runs, masked).
  if (!quality_.sky_view_lut) return true;
  return SunlitAirInView(std::asin(std::clamp(sun.y, -1.0, 1.0)) * 180.0 / M_PI, gpu_atmosphere_.radii.x,
                         gpu_atmosphere_.radii.y, gpu_atmosphere_.radii.z, gpu_atmosphere_.solar_irradiance.w);
}

const std::vector<RowRange>& SkyRenderer::TwilightRows(const ViewRequest& view) {
  for (const auto& [shape, runs] : twilight_row_runs_)
    if (shape.mapping == view.mapping && shape.width == view.width && shape.height == view.height &&
        shape.face == view.face)
      return runs;
  // The bounds in the shared code's double, from the uniform block's values.
  glsl::AtmosphereParameters atm{};
  atm.bottom_radius = gpu_atmosphere_.radii.x;
  atm.top_radius = gpu_atmosphere_.radii.y;
  atm.observer_altitude = gpu_atmosphere_.radii.z;
  atm.twilight_march_band = gpu_atmosphere_.twilight.x;
  const glm::dvec2 elevations = glsl::TwilightMarchElevations(atm);
  constexpr double kFloatMargin = 1e-3;  // rad; float32's angles err by about 1e-7 rad
  std::vector<RowRange> runs;
  for (RowRange r : RowsReachingElevations(view, elevations.x - kFloatMargin, elevations.y + kFloatMargin)) {
    r.begin -= r.begin % SKYBAKE_LOCAL_SIZE_Y;
    r.end = std::min(view.height, r.end + (SKYBAKE_LOCAL_SIZE_Y - r.end % SKYBAKE_LOCAL_SIZE_Y) % SKYBAKE_LOCAL_SIZE_Y);
    if (!runs.empty() && runs.back().end >= r.begin) runs.back().end = std::max(runs.back().end, r.end);
    else runs.push_back(r);
  }
  twilight_row_runs_.push_back({view, std::move(runs)});
  return twilight_row_runs_.back().second;
}

void SkyRenderer::AddSkyRows(const ViewRequest& view, const Dispatch& view_dispatch, bool twilight,
                             std::vector<Dispatch>& dispatches, std::vector<bool>& barriers) {
  // Views write disjoint ranges of the output buffer, and runs of rows
  // disjoint parts of a view: no barriers between them.
  const long long texels = (long long)view.width * view.height;
  counters_.sky_texels += texels;
  if (!twilight || !twilight_rows_ || !quality_.sky_view_lut) {
    dispatches.push_back(view_dispatch);
    if (twilight) dispatches.back().pipeline = TwilightSkyPipeline();
    if (twilight) counters_.twilight_texels += texels;
    barriers.push_back(false);
    return;
  }
  bool first = true;
  auto add = [&](int begin, int end, VkPipeline pipeline) {
    if (end <= begin) return;
    Dispatch d = view_dispatch;
    d.pipeline = pipeline;
    d.push.rect = {0, begin, view.width, end};
    d.groups_y = GroupCount(end - begin, SKYBAKE_LOCAL_SIZE_Y);
    d.continues = !first;
    first = false;
    dispatches.push_back(d);
    barriers.push_back(false);
  };
  int row = 0;
  for (const RowRange& r : TwilightRows(view)) {
    add(row, r.begin, sky_pipeline_);
    add(r.begin, r.end, TwilightSkyPipeline());
    counters_.twilight_texels += (long long)view.width * (r.end - r.begin);
    row = r.end;
  }
  add(row, view.height, sky_pipeline_);
}

VkPipeline SkyRenderer::TwilightSkyPipeline() {
  if (!twilight_sky_pipeline_) {
    // The sky pass of sky_pipeline_ with the twilight band's march compiled in.
    const bool sun_disc = effects_.sun_disc && !disc_pass_;
    twilight_sky_pipeline_ =
        sky_view_variant_
            ? CreatePipeline(kSkyRenderSkyViewTwilightSpv, sizeof(kSkyRenderSkyViewTwilightSpv), sun_disc, false, true)
            : CreatePipeline(kSkyRenderSpv, sizeof(kSkyRenderSpv), sun_disc, false, true);
    ++counters_.pipelines;
    if (sky_view_variant_) ++counters_.variant_pipelines;
  }
  return twilight_sky_pipeline_;
}

bool SkyRenderer::CloudsInEarthShadow(const glm::dvec3& sun) const {
  if (cloud_layers_ == 0 || !shadowed_clouds_) return false;
  // The GPU's own values: the bands' tops, the distance bound, the radii (km).
  const double below = CloudEarthShadowElevationDeg(gpu_clouds_, gpu_atmosphere_);
  return sun.y < std::sin(below * M_PI / 180.0);
}

VkPipeline SkyRenderer::ShadowedCloudPipeline() {
  if (!shadowed_cloud_pipeline_) {
    // cloud_pipeline_ with the Sun's light (and its light march) compiled out.
    shadowed_cloud_pipeline_ = CreatePipeline(kCloudRenderSpv, sizeof(kCloudRenderSpv), false, false, false, false);
    ++counters_.pipelines;
  }
  return shadowed_cloud_pipeline_;
}

VkPipeline SkyRenderer::MarchedLightCloudPipeline() {
  if (!marched_light_cloud_pipeline_) {
    // cloud_pipeline_ with every light sample marched (no light volume).
    marched_light_cloud_pipeline_ = CreatePipeline(kCloudRenderSpv, sizeof(kCloudRenderSpv), false, false, false, true);
    ++counters_.pipelines;
  }
  return marched_light_cloud_pipeline_;
}

void SkyRenderer::AddCloudLutDispatch(const char* name, int32_t pass, const glm::dvec3& sun, int width, int height,
                                      std::vector<Dispatch>& dispatches) {
  gpu::SkyPush push{};
  push.sun_direction = {float(sun.x), float(sun.y), float(sun.z), 0.0f};
  push.view = {pass, 0, 0, 0};
  // A height of 0 is a one-dimensional grid.
  dispatches.push_back({name, cloud_lut_pipeline_, push, GroupCount(width, SKYBAKE_LOCAL_SIZE_X),
                        height > 0 ? GroupCount(height, SKYBAKE_LOCAL_SIZE_Y) : 1u});
}

void SkyRenderer::AddCloudLightVolume(const glm::dvec3& sun, std::vector<Dispatch>& dispatches,
                                      std::vector<bool>& barriers) {
  if (cloud_light_volume_ready_ && cloud_light_volume_sun_ == sun) return;
  cloud_light_volume_ready_ = true;
  cloud_light_volume_sun_ = sun;
  const int columns = gpu_clouds_.light_volume.x;
  AddCloudLutDispatch("cloud light volume", CLOUD_PASS_LIGHT_VOLUME, sun, columns, columns, dispatches);
  // Its writes before the cloud pass reads them.
  barriers.push_back(true);
}

VkPipeline SkyRenderer::CreatePipeline(const uint32_t* code, size_t bytes, bool sun_disc, bool sun_disc_pass,
                                       bool twilight_march, bool cloud_sun_light, bool cloud_light_volume) {
  // Specialization constants (SPEC_* of gpu_shared.h). Every pipeline gets
  // them all; a shader that does not use one ignores it.
  struct {
    VkBool32 multiple_scattering, sun_disc, ground, output_directions;
    VkBool32 skydome, ambiguity, cloud_noise, cloud_shapes;
    int32_t integrator;
    VkBool32 sky_view, mie, ozone, night, sun_disc_pass;
    int32_t cloud_layers;
    VkBool32 twilight_march, cloud_sun_light, cloud_light_volume, ground_cloud_shadow, texel_views, cloud_formation;
    VkBool32 cloud_cirrus;
  } values = {effects_.multiple_scattering,
              sun_disc,
              effects_.ground,
              output_directions_,
              aoas_switches_.skydome,
              aoas_switches_.ambiguity,
              aoas_switches_.cloud_noise,
              aoas_switches_.cloud_shapes,
              quality_.integrator,
              quality_.sky_view_lut,
              effects_.mie,
              effects_.ozone,
              effects_.night_dimming,
              sun_disc_pass,
              std::max(cloud_layers_, 1),
              twilight_march,
              cloud_sun_light,
              cloud_light_volume,
              cloud_layers_ > 0 && gpu_clouds_.ground_shadow.x > 0.0f,
              texel_views_whole_,
              cloud_formation_,
              cloud_cirrus_};
  const VkSpecializationMapEntry entries[22] = {{SPEC_MULTIPLE_SCATTERING, 0, 4},
                                                {SPEC_SUN_DISC, 4, 4},
                                                {SPEC_GROUND, 8, 4},
                                                {SPEC_OUTPUT_DIRECTION, 12, 4},
                                                {SPEC_SKYDOME, 16, 4},
                                                {SPEC_AMBIGUITY, 20, 4},
                                                {SPEC_CLOUD_NOISE, 24, 4},
                                                {SPEC_CLOUD_SHAPES, 28, 4},
                                                {SPEC_INTEGRATOR, 32, 4},
                                                {SPEC_USE_SKY_VIEW, 36, 4},
                                                {SPEC_MIE, 40, 4},
                                                {SPEC_OZONE, 44, 4},
                                                {SPEC_NIGHT, 48, 4},
                                                {SPEC_SUN_DISC_PASS, 52, 4},
                                                {SPEC_CLOUD_LAYERS, 56, 4},
                                                {SPEC_TWILIGHT_MARCH, 60, 4},
                                                {SPEC_CLOUD_SUN_LIGHT, 64, 4},
                                                {SPEC_CLOUD_LIGHT_VOLUME, 68, 4},
                                                {SPEC_GROUND_CLOUD_SHADOW, 72, 4},
                                                {SPEC_TEXEL_VIEWS, 76, 4},
                                                {SPEC_CLOUD_FORMATION, 80, 4},
                                                {SPEC_CLOUD_CIRRUS, 84, 4}};
  VkSpecializationInfo specialization{22, entries, sizeof(values), &values};
  return CreateComputePipeline(context_.device(), code, bytes, pipeline_layout_, &specialization,
                               context_.pipeline_cache());
}

void SkyRenderer::Submit(const std::vector<Dispatch>& dispatches, const std::vector<bool>& barrier_after) {
  VkDevice device = context_.device();
  uint32_t queries = uint32_t(2 * dispatches.size());
  if (timestamps_supported_ && queries > query_capacity_) {
    if (query_pool_) vkDestroyQueryPool(device, query_pool_, nullptr);
    VkQueryPoolCreateInfo qinfo{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qinfo.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qinfo.queryCount = std::max<uint32_t>(queries, 16);
    VK_CHECK(vkCreateQueryPool(device, &qinfo, nullptr, &query_pool_));
    query_capacity_ = qinfo.queryCount;
  }

  // Each dispatch's constants into the dispatch buffer (host-coherent: the
  // submission makes the writes visible); the previous submission was
  // waited for, so nothing reads the buffer now.
  EnsureDispatchCapacity(dispatches.size());
  for (size_t i = 0; i < dispatches.size(); ++i)
    std::memcpy(static_cast<gpu::SkyPush*>(dispatch_buffer_.mapped) + i, &dispatches[i].push, sizeof(gpu::SkyPush));

  VK_CHECK(vkResetCommandBuffer(command_buffer_, 0));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(command_buffer_, &begin));
  if (timestamps_supported_) vkCmdResetQueryPool(command_buffer_, query_pool_, 0, queries);
  vkCmdBindDescriptorSets(command_buffer_, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout_, 0, 1, &descriptor_set_, 0,
                          nullptr);
  for (size_t i = 0; i < dispatches.size(); ++i) {
    const Dispatch& d = dispatches[i];
    if (timestamps_supported_)
      vkCmdWriteTimestamp(command_buffer_, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, query_pool_, uint32_t(2 * i));
    vkCmdBindPipeline(command_buffer_, VK_PIPELINE_BIND_POINT_COMPUTE, d.pipeline);
    const uint32_t dispatch_index = uint32_t(i);
    vkCmdPushConstants(command_buffer_, pipeline_layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(dispatch_index),
                       &dispatch_index);
    vkCmdDispatch(command_buffer_, d.groups_x, d.groups_y, 1);
    if (timestamps_supported_)
      vkCmdWriteTimestamp(command_buffer_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, query_pool_, uint32_t(2 * i + 1));
    if (barrier_after[i]) {
      // Orders this dispatch's LUT writes before the next dispatch's LUT reads.
      VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
      barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
      barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
      vkCmdPipelineBarrier(command_buffer_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                           0, 1, &barrier, 0, nullptr, 0, nullptr);
    }
  }
  // Makes every shader write of the submission visible to host reads after the fence.
  VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  to_host.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(command_buffer_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                       &to_host, 0, nullptr, 0, nullptr);
  VK_CHECK(vkEndCommandBuffer(command_buffer_));

  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &command_buffer_;
  VK_CHECK(vkResetFences(device, 1, &fence_));
  VK_CHECK(vkQueueSubmit(context_.queue(), 1, &submit, fence_));
  VK_CHECK(vkWaitForFences(device, 1, &fence_, VK_TRUE, UINT64_MAX));

  timings_.clear();
  std::vector<uint64_t> stamps(queries, 0);
  if (timestamps_supported_ && queries > 0)
    VK_CHECK(vkGetQueryPoolResults(device, query_pool_, 0, queries, stamps.size() * sizeof(uint64_t), stamps.data(),
                                   sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  double period_ns = context_.properties().limits.timestampPeriod;
  for (size_t i = 0; i < dispatches.size(); ++i) {
    PassTiming t;
    t.name = dispatches[i].name;
    if (timestamps_supported_) t.gpu_ms = double(stamps[2 * i + 1] - stamps[2 * i]) * period_ns * 1e-6;
    if (dispatches[i].continues && !timings_.empty()) timings_.back().gpu_ms += t.gpu_ms;
    else timings_.push_back(t);
  }
}

void SkyRenderer::SyncSpectral() {
  timings_ = spectral_->last_timings();
  counters_ = spectral_->counters();
}

void SkyRenderer::PrecomputeLuts() {
  if (spectral_) {
    spectral_->PrecomputeLuts();
    return SyncSpectral();
  }
  std::vector<Dispatch> dispatches;
  std::vector<bool> barriers;
  gpu::SkyPush push{};
  // A LUT that nothing reads is not computed (pass_plan.h); the clouds read
  // the transmittance LUT for the sunlight at each sample.
  const bool transmittance = NeedsTransmittanceLut(quality_, effects_) || cloud_layers_ > 0;
  if (transmittance) {
    dispatches.push_back({"transmittance LUT", transmittance_pipeline_, push,
                          GroupCount(gpu_atmosphere_.lut_sizes.x, SKYBAKE_LOCAL_SIZE_X),
                          GroupCount(gpu_atmosphere_.lut_sizes.y, SKYBAKE_LOCAL_SIZE_Y)});
    barriers.push_back(true);
  }
  if (effects_.multiple_scattering) {
    dispatches.push_back({"multiple-scattering LUT", multiscattering_pipeline_, push,
                          GroupCount(gpu_atmosphere_.lut_sizes.z, SKYBAKE_LOCAL_SIZE_X),
                          GroupCount(gpu_atmosphere_.lut_sizes.w, SKYBAKE_LOCAL_SIZE_Y)});
    barriers.push_back(true);
  }
  if (!dispatches.empty()) Submit(dispatches, barriers);
  if (transmittance) ++counters_.transmittance_lut_builds;
  if (effects_.multiple_scattering) ++counters_.multiscattering_lut_builds;
  luts_ready_ = true;
  if (cloud_layers_ > 0 && !cloud_noise_ready_) GenerateCloudNoise();
}

void SkyRenderer::GenerateCloudNoise() {
  cloud_light_volume_ready_ = false;  // read from the noise
  // The weather images first (host writes to the mapped buffer; the
  // submission below makes them visible to the device), then the volumes
  // and procedural maps, from the seeds alone.
  const int n_weather = gpu_clouds_.resolution.z;
  std::vector<Dispatch> dispatches;
  std::vector<bool> barriers;
  for (int l = 0; l < cloud_layers_; ++l) {
    const gpu::GpuCloudLayer& layer = gpu_clouds_.layers[l];
    gpu::SkyPush push{};
    push.view = {CLOUD_PASS_SHAPE, 0, 0, l};
    const int ns = gpu_clouds_.resolution.x, nd = gpu_clouds_.resolution.y;
    // A formation's density volume takes the shape volume's place (GpuCloudLayer.weather.w = 2).
    if (layer.weather.w < 1.5f)
      dispatches.push_back({"cloud shape noise", cloud_lut_pipeline_, push, GroupCount(ns, SKYBAKE_LOCAL_SIZE_X),
                            GroupCount(ns * ns, SKYBAKE_LOCAL_SIZE_Y)});
    push.view.x = CLOUD_PASS_DETAIL;
    dispatches.push_back({"cloud detail noise", cloud_lut_pipeline_, push, GroupCount(nd, SKYBAKE_LOCAL_SIZE_X),
                          GroupCount(nd * nd, SKYBAKE_LOCAL_SIZE_Y)});
    if (layer.weather.w < 0.5f) {
      push.view.x = CLOUD_PASS_WEATHER;
      dispatches.push_back({"cloud weather map", cloud_lut_pipeline_, push, GroupCount(n_weather, SKYBAKE_LOCAL_SIZE_X),
                            GroupCount(n_weather, SKYBAKE_LOCAL_SIZE_Y)});
    }
  }
  CopyCloudWeatherImages();
  // Each dispatch writes its own range of the noise buffer: no barriers
  // between them; the submission's end orders them before later reads.
  barriers.assign(dispatches.size(), false);
  Submit(dispatches, barriers);
  FillCloudSkipMaps();
  cloud_noise_ready_ = true;
  ++counters_.cloud_noise_builds;
}

void SkyRenderer::FillCloudSkipMaps() {
  // The noise's writes were made visible to the host by the submission's
  // last barrier and its fence; the host's writes reach the next submission.
  if (gpu_clouds_.range.w > 0.5f)
    skybake::FillCloudSkipMaps(gpu_clouds_, static_cast<float*>(cloud_noise_buffer_.mapped));
}

void SkyRenderer::CopyCloudWeatherImages() {
  // CloudInputs::weather_images: per image layer its map, and after a
  // formation volume's map its volume (clouds.h).
  float* noise = static_cast<float*>(cloud_noise_buffer_.mapped);
  const size_t count = size_t(gpu_clouds_.resolution.z) * gpu_clouds_.resolution.z;
  const size_t volume = size_t(gpu_clouds_.resolution.x) * gpu_clouds_.resolution.x * gpu_clouds_.resolution.x;
  const float* next = cloud_weather_images_.data();
  for (int l = 0; l < cloud_layers_; ++l) {
    const gpu::GpuCloudLayer& layer = gpu_clouds_.layers[l];
    if (layer.weather.w < 0.5f) continue;
    std::memcpy(noise + layer.noise.z, next, count * sizeof(float));
    next += count;
    if (layer.weather.w > 1.5f) {
      std::memcpy(noise + layer.noise.x, next, volume * sizeof(float));
      next += volume;
    }
  }
}

void SkyRenderer::AddCloudTables(const glm::dvec3& sun, std::vector<Dispatch>& dispatches,
                                 std::vector<bool>& barriers) {
  if (cloud_tables_ready_ && cloud_sun_ == sun) return;
  cloud_tables_ready_ = true;
  cloud_sun_ = sun;
  AddCloudLutDispatch("cloud aerial perspective", CLOUD_PASS_AERIAL, sun, gpu_clouds_.lut.x, gpu_clouds_.lut.y,
                      dispatches);
  barriers.push_back(false);  // the two tables are disjoint ranges of one buffer
  AddCloudLutDispatch("cloud ambient", CLOUD_PASS_AMBIENT, sun, gpu_clouds_.lut.w, 0, dispatches);
  // The tables' writes before the cloud pass reads them.
  barriers.push_back(true);
  ++counters_.cloud_table_builds;
}

std::vector<std::vector<float>> SkyRenderer::Render(const glm::dvec3& sun, const std::vector<ViewRequest>& views,
                                                    bool sun_disc) {
  if (spectral_) {
    std::vector<std::vector<float>> images = spectral_->Render(sun, views, sun_disc);
    SyncSpectral();
    return images;
  }
  if (!luts_ready_ && !output_directions_) PrecomputeLuts();
  size_t total = 0;
  const std::vector<size_t> offsets = TexelOffsets(views, total);
  // The views share one storage buffer; when they do not fit in the largest
  // range the device can bind, they are rendered in groups that do.
  const VkDeviceSize max_range = context_.properties().limits.maxStorageBufferRange;
  if (VkDeviceSize(total) * 16 > max_range) {
    if (views.size() == 1)
      throw VulkanError(fmt::format("a {}x{} view needs {} MiB in one storage buffer; {} allows {} MiB "
                                    "(maxStorageBufferRange): lower render.cube_size or render.latlong_height",
                                    views[0].width, views[0].height, (VkDeviceSize(total) * 16) >> 20,
                                    context_.device_info().name, max_range >> 20),
                        VK_ERROR_OUT_OF_DEVICE_MEMORY);
    const size_t half = views.size() / 2;
    std::vector<std::vector<float>> images =
        Render(sun, std::vector<ViewRequest>(views.begin(), views.begin() + half), sun_disc);
    std::vector<PassTiming> timings = last_timings();
    for (std::vector<float>& image : Render(sun, std::vector<ViewRequest>(views.begin() + half, views.end()), sun_disc))
      images.push_back(std::move(image));
    timings.insert(timings.end(), last_timings().begin(), last_timings().end());
    timings_ = timings;
    return images;
  }
  EnsureOutputCapacity(std::max<size_t>(total, 1) * 16);
  SubmitViews(output_buffer_, sun, views, sun_disc, offsets);

  std::vector<std::vector<float>> images;
  const float* data = static_cast<const float*>(output_buffer_.mapped);
  for (size_t i = 0; i < views.size(); ++i) {
    size_t count = size_t(views[i].width) * views[i].height * 4;
    images.emplace_back(data + offsets[i] * 4, data + offsets[i] * 4 + count);
  }
  return images;
}

RenderedViews SkyRenderer::RenderInPlace(const glm::dvec3& sun, const std::vector<ViewRequest>& views, bool sun_disc) {
  if (spectral_) {  // combined on the host, held in memory of its own
    auto images = std::make_shared<std::vector<std::vector<float>>>(Render(sun, views, sun_disc));
    RenderedViews result;
    for (const std::vector<float>& image : *images) result.views.push_back(image.data());
    result.hold = images;
    return result;
  }
  if (!luts_ready_ && !output_directions_) PrecomputeLuts();
  size_t total = 0;
  const std::vector<size_t> offsets = TexelOffsets(views, total);
  const VkDeviceSize bytes = VkDeviceSize(std::max<size_t>(total, 1)) * 16;
  RenderedViews result;
  if (bytes > context_.properties().limits.maxStorageBufferRange) {
    // Rendered in groups (Render) and held in memory of their own.
    auto images = std::make_shared<std::vector<std::vector<float>>>(Render(sun, views, sun_disc));
    for (const std::vector<float>& image : *images) result.views.push_back(image.data());
    result.hold = images;
    return result;
  }
  // A slot whose texels nobody holds any more, large enough; else a new one.
  FrameSlot* slot = nullptr;
  for (const std::unique_ptr<FrameSlot>& s : frame_slots_) {
    if (s->hold.use_count() == 1) {
      slot = s.get();
      break;
    }
  }
  if (!slot) {
    frame_slots_.push_back(std::make_unique<FrameSlot>());
    slot = frame_slots_.back().get();
    slot->hold = std::make_shared<int>(0);
  }
  // The last holder's reads of the slot before the device writes it again.
  std::atomic_thread_fence(std::memory_order_acquire);
  if (slot->buffer.size < bytes) {
    DestroyBuffer(slot->buffer);
    slot->buffer = CreateBuffer(bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  }
  SubmitViews(slot->buffer, sun, views, sun_disc, offsets);
  const float* data = static_cast<const float*>(slot->buffer.mapped);
  for (size_t offset : offsets) result.views.push_back(data + offset * 4);
  result.hold = slot->hold;
  return result;
}

bool SkyRenderer::HoldsFrames() const {
  for (const std::unique_ptr<FrameSlot>& slot : frame_slots_)
    if (slot->hold.use_count() > 1) return true;
  return false;
}

std::vector<SkyRenderer::Dispatch> SkyRenderer::ViewDispatches(const glm::dvec3& sun,
                                                               const std::vector<ViewRequest>& views, bool sun_disc,
                                                               const std::vector<size_t>& offsets) const {
  static const char* kFaceNames[6] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};
  std::vector<Dispatch> dispatches;
  for (size_t i = 0; i < views.size(); ++i) {
    const ViewRequest& v = views[i];
    gpu::SkyPush push = ViewPush(sun, v);
    // MAPPING_DIRECTIONS (RenderDirections): the directions follow the texels.
    push.offsets = {int32_t(offsets[i]), sun_disc ? 0 : 1, int32_t(offsets[i] + size_t(v.width) * v.height), 0};
    std::string name = v.mapping == MAPPING_LATLONG       ? "latlong"
                       : v.mapping == MAPPING_CUBE_STRIP  ? "cube strip"
                       : v.mapping == MAPPING_VULKAN_FACE ? std::string("face ") + kFaceNames[v.face % 6]
                                                          : "directions";
    dispatches.push_back({name, sky_pipeline_, push, GroupCount(v.width, SKYBAKE_LOCAL_SIZE_X),
                          GroupCount(v.height, SKYBAKE_LOCAL_SIZE_Y)});
  }
  return dispatches;
}

void SkyRenderer::AddSunDisc(const glm::dvec3& sun, const std::vector<ViewRequest>& views,
                             const std::vector<Dispatch>& view_dispatches, std::vector<Dispatch>& dispatches,
                             std::vector<bool>& barriers) {
  // The disc, added to the texels near the Sun once the sky pass has
  // written them. Its angular radius with the margin NearSunDisc leaves.
  const double disc_angle = std::min(2.0 * double(gpu_atmosphere_.solar_irradiance.w), 3.14159265358979);
  const size_t last_view = dispatches.size() - 1;
  for (size_t i = 0; i < views.size(); ++i) {
    for (const TexelRect& r : TexelsNearDirection(views[i], sun, disc_angle)) {
      gpu::SkyPush push = view_dispatches[i].push;  // the view's own constants
      push.rect = {r.x0, r.y0, r.x1, r.y1};
      dispatches.push_back({"sun disc", disc_pipeline_, push, GroupCount(r.x1 - r.x0, SKYBAKE_LOCAL_SIZE_X),
                            GroupCount(r.y1 - r.y0, SKYBAKE_LOCAL_SIZE_Y)});
      // Rectangles are disjoint, within and across views.
      barriers.push_back(false);
      ++counters_.sun_disc_dispatches;
      counters_.sun_disc_texels += (long long)(r.x1 - r.x0) * (r.y1 - r.y0);
    }
  }
  // The sky pass's writes before the disc's reads: a barrier after the last
  // dispatch so far (the cloud panorama, where there is one, follows the views).
  if (dispatches.size() > last_view + 1) barriers[last_view] = true;
}

void SkyRenderer::AddCloudComposites(const std::vector<Dispatch>& view_dispatches, const CloudPanorama& panorama,
                                     int32_t panorama_row_range, VkPipeline cloud_pipeline,
                                     std::vector<Dispatch>& dispatches, std::vector<bool>& barriers) {
  // The sky and disc passes' writes before the cloud pass reads them (in a
  // submission of its own, FramePart::kClouds, the host's writes are).
  if (!barriers.empty()) barriers.back() = true;
  for (Dispatch d : view_dispatches) {
    d.name = "clouds " + d.name;
    d.pipeline = cloud_pipeline;
    if (panorama.width > 0) {
      d.pipeline = cloud_resample_pipeline_;
      d.push.rect = {int32_t(CloudLutTexels(gpu_clouds_)), panorama.width, panorama.height, CLOUD_MODE_RESAMPLE};
      d.push.offsets.w = panorama_row_range;
    }
    dispatches.push_back(d);
    barriers.push_back(false);  // views are disjoint
    ++counters_.cloud_dispatches;
  }
}

void SkyRenderer::SubmitViews(const Buffer& target, const glm::dvec3& sun, const std::vector<ViewRequest>& views,
                              bool sun_disc, const std::vector<size_t>& offsets, FramePart part) {
  // The cloud panorama (cloud_panorama.h), after the cloud tables in their
  // buffer; growing it rewrites the descriptors, so before the output's.
  const CloudPanorama panorama = cloud_layers_ > 0 ? ChooseCloudPanorama(views, gpu_clouds_.range.z) : CloudPanorama{};
  if (panorama.width > 0) EnsureCloudLutCapacity(CloudLutTexels(gpu_clouds_) + panorama.texels());
  // Its rows that can see a cloud (the others are not marched), packed for the
  // shaders as begin + end x 65536 (SkyPush.offsets.w, cloud_panorama.glsl).
  CloudPanoramaRows panorama_rows{0, panorama.height};
  if (panorama.width > 0) {
    std::vector<std::array<double, 2>> bands;
    for (int b = 0; b < gpu_clouds_.resolution.w; ++b)
      bands.push_back({gpu_clouds_.bands[b].x, gpu_clouds_.bands[b].y});
    panorama_rows = CloudPanoramaRowsSeeingBands(panorama, gpu_atmosphere_.radii.x, gpu_atmosphere_.radii.z, bands);
  }
  const int32_t panorama_row_range = panorama_rows.begin + panorama_rows.end * 65536;
  BindOutput(target);
  // At twilight the low sky is ray-marched (quality.twilight_march_band_deg).
  const bool twilight = twilight_march_allowed_ && MarchesTwilightBand(sun);
  // With every cloud band in the Earth's shadow the clouds march without the Sun's light.
  const bool shadowed_clouds = CloudsInEarthShadow(sun);
  // A Sun too low for the light volume (CloudLightVolumeForSun): every light sample marched.
  const bool light_volume = cloud_light_volume_ && !shadowed_clouds && CloudLightVolumeForSun(gpu_clouds_, sun.y);
  const VkPipeline cloud_pipeline = shadowed_clouds                        ? ShadowedCloudPipeline()
                                    : cloud_light_volume_ && !light_volume ? MarchedLightCloudPipeline()
                                                                           : cloud_pipeline_;
  if (shadowed_clouds && part != FramePart::kClouds) ++counters_.shadowed_cloud_frames;
  // The views' constants, the cloud pass's too.
  const std::vector<Dispatch> view_dispatches = ViewDispatches(sun, views, sun_disc, offsets);

  std::vector<Dispatch> dispatches;
  std::vector<bool> barriers;
  if (part != FramePart::kClouds) {
    // The skydome moves the observer, so its texels ray-march: no sky-view LUT.
    if (quality_.sky_view_lut && !aoas_switches_.skydome && !output_directions_ &&
        !(skyview_ready_ && skyview_sun_ == sun)) {
      // The sky-view LUT depends on the sun only: built once per sun position.
      skyview_ready_ = true;
      skyview_sun_ = sun;
      // The sky-view LUT for this Sun, read by every view below.
      gpu::SkyPush push{};
      push.sun_direction = {float(sun.x), float(sun.y), float(sun.z), 0.0f};
      dispatches.push_back({"sky-view LUT", skyview_pipeline_, push,
                            GroupCount(quality_.sky_view_width, SKYBAKE_LOCAL_SIZE_X),
                            GroupCount(quality_.sky_view_height, SKYBAKE_LOCAL_SIZE_Y)});
      barriers.push_back(true);
      ++counters_.skyview_lut_builds;
    }
    if (cloud_layers_ > 0) AddCloudTables(sun, dispatches, barriers);
    if (light_volume) AddCloudLightVolume(sun, dispatches, barriers);
    // The sky views before the cloud panorama: neither reads the other, and
    // on lavapipe the views recorded after the panorama ran about 6% slower
    // than the same views before it (W3's render stage 1.25 -> 1.17 s,
    // medians of 6 alternating runs, docs/performance.md).
    for (size_t i = 0; i < views.size(); ++i) AddSkyRows(views[i], view_dispatches[i], twilight, dispatches, barriers);
    if (panorama.width > 0) {
      gpu::SkyPush push{};
      push.sun_direction = {float(sun.x), float(sun.y), float(sun.z), 0.0f};
      const uint32_t row_blocks = GroupCount(panorama_rows.end - panorama_rows.begin, SKYBAKE_LOCAL_SIZE_Y);
      push.view = {MAPPING_LATLONG, panorama.width, panorama.height, CloudPanoramaBlockStride(int(row_blocks))};
      push.rect = {int32_t(CloudLutTexels(gpu_clouds_)), panorama.width, panorama.height, CLOUD_MODE_PANORAMA};
      push.offsets.w = panorama_row_range;
      // Read by the cloud passes after the barrier the sun disc or the composites set.
      dispatches.push_back(
          {"clouds panorama", cloud_pipeline, push, GroupCount(panorama.width, SKYBAKE_LOCAL_SIZE_X), row_blocks});
      barriers.push_back(false);
      ++counters_.cloud_dispatches;
    }
    if (disc_pass_ && sun_disc) AddSunDisc(sun, views, view_dispatches, dispatches, barriers);
  }
  if (cloud_layers_ > 0 && part != FramePart::kClearSky)
    AddCloudComposites(view_dispatches, panorama, panorama_row_range, cloud_pipeline, dispatches, barriers);
  Submit(dispatches, barriers);
  if (part != FramePart::kClouds) ++counters_.frames;
}

std::vector<float> SkyRenderer::RenderDirections(const glm::dvec3& sun, const std::vector<glm::dvec3>& directions,
                                                 bool sun_disc) {
  if (spectral_) {
    std::vector<float> radiance = spectral_->RenderDirections(sun, directions, sun_disc);
    SyncSpectral();
    return radiance;
  }
  if (!luts_ready_) PrecomputeLuts();
  // The directions after the view's texels, where the sun-disc pass still
  // finds them once the sky pass has written radiance.
  EnsureOutputCapacity(std::max<size_t>(directions.size(), 1) * 2 * 16);
  float* data = static_cast<float*>(output_buffer_.mapped) + 4 * directions.size();
  for (size_t i = 0; i < directions.size(); ++i) {
    data[4 * i + 0] = float(directions[i].x);
    data[4 * i + 1] = float(directions[i].y);
    data[4 * i + 2] = float(directions[i].z);
    data[4 * i + 3] = 0.0f;
  }
  ViewRequest view;
  view.mapping = MAPPING_DIRECTIONS;
  view.width = int(directions.size());
  view.height = 1;
  return Render(sun, {view}, sun_disc)[0];
}

std::vector<float*> SkyRenderer::RenderClearSky(const glm::dvec3& sun, const std::vector<ViewRequest>& views,
                                                bool sun_disc, const std::vector<glm::dvec3>& directions) {
  if (spectral_ || style_pass_ || output_directions_)
    throw std::logic_error("SkyRenderer::RenderClearSky: a three-wavelength sky renderer only");
  if (!luts_ready_) PrecomputeLuts();
  size_t total = 0;
  const std::vector<size_t> offsets = TexelOffsets(views, total);
  // A MAPPING_DIRECTIONS view's directions after its texels, as RenderDirections places them.
  const VkDeviceSize bytes = VkDeviceSize(std::max<size_t>(total + directions.size(), 1)) * 16;
  if (bytes > context_.properties().limits.maxStorageBufferRange)
    throw VulkanError(fmt::format("{} texels need {} MiB in one storage buffer; {} allows {} MiB "
                                  "(maxStorageBufferRange): lower render.cube_size or render.latlong_height",
                                  total, bytes >> 20, context_.device_info().name,
                                  context_.properties().limits.maxStorageBufferRange >> 20),
                      VK_ERROR_OUT_OF_DEVICE_MEMORY);
  EnsureOutputCapacity(bytes);
  float* data = static_cast<float*>(output_buffer_.mapped);
  for (size_t i = 0; i < directions.size(); ++i) {
    float* d = data + 4 * (total + i);
    d[0] = float(directions[i].x);
    d[1] = float(directions[i].y);
    d[2] = float(directions[i].z);
    d[3] = 0.0f;
  }
  SubmitViews(output_buffer_, sun, views, sun_disc, offsets, FramePart::kClearSky);
  clear_sky_ = std::make_unique<ClearSkyFrame>(ClearSkyFrame{sun, views, sun_disc, offsets});
  std::vector<float*> texels;
  for (size_t offset : offsets) texels.push_back(data + 4 * offset);
  return texels;
}

void SkyRenderer::CompositeClouds() {
  if (!clear_sky_) throw std::logic_error("SkyRenderer::CompositeClouds: no RenderClearSky before it");
  const ClearSkyFrame frame = *clear_sky_;
  clear_sky_.reset();
  timings_.clear();
  if (cloud_layers_ == 0) return;  // the clear sky is the frame
  SubmitViews(output_buffer_, frame.sun, frame.views, frame.sun_disc, frame.offsets, FramePart::kClouds);
}

void SkyRenderer::ApplyStyle(const glm::dvec3& sun, const std::vector<ViewRequest>& views,
                             std::vector<std::vector<float>>& images, const std::vector<glm::dvec3>& directions) {
  if (!style_pass_) throw std::logic_error("SkyRenderer::ApplyStyle: not a style pass (SkyRenderer::StylePass)");
  size_t total = 0;
  const std::vector<size_t> offsets = TexelOffsets(views, total);
  // The directions of a MAPPING_DIRECTIONS view after every view's texels.
  const VkDeviceSize bytes = VkDeviceSize(std::max<size_t>(total + directions.size(), 1)) * 16;
  if (bytes > context_.properties().limits.maxStorageBufferRange && views.size() > 1) {
    // In two halves, as Render splits a frame too large for one buffer.
    const size_t half = views.size() / 2;
    std::vector<std::vector<float>> first(images.begin(), images.begin() + half);
    std::vector<std::vector<float>> second(images.begin() + half, images.end());
    ApplyStyle(sun, std::vector<ViewRequest>(views.begin(), views.begin() + half), first, directions);
    std::vector<PassTiming> timings = last_timings();
    ApplyStyle(sun, std::vector<ViewRequest>(views.begin() + half, views.end()), second, directions);
    timings.insert(timings.end(), last_timings().begin(), last_timings().end());
    timings_ = timings;
    for (size_t i = 0; i < views.size(); ++i) images[i] = std::move(i < half ? first[i] : second[i - half]);
    return;
  }
  EnsureOutputCapacity(bytes);
  BindOutput(output_buffer_);
  float* data = static_cast<float*>(output_buffer_.mapped);
  for (size_t i = 0; i < views.size(); ++i) std::memcpy(data + 4 * offsets[i], images[i].data(), images[i].size() * 4);
  for (size_t i = 0; i < directions.size(); ++i) {
    float* d = data + 4 * (total + i);
    d[0] = float(directions[i].x);
    d[1] = float(directions[i].y);
    d[2] = float(directions[i].z);
    d[3] = 0.0f;
  }
  std::vector<Dispatch> dispatches;
  for (size_t i = 0; i < views.size(); ++i) {
    const ViewRequest& v = views[i];
    gpu::SkyPush push = ViewPush(sun, v);
    push.offsets = {int32_t(offsets[i]), 0, int32_t(total), 0};
    dispatches.push_back({"style", style_pipeline_, push, GroupCount(v.width, SKYBAKE_LOCAL_SIZE_X),
                          GroupCount(v.height, SKYBAKE_LOCAL_SIZE_Y)});
  }
  Submit(dispatches, std::vector<bool>(dispatches.size(), false));  // views are disjoint
  for (size_t i = 0; i < views.size(); ++i) std::memcpy(images[i].data(), data + 4 * offsets[i], images[i].size() * 4);
}

bool SkyRenderer::UpdateAtmosphere(const AtmosphereParams& atmosphere, const QualitySettings& quality,
                                   const EffectSettings& effects, const Rgb& output_scale) {
  if (spectral_) return spectral_->UpdateAtmosphere(atmosphere, quality, effects);
  if (quality.wavelengths != quality_.wavelengths) return false;
  gpu::GpuAtmosphere g = ToGpuAtmosphere(atmosphere, quality, effects, output_scale);
  // The frame's conversion stays (SetOutputConversion owns it).
  g.output_scale = gpu_atmosphere_.output_scale;
  std::copy(std::begin(gpu_atmosphere_.sky_to_output), std::end(gpu_atmosphere_.sky_to_output), g.sky_to_output);
  std::copy(std::begin(gpu_atmosphere_.ambient_to_direct), std::end(gpu_atmosphere_.ambient_to_direct),
            g.ambient_to_direct);
  // The shader variant (specialization constants) and the buffer sizes must
  // stay; every other value is uniform data.
  auto same = [](const auto& a, const auto& b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  if (!same(g.lut_sizes, gpu_atmosphere_.lut_sizes) || !same(g.samples, gpu_atmosphere_.samples) ||
      !same(g.effects, gpu_atmosphere_.effects) || !same(g.render, gpu_atmosphere_.render) ||
      !same(g.twilight, gpu_atmosphere_.twilight) || quality.sky_view_lut != quality_.sky_view_lut ||
      effects.mie != effects_.mie || effects.ozone != effects_.ozone || effects.night_dimming != effects_.night_dimming)
    return false;
  if (same(g, gpu_atmosphere_)) return true;
  // Every submission waits for its fence, so no dispatch reads the buffer now.
  gpu_atmosphere_ = g;
  effects_ = effects;
  std::memcpy(atmosphere_buffer_.mapped, &gpu_atmosphere_, sizeof(gpu_atmosphere_));
  luts_ready_ = false;
  skyview_ready_ = false;
  cloud_tables_ready_ = false;
  cloud_light_volume_ready_ = false;
  return true;
}

void SkyRenderer::SetOutputConversion(const OutputConversion& conversion) {
  if (spectral_) return;
  gpu::GpuAtmosphere g = gpu_atmosphere_;
  auto v4 = [](const Rgb& rgb) { return gpu::vec4{float(rgb[0]), float(rgb[1]), float(rgb[2]), 0.0f}; };
  g.output_scale = v4(conversion.direct);
  for (int i = 0; i < 3; ++i) {
    g.sky_to_output[i] = v4(conversion.sky[i]);
    Rgb ambient{};
    for (int j = 0; j < 3; ++j) ambient[j] = conversion.sky[i][j] / conversion.direct[i];
    g.ambient_to_direct[i] = v4(ambient);
  }
  // The clouds' ambient table holds the sky light re-expressed (ComputeCloudAmbientRow).
  if (std::memcmp(g.ambient_to_direct, gpu_atmosphere_.ambient_to_direct, sizeof g.ambient_to_direct) != 0)
    cloud_tables_ready_ = false;
  if (std::memcmp(&g, &gpu_atmosphere_, sizeof g) == 0) return;
  // Every submission waits for its fence, so no dispatch reads the buffer now.
  gpu_atmosphere_ = g;
  std::memcpy(atmosphere_buffer_.mapped, &gpu_atmosphere_, sizeof(gpu_atmosphere_));
}

bool SkyRenderer::CloudFormationRead(const gpu::GpuClouds& clouds) const {
  return formation_read_always_ || CloudFormationDensityOn(clouds);
}

bool SkyRenderer::UpdateClouds(const CloudInputs& clouds) {
  if (spectral_) return spectral_->UpdateClouds(clouds);
  const gpu::GpuClouds& c = clouds.uniform;
  auto same = [](const auto& a, const auto& b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  if (output_directions_ || c.counts.x != cloud_layers_ || !same(c.resolution, gpu_clouds_.resolution) ||
      !same(c.lut, gpu_clouds_.lut) || !same(c.light_volume, gpu_clouds_.light_volume) ||
      (cloud_layers_ > 0 && CloudLightVolumeOn(c) != cloud_light_volume_) ||
      (cloud_layers_ > 0 && CloudFormationRead(c) != cloud_formation_) ||  // SPEC_CLOUD_FORMATION
      (cloud_layers_ > 0 && CloudCirrusOn(c) != cloud_cirrus_) ||          // SPEC_CLOUD_CIRRUS
      (c.ground_shadow.x > 0.0f) != (gpu_clouds_.ground_shadow.x > 0.0f))  // kGroundCloudShadow's pipelines
    return false;
  // The noise depends on the seeds, the buffer layout and the weather images.
  const bool images_same = clouds.weather_images == cloud_weather_images_;
  bool layout_same = true;
  for (int l = 0; l < cloud_layers_; ++l)
    layout_same = layout_same && same(c.layers[l].noise, gpu_clouds_.layers[l].noise) &&
                  c.layers[l].weather.w == gpu_clouds_.layers[l].weather.w;
  const bool noise_same = images_same && layout_same;
  if (same(c, gpu_clouds_) && noise_same) return true;
  // The light volume follows every cloud setting (the wind's offsets too).
  cloud_light_volume_ready_ = false;
  // Every submission waits for its fence, so no dispatch reads the buffers now.
  if (!noise_same) {
    cloud_weather_images_ = clouds.weather_images;
    // Only the weather images changed (a cloud formation's coverage of a
    // new frame): the volumes stay, the images are copied in place.
    if (layout_same && cloud_noise_ready_) CopyCloudWeatherImages();
    else cloud_noise_ready_ = false;
  }
  // The tables depend on the layers' top (the ambient table's range) and distances.
  if (!same(c.range, gpu_clouds_.range)) cloud_tables_ready_ = false;
  // The empty-space bounds follow the weather images copied in place, and
  // are filled when the march starts to use them.
  const bool refill = cloud_noise_ready_ && (!noise_same || c.range.w != gpu_clouds_.range.w);
  gpu_clouds_ = c;
  std::memcpy(clouds_buffer_.mapped, &gpu_clouds_, sizeof(gpu_clouds_));
  if (refill) FillCloudSkipMaps();
  if (!cloud_noise_ready_ && luts_ready_) GenerateCloudNoise();
  return true;
}

std::vector<float> SkyRenderer::ReadCloudNoise() const {
  if (spectral_) return spectral_->group(0).ReadCloudNoise();
  if (cloud_layers_ == 0) return {};
  const float* data = static_cast<const float*>(cloud_noise_buffer_.mapped);
  return std::vector<float>(data, data + CloudNoiseFloats(gpu_clouds_));
}

bool SkyRenderer::UpdateAoas(const AoasInputs& aoas) {
  if (spectral_) return spectral_->UpdateAoas(aoas);
  const AoasSwitches& s = aoas.switches;
  if (s.skydome != aoas_switches_.skydome || s.ambiguity != aoas_switches_.ambiguity ||
      s.cloud_noise != aoas_switches_.cloud_noise || s.cloud_shapes != aoas_switches_.cloud_shapes)
    return false;
  // Every submission waits for its fence, so no dispatch reads the buffer now.
  std::memcpy(aoas_buffer_.mapped, &aoas.uniform, sizeof(gpu::GpuAoas));
  return true;
}

std::vector<float> SkyRenderer::ReadTransmittanceLut() const {
  if (spectral_) return spectral_->group(0).ReadTransmittanceLut();
  const float* data = static_cast<const float*>(transmittance_buffer_.mapped);
  return std::vector<float>(data, data + size_t(gpu_atmosphere_.lut_sizes.x) * gpu_atmosphere_.lut_sizes.y * 4);
}

std::vector<float> SkyRenderer::ReadMultipleScatteringLut() const {
  if (spectral_) return spectral_->group(0).ReadMultipleScatteringLut();
  const float* data = static_cast<const float*>(multiscattering_buffer_.mapped);
  return std::vector<float>(data, data + size_t(gpu_atmosphere_.lut_sizes.z) * gpu_atmosphere_.lut_sizes.w * 4);
}

}  // namespace skybake
