// The bake's renderers (private to the pipeline layer): one SkyRenderer per
// styled atmosphere and shader variant, kept across the frames of a
// sequence and rebuilt only when a frame changes what the shaders see.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "skybake/gpu/sky_renderer.h"
#include "skybake/gpu/vulkan_context.h"
#include "skybake/input/style.h"
#include "skybake/model/aoas.h"
#include "skybake/output/bake_record.h"

namespace skybake {

// What the shaders of one style see: the atmosphere with the hue principle
// applied (its Rayleigh constants), and the per-texel AOAS principles, whose
// saturation is judged in Rec.709 luminance RGB.
struct StyledInputs {
  AtmosphereParams atmosphere;
  AoasInputs aoas;
};
StyledInputs StyledInputsOf(const SkyStyle& style);

// The renderer for one styled atmosphere (it also renders without the disc,
// for the sky-only SH, from the same LUTs). Rebuilt only when a frame changes
// what the shaders see.
class RendererCache {
 public:
  RendererCache(VulkanContext& context, BakeResult& result, const ShaderSwitches& shaders)
      : context_(context), result_(result), shaders_(shaders) {}

  // `cloud_time_s`: the frame's clock time since the sequence's first frame,
  // which the wind moves the clouds by.
  SkyRenderer& Main(const SkyStyle& style, double cloud_time_s = 0.0) {
    Update(style, cloud_time_s);
    return *main_;
  }
  // The same, with the output conversion of a frame whose Sun is along
  // `sun` set on it (colour_conversion.h; luminance output only).
  SkyRenderer& Main(const SkyStyle& style, double cloud_time_s, const glm::dvec3& sun);
  // The renderer of the last frame.
  SkyRenderer& Current() { return *main_; }

 private:
  void Update(const SkyStyle& unpruned, double cloud_time_s);

  VulkanContext& context_;
  BakeResult& result_;
  ShaderSwitches shaders_;
  std::unique_ptr<SkyRenderer> main_;
  std::vector<std::unique_ptr<SkyRenderer>> retired_;
  gpu::GpuAtmosphere key_{};
  int wavelengths_ = 0;  // quality.wavelengths of main_
  AoasInputs aoas_key_;
  // What the frame's output conversion is computed from (Update), and the last one.
  // Near and below the horizon the host's single-scattering probe does not
  // hold (a twilight sky is multiple scattering and ozone): the sky matrix
  // is fitted to the spectral mode's own sky, 24 bins on the GPU, at the
  // same probe directions (FitTwilightSky).
  bool FitTwilightSky(const glm::dvec3& sun, Matrix3& sky);
  bool luminance_ = false;
  bool hue_ = false;           // the style's sky is a hue vector's colour
  bool twilight_fit_ = false;  // FitTwilightSky applies to the style
  QualitySettings probe_quality_;
  EffectSettings probe_effects_;
  std::unique_ptr<SkyRenderer> probe_;  // the 48-bin renderer of FitTwilightSky, built on first use
  AtmosphereParams conversion_atmosphere_;
  EffectSettings conversion_effects_;
  std::optional<glm::dvec3> conversion_sun_;
  OutputConversion conversion_;
};

}  // namespace skybake
