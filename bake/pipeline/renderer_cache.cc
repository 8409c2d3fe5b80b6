#include "renderer_cache.h"

#include <cstring>
#include <filesystem>

#include "skybake/input/config.h"
#include "skybake/pipeline/pass_plan.h"

namespace skybake {

StyledInputs StyledInputsOf(const SkyStyle& style) {
  return {StyledAtmosphere(style.atmosphere, style.aoas),
          ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance))};
}

SkyRenderer& RendererCache::Main(const SkyStyle& style, double cloud_time_s, const glm::dvec3& sun) {
  Update(style, cloud_time_s);
  if (!luminance_) return *main_;
  if (!conversion_sun_ || *conversion_sun_ != sun) {
    conversion_ = FrameOutputConversion(conversion_atmosphere_, conversion_effects_, sun);
    // A hue-styled sky (AOAS [hue]: a free RGB vector for the Rayleigh
    // constants) is a colour, not a spectrum: it keeps the conversion its
    // target colour is solved with (RayleighForTargetColor, the sky factors).
    if (hue_) conversion_.sky = UniformOutputConversion(BrunetonSkyFactors()).sky;
    else if (twilight_fit_) FitTwilightSky(sun, conversion_.sky);
    conversion_sun_ = sun;
  }
  main_->SetOutputConversion(conversion_);
  return *main_;
}

// Below this elevation of the Sun (deg) the sky matrix comes from the GPU's
// spectral mode: at 2 deg the host probe is within 0.0014 of the 48-bin
// mode, at -3 deg 0.008 (docs/colour.md).
constexpr double kTwilightProbeBelowDeg = 1.0;

bool RendererCache::FitTwilightSky(const glm::dvec3& sun, Matrix3& sky) {
  const AtmosphereParams& a = conversion_atmosphere_;
  const double elevation_deg = std::asin(std::clamp(sun.y, -1.0, 1.0)) * 180.0 / M_PI;
  if (elevation_deg >= kTwilightProbeBelowDeg ||
      !SunlitAirInView(elevation_deg, a.bottom_radius_km, a.top_radius_km, a.observer_altitude_m * 1e-3,
                       a.sun_angular_radius_rad))
    return false;
  if (!probe_) probe_ = std::make_unique<SkyRenderer>(context_, a, probe_quality_, probe_effects_, Rgb{1.0, 1.0, 1.0});
  const std::vector<glm::dvec3> directions = SkyProbeDirections(sun);
  const std::vector<float> reference = probe_->RenderDirections(sun, directions, false);
  // The main renderer's own radiance at the same directions, unconverted.
  main_->SetOutputConversion(UniformOutputConversion({1.0, 1.0, 1.0}));
  const std::vector<float> radiance = main_->RenderDirections(sun, directions, false);
  std::vector<Rgb> samples, targets;
  for (size_t i = 0; i < directions.size(); ++i) {
    samples.push_back({radiance[4 * i], radiance[4 * i + 1], radiance[4 * i + 2]});
    targets.push_back({reference[4 * i], reference[4 * i + 1], reference[4 * i + 2]});
  }
  return FitSkyMatrix(samples, targets, sky);
}

