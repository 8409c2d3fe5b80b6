// Image-based lighting from a baked sky (split sum, Karis 2013, "Real Shading
// in Unreal Engine 4"): what an engine loads to light a scene with the sky.
//
//   specular    a cube mip chain: level l of L holds the sky's radiance
//               prefiltered with the GGX distribution of perceptual roughness
//               l / (L - 1) (alpha = roughness^2), with N = V = R; level 0 is
//               the sky itself. Faces N x N at level 0, N / 2^l below.
//   irradiance  a small cube of E(n) / pi, E the irradiance on a surface of
//               normal n: the radiance a white Lambertian surface reflects,
//               so shading multiplies it by the albedo alone. (The SH of the
//               manifest and the glTF scene are E_lm, without the 1 / pi.)
//   DFG         the split sum's second factor, a 2D table: x = N.V, y =
//               perceptual roughness (texel centres), R = scale A and G =
//               bias B of F0, Schlick-Smith G with k = alpha / 2.
//
// Faces are Vulkan cube faces (+X -X +Y -Y +Z -Z, the face-selection table of
// envmap.glsl) in skybake's frame, +Y up, right-handed, North = -Z. Values
// are in the bake's output units (cd/m^2 by default). By default the sky is
// filtered without the sun disc: the Sun travels as the glTF scene's
// KHR_lights_punctual light, which an engine shades exactly, and 16-bit
// formats cannot hold the disc. ibl.include_sun adds the Sun's energy as a
// point source through each level's kernel, not clamped, and with the
// night sky the Moon's (IblRequest::moon) the same way.
//
// The filtering runs on the Vulkan device (shaders/ibl_prefilter.comp):
// importance sampling whose samples read the source cube at the mip their
// solid angle covers (GPU Gems 3 ch. 20), so the bright sky near the Sun
// makes no fireflies with a few hundred samples.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "skybake/gpu_shared.h"
#include "skybake/gpu/pass_timing.h"
#include "skybake/gpu/vulkan_context.h"
#include "skybake/input/output_settings.h"
#include "skybake/model/atmosphere.h"

namespace skybake {

// Mip levels of the specular chain: ibl.levels, or down to 8 x 8 when 0.
int IblLevelCount(const IblSettings& settings);

// Perceptual roughness of level `level` of `levels`: level / (levels - 1)
// (0 for a chain of one level).
double IblRoughness(int level, int levels);

// The integral of (n.l) D(h) / 4 over the directions l with n.l > 0, for
// N = V and GGX alpha: the normalization of the specular filter's kernel, in closed
// form (ibl.cc derives it).
double IblSunKernelNormalization(double alpha);

// One cube level: six faces of size x size RGBA float texels, rows from the
// top, in the Vulkan face orientation.
struct CubeLevel {
  int size = 0;
  std::array<std::vector<float>, 6> faces;
};

// The next level down, each texel the mean of the 2 x 2 above it.
CubeLevel DownsampleCube(const CubeLevel& level);

// The six faces of a level stacked top to bottom (+X -X +Y -Y +Z -Z): one
// N x 6N RGBA image.
std::vector<float> StackFaces(const CubeLevel& level);

// Vulkan cube face and texel (x, y) that hold unit `direction` (the inverse
// of DirectionFromVulkanCubeTexel).
struct CubeTexel {
  int face = 0, x = 0, y = 0;
};
CubeTexel VulkanCubeTexelFromDirection(const glm::dvec3& direction, int face_size);

// What one frame needs.
struct IblRequest {
  IblSettings settings;
  glm::dvec3 sun_direction{0, 1, 0};  // unit, towards the Sun
  Rgb sun_irradiance{0, 0, 0};        // the Sun's irradiance at normal incidence, output units x sr
  bool dfg = false;                   // compute the DFG table too (once per bake)
  // The perceptual roughness of each level (level 0's must be 0), for a
  // comparison with another tool's mapping; empty: IblRoughness of
  // IblLevelCount(settings) levels.
  std::vector<double> roughness;
  // The Moon as a second point source (night sky, pipeline/night_sky.h):
  // with ibl.include_sun it goes into the maps as the Sun does; the Moon's
  // disc is, like the Sun's, left out of the filtered source.
  bool moon = false;
  glm::dvec3 moon_direction{0, 1, 0};
  Rgb moon_irradiance{0, 0, 0};  // after the atmosphere, output units x sr
};

struct IblMaps {
  std::vector<CubeLevel> specular;  // empty unless settings.specular
  CubeLevel irradiance;             // size 0 unless settings.irradiance
  int dfg_size = 0;                 // 0 unless request.dfg
  std::vector<float> dfg;           // dfg_size^2 RGBA texels, rows by roughness from 0 at the top
  double gltf_scale = 1.0;          // gltf.image_based_light: the PNGs' scale k (gltf_ibl.h)
};

// The filtering pipeline, created once per bake on the bake's device.
class IblBaker {
 public:
  explicit IblBaker(VulkanContext& context);
  ~IblBaker();
  IblBaker(const IblBaker&) = delete;
  IblBaker& operator=(const IblBaker&) = delete;

  // Filters `source` (the sky without the sun disc, level 0 of size
  // request.settings.size) into the maps the request asks for.
  IblMaps Bake(const IblRequest& request, const CubeLevel& source);

  const std::vector<PassTiming>& last_timings() const { return timings_; }

 private:
  struct Resources;
  static constexpr uint32_t kTimestampQueries = 8;  // a begin and an end for each of the four modes
  void Release();
  void CreateSourceImage(Resources& r, const std::vector<CubeLevel>& chain);
  void CreateOutputAndSet(Resources& r, VkDeviceSize texels);
  std::vector<int> RecordPasses(const Resources& r, const std::vector<gpu::IblPush>& passes);
  void ReadTimings(const std::vector<int>& modes);
  VulkanContext& context_;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout pipeline_layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  VkSampler sampler_ = VK_NULL_HANDLE;
  VkCommandPool command_pool_ = VK_NULL_HANDLE;
  VkQueryPool query_pool_ = VK_NULL_HANDLE;
  bool timestamps_ = false;
  std::vector<PassTiming> timings_;
};

// GGX samples of a specular level of perceptual roughness `roughness`:
// ibl.samples, or with ibl.full_samples_roughness = r0 > 0,
// clamp(ceil(ibl.samples x roughness / r0), 16, ibl.samples). With a fixed
// count the error against a converged reference grows with roughness (the
// lobe spans more of the sky's structure: docs/performance.md, 0.24% at
// roughness 1/6 to 1.1% at 1 for 256 samples), so the narrow lobes need
// fewer samples to stay within the roughest level's error.
int IblLevelSamples(const IblSettings& settings, double roughness);

}  // namespace skybake
