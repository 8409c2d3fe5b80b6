// SkyRenderer::RenderCloudShadow: the cloud shadow map pass
// (shaders/cloud_shadow.comp, cloud_shadow.h), on the renderer's cloud
// layers and noise.
#include <cstdint>
#include <cstring>

#include "shaders/kCloudShadowSpv.spv.h"
#include "skybake/model/cloud_shadow.h"
#include "skybake/gpu/sky_renderer.h"
#include "skybake/gpu/spectral_sky.h"

namespace skybake {
namespace {

int32_t FloatBits(double v) {
  const float f = float(v);
  int32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  return bits;
}

}  // namespace

std::vector<float> SkyRenderer::RenderCloudShadow(const glm::dvec3& sun, const CloudShadowSettings& s) {
  // The clouds are grey: one group's map is every wavelength's.
  if (spectral_) return spectral_->group(0).RenderCloudShadow(sun, s);
  const size_t texels = size_t(s.resolution) * s.resolution;
  // The Sun's centre at or below the horizon: no direct sunlight, zeros;
  // without cloud layers nothing shadows it: ones.
  if (sun.y <= 0.0 || cloud_layers_ == 0 || s.strength == 0.0) {
    timings_.clear();  // no pass ran
    return std::vector<float>(texels, sun.y <= 0.0 ? 0.0f : 1.0f);
  }
  if (!luts_ready_) PrecomputeLuts();
  if (cloud_shadow_pipeline_ == VK_NULL_HANDLE) {
    cloud_shadow_pipeline_ = CreatePipeline(kCloudShadowSpv, sizeof(kCloudShadowSpv), effects_.sun_disc, false);
    ++counters_.pipelines;
  }
  EnsureOutputCapacity(std::max<size_t>(texels, 1) * 16);
  BindOutput(output_buffer_);
  gpu::SkyPush push{};
  push.sun_direction = {float(sun.x), float(sun.y), float(sun.z), float(s.strength)};
  push.view = {0, s.resolution, s.resolution, s.steps};
  push.offsets = {0, 0, 0, 0};
  const double west_km = (s.center_east_m - 0.5 * s.extent_m) * 1e-3;
  const double north_z_km = -(s.center_north_m + 0.5 * s.extent_m) * 1e-3;
  push.rect = {FloatBits(west_km), FloatBits(north_z_km), FloatBits(s.extent_m / s.resolution * 1e-3),
               FloatBits(s.receiver_altitude_m * 1e-3)};
  const uint32_t groups = uint32_t((s.resolution + SKYBAKE_LOCAL_SIZE_X - 1) / SKYBAKE_LOCAL_SIZE_X);
  Submit({{"cloud shadow map", cloud_shadow_pipeline_, push, groups, groups}}, {false});
  const float* data = static_cast<const float*>(output_buffer_.mapped);
  std::vector<float> map(texels);
  for (size_t i = 0; i < texels; ++i) map[i] = data[4 * i];
  return map;
}

}  // namespace skybake