void RendererCache::Update(const SkyStyle& unpruned, double cloud_time_s) {
  // The pass plan's pruning: zero-strength and unused effects compiled out.
  const SkyStyle style = PrunedStyle(unpruned);
  StyledInputs in = StyledInputsOf(style);
  const bool luminance = style.output.units == OutputUnits::kLuminance && style.quality.wavelengths <= kRgbWavelengths;
  // The conversion's probe reads the atmosphere and whether aerosols and ozone are on.
  const bool hue = style.aoas.hue.enabled && style.aoas.hue.strength > 0.0;
  // The twilight fit compares the renderer's radiance with the spectral
  // mode's sky: a style whose principles change a texel's colour or direction
  // (AOAS noise, shapes, ambiguity, the skydome; the night floor), or whose
  // cloud layers stand in front of the sky, keeps the host's fit, which
  // they do not touch.
  const AoasSwitches& s = in.aoas.switches;
  const bool twilight_fit = !style.effects.night_dimming && !s.skydome && !s.ambiguity && !s.cloud_noise &&
                            !s.cloud_shapes && ActiveCloudLayers(style.clouds).empty();
  if (luminance != luminance_ || hue != hue_ || twilight_fit != twilight_fit_ ||
      std::memcmp(&in.atmosphere, &conversion_atmosphere_, sizeof in.atmosphere) != 0 ||
      style.effects.mie != conversion_effects_.mie || style.effects.ozone != conversion_effects_.ozone) {
    luminance_ = luminance;
    hue_ = hue;
    probe_quality_ = style.quality;
    // 24 bins: on colour_test's twilight frames its matrix is within u'v'
    // 0.0002 of a 48-bin probe's, at half the groups; a coarse sky-view LUT
    // (its rows at the probe's directions are marched or smooth) changes
    // nothing there.
    probe_quality_.wavelengths = 24;
    probe_quality_.sky_view_width = 64;
    probe_quality_.sky_view_height = 72;
    probe_effects_ = style.effects;
    probe_.reset();
    twilight_fit_ = twilight_fit;
    conversion_atmosphere_ = in.atmosphere;
    conversion_effects_ = style.effects;
    conversion_sun_.reset();
  }
  CloudInputs clouds = ToCloudInputs(style.clouds, style.aoas.seed,
                                     std::filesystem::path(style.source_path).parent_path().string(), cloud_time_s);
  ApplyGroundCloudShadow(style.cloud_shadow, clouds);  // the ground below the horizon in the clouds' shadow
  // New cloud parameters (the wind's offsets of this frame) in place, or a
  // new renderer; so is another number of wavelengths (the spectral mode's
  // groups of bins, which the atmosphere's key does not hold).
  const bool clouds_kept = !main_ || (wavelengths_ == style.quality.wavelengths && main_->UpdateClouds(clouds));
  gpu::GpuAtmosphere key =
      ToGpuAtmosphere(in.atmosphere, style.quality, style.effects, OutputScale(style.output.units));
  // A new atmosphere with the same shader variant (a scheduled drift of
  // its constants): new uniforms and LUTs, the same pipelines.
  if (clouds_kept && main_ && std::memcmp(&key, &key_, sizeof key) != 0 &&
      main_->UpdateAtmosphere(in.atmosphere, style.quality, style.effects, OutputScale(style.output.units))) {
    key_ = key;
    ++result_.atmosphere_updates;
  }
  if (clouds_kept && main_ && std::memcmp(&key, &key_, sizeof key) == 0) {
    // Same atmosphere: the LUTs stay; per-texel AOAS parameters (a cloud
    // drift, say) change in place when the shader variant is the same.
    if (std::memcmp(&in.aoas.uniform, &aoas_key_.uniform, sizeof(gpu::GpuAoas)) == 0 &&
        in.aoas.switches.skydome == aoas_key_.switches.skydome &&
        in.aoas.switches.ambiguity == aoas_key_.switches.ambiguity &&
        in.aoas.switches.cloud_noise == aoas_key_.switches.cloud_noise &&
        in.aoas.switches.cloud_shapes == aoas_key_.switches.cloud_shapes)
      return;
    if (main_->UpdateAoas(in.aoas)) {
      aoas_key_ = in.aoas;
      return;
    }
  }
  // A renderer whose frame the writer thread still reads lives on until
  // that frame is written.
  std::erase_if(retired_, [](const std::unique_ptr<SkyRenderer>& r) { return !r->HoldsFrames(); });
  if (main_ && main_->HoldsFrames()) retired_.push_back(std::move(main_));
  main_.reset();
  main_ = std::make_unique<SkyRenderer>(context_, in.atmosphere, style.quality, style.effects,
                                        OutputScale(style.output.units), false, in.aoas, clouds, shaders_);
  ++result_.renderer_builds;
  wavelengths_ = style.quality.wavelengths;
  key_ = key;
  aoas_key_ = in.aoas;
}

}  // namespace skybake
