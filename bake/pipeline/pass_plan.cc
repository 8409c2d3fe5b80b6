#include "skybake/pipeline/pass_plan.h"
#include "cloud_plan.h"

#include "skybake/gpu/ibl.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "skybake/model/aoas.h"
#include "skybake/gpu/sky_renderer.h"
#include "skybake/pipeline/engine_files.h"
#include "skybake/pipeline/night_sky.h"

namespace skybake {
namespace {

bool AnyPositive(const Rgb& v) { return v[0] > 0.0 || v[1] > 0.0 || v[2] > 0.0; }

// A rough cost per medium sample (3 exponentials, two bilinear LUT reads,
// phase functions): for the "estimated work" line only.
constexpr double kFlopPerSample = 60.0;

std::string Size(int w, int h) { return fmt::format("{} x {}", w, h); }

}  // namespace

SkyStyle PrunedStyle(const SkyStyle& style) {
  SkyStyle s = style;
  EffectSettings& e = s.effects;
  const AtmosphereParams& a = style.atmosphere;
  e.mie = e.mie && (AnyPositive(a.mie_scattering_per_km) || AnyPositive(a.mie_extinction_per_km));
  e.ozone = e.ozone && AnyPositive(a.ozone_absorption_per_km);
  e.ground = e.ground && AnyPositive(a.ground_albedo);
  e.sun_disc = e.sun_disc && e.sun_disc_strength > 0.0 && AnyPositive(a.solar_irradiance);
  const bool scatters = AnyPositive(style.aoas.hue.enabled ? StyledAtmosphere(a, style.aoas).rayleigh_scattering_per_km
                                                           : a.rayleigh_scattering_per_km) ||
                        (e.mie && AnyPositive(a.mie_scattering_per_km));
  e.multiple_scattering = e.multiple_scattering && e.multiple_scattering_strength > 0.0 && scatters;
  e.night_dimming = e.night_dimming && e.night_dimming_strength > 0.0;
  // night.airglow replaces the flat night floor (night_sky.h): the dimming
  // then blends the Sun's sky to black and the glow is added on the host.
  if (s.night.airglow) e.night_sky_luminance_cd_m2 = 0.0;
  AoasSettings& x = s.aoas;
  x.hue.enabled = x.hue.enabled && x.hue.strength > 0.0;
  x.ambiguity.enabled = x.ambiguity.enabled && x.ambiguity.l_pt > 0.0;
  x.clouds.enabled = x.clouds.enabled && x.clouds.strength > 0.0;
  x.shapes.enabled = x.shapes.enabled && x.shapes.strength > 0.0 && !x.shapes.shapes.empty();
  return s;
}

bool NeedsSkyViewLut(const SkyStyle& style) { return style.quality.sky_view_lut && !style.aoas.skydome.enabled; }

bool RendersLatlong(const SkyStyle& style) { return style.output.latlong || WritesLatlongPng(style); }

bool WritesLatlongPng(const SkyStyle& style) { return style.output.preview || style.gltf.enabled; }

std::vector<ViewRequest> PlanViews(const SkyStyle& style) {
  std::vector<ViewRequest> views;
  const int n = style.render.cube_size;
  if (style.output.faces)
    for (int face = 0; face < 6; ++face) views.push_back({MAPPING_VULKAN_FACE, n, n, face});
  if (style.output.cube_strip) views.push_back({MAPPING_CUBE_STRIP, n, 6 * n, 0});
  if (RendersLatlong(style)) {
    const int h = style.render.latlong_height;
    views.push_back({MAPPING_LATLONG, 2 * h, h, 0});
  }
  return views;
}

namespace {

// Effects, with the keys that decided them.
void PlanEffects(const SkyStyle& first, const SkyStyle& pruned, PassPlan& plan) {
  const EffectSettings& r = first.effects;
  const EffectSettings& p = pruned.effects;
  const AtmosphereParams& a = first.atmosphere;
  auto decide = [&](const std::string& name, bool requested, bool on, const std::string& why_off,
                    const std::string& why_on) {
    plan.effects.push_back({name, requested, on, on ? why_on : (requested ? why_off : "switched off in the style")});
  };
  decide("multiple scattering", r.multiple_scattering, p.multiple_scattering,
         "effects.multiple_scattering_strength = 0 or nothing scatters",
         fmt::format("effects.multiple_scattering = true, strength {}", r.multiple_scattering_strength));
  decide("Mie (aerosols)", r.mie, p.mie, "atmosphere.mie coefficients are all 0",
         "atmosphere.mie.scattering_per_km / extinction_per_km > 0");
  decide("ozone", r.ozone, p.ozone, "atmosphere.ozone.absorption_per_km is 0",
         "atmosphere.ozone.absorption_per_km > 0");
  decide("ground bounce", r.ground, p.ground, "atmosphere.ground_albedo is 0",
         fmt::format("atmosphere.ground_albedo = [{}, {}, {}]", a.ground_albedo[0], a.ground_albedo[1],
                     a.ground_albedo[2]));
  decide("sun disc", r.sun_disc, p.sun_disc, "effects.sun_disc_strength = 0 or no irradiance",
         fmt::format("effects.sun_disc = true, strength {}", r.sun_disc_strength));
  const AoasSettings& xr = first.aoas;
  const AoasSettings& xp = pruned.aoas;
  decide("skydome (AOAS 3.2)", xr.skydome.enabled, xp.skydome.enabled, "", "[skydome] enabled = true");
  decide("hue override", xr.hue.enabled, xp.hue.enabled, "hue.strength = 0",
         fmt::format("[hue] enabled, strength {}", xr.hue.strength));
  decide("ambiguity (eq. 5-6)", xr.ambiguity.enabled, xp.ambiguity.enabled, "ambiguity.l_pt = 0",
         fmt::format("[ambiguity] enabled, l_pt {}", xr.ambiguity.l_pt));
  decide("cloud noise (eq. 7-8)", xr.clouds.enabled, xp.clouds.enabled, "clouds.strength = 0",
         fmt::format("[clouds] enabled, strength {}", xr.clouds.strength));
  decide("cloud shapes", xr.shapes.enabled, xp.shapes.enabled, "shapes.strength = 0 or no shape",
         fmt::format("[shapes] enabled, {} shapes", xr.shapes.shapes.size()));
  {
    // Volumetric cloud layers: on when a layer has coverage and density.
    const std::vector<CloudLayer> active = ActiveCloudLayers(first.clouds);
    std::string why_on;
    for (const CloudLayer& l : active)
      why_on +=
          fmt::format("{}{} at {}-{} m, coverage {}, density {} /m", why_on.empty() ? "" : "; ", CloudTypeName(l.type),
                      l.altitude_m, l.altitude_m + l.thickness_m, l.coverage, l.density_per_m);
    decide("volumetric clouds", !first.clouds.layers.empty(), !active.empty(),
           "every [[cloud_layer]] has coverage 0 or density_per_m 0 (pruned)",
           fmt::format("{} [[cloud_layer]]: {}", active.size(), why_on));
  }
  decide("twilight and night dimming", r.night_dimming, p.night_dimming, "effects.night_dimming_strength = 0",
         fmt::format("effects.night_dimming = true, strength {}, night sky {} cd/m^2", r.night_dimming_strength,
                     r.night_sky_luminance_cd_m2));

  // The night sky (night_sky.h): stars and the Moon's disc splatted on the
  // host, moonlight a second render with the Moon as the light.
  const NightSettings& night = first.night;
  decide("night sky (stars, Moon, moonlight, airglow)", night.Any(), night.Any(), "",
         fmt::format("night.stars = {} (to V {}), night.moon = {}, night.moonlight = {}, night.airglow = {}",
                     night.stars, night.star_magnitude_limit, night.moon, night.moonlight, night.airglow));
}

// Distinct atmospheres over the frames: each one rebuilds the LUTs.
int DistinctAtmospheres(const std::vector<SkyStyle>& frames) {
  std::vector<gpu::GpuAtmosphere> keys;
  for (const SkyStyle& f : frames) {
    SkyStyle fp = PrunedStyle(f);
    gpu::GpuAtmosphere key =
        ToGpuAtmosphere(StyledAtmosphere(fp.atmosphere, fp.aoas), fp.quality, fp.effects, OutputScale(fp.output.units));
    bool seen = std::any_of(keys.begin(), keys.end(),
                            [&](const gpu::GpuAtmosphere& k) { return std::memcmp(&k, &key, sizeof key) == 0; });
    if (!seen) keys.push_back(key);
  }
  return int(keys.size());
}

// Samples per rendered texel: one LUT read with the sky-view LUT, else the
// ray march (times the light march when the Sun's transmittance is marched).
double SamplesPerTexel(const SkyStyle& first, const SkyStyle& pruned) {
  const QualitySettings& q = first.quality;
  return NeedsSkyViewLut(pruned) ? 1.0 : double(q.view_steps) * std::max(q.light_steps, 1);
}

// The sky: the LUTs and the render of every view.
void PlanSkyPasses(const SkyStyle& first, const SkyStyle& pruned, PassPlan& plan) {
  const EffectSettings& p = pruned.effects;
  const QualitySettings& q = first.quality;
  const int light = std::max(q.light_steps, 1);
  if (NeedsTransmittanceLut(q, p) || !ActiveCloudLayers(first.clouds).empty())
    plan.passes.push_back({"transmittance LUT", Size(q.transmittance_width, q.transmittance_height),
                           "once per atmosphere", plan.atmospheres,
                           double(q.transmittance_width) * q.transmittance_height * q.transmittance_steps});
  if (p.multiple_scattering)
    plan.passes.push_back({"multiple-scattering LUT", Size(q.multiscattering_size, q.multiscattering_size),
                           "once per atmosphere", plan.atmospheres,
                           double(q.multiscattering_size) * q.multiscattering_size * q.multiscattering_sqrt_dirs *
                               q.multiscattering_sqrt_dirs * q.multiscattering_steps});
  const bool sky_view = NeedsSkyViewLut(pruned);
  if (sky_view)
    plan.passes.push_back({"sky-view LUT", Size(q.sky_view_width, q.sky_view_height), "once per frame", plan.frames,
                           double(q.sky_view_width) * q.sky_view_height * q.view_steps * light});
  const double per_texel = sky_view ? 1.0 : double(q.view_steps) * light;
  for (const ViewRequest& v : PlanViews(first)) {
    std::string name = v.mapping == MAPPING_LATLONG      ? "render latlong"
                       : v.mapping == MAPPING_CUBE_STRIP ? "render cube strip"
                                                         : fmt::format("render face {}", v.face);
    plan.passes.push_back({name, Size(v.width, v.height), sky_view ? "once per frame (LUT reads)" : "once per frame",
                           plan.frames, double(v.width) * v.height * per_texel});
  }
  // The engine preset's images (engine_files.h): the sky pass again along the engine's directions.
  for (const EngineImageSize& e : PlanEngineImages(first))
    plan.passes.push_back({"render engine " + e.suffix, Size(e.width, e.height),
                           sky_view ? "once per frame (LUT reads)" : "once per frame", plan.frames,
                           double(e.width) * e.height * per_texel});
}

// The twilight band's march (quality.twilight_march_band_deg): in the
// frames whose Sun is below TwilightSunElevationDeg (listed only when there
// is one), the texels from the observer's horizon (the dip below the
// horizontal: acos(R / r), 0 at the ground) up to the band above the
// horizontal (InTwilightMarchBand), a fraction (sin(band) + sin(dip)) / 2 of
// each view's directions, and, above it, the texels on the Earth's shadow's
// edge (TwilightMarchWeight: at most kTwilightAboveBandShare of the
// directions, docs/accuracy.md) are ray-marched by a sky pass of their own
// pipeline, unless the Sun is too low for any sunlit air to be in view.
void PlanTwilightBand(const std::vector<SkyStyle>& frames, const SkyStyle& first, const SkyStyle& pruned,
                      const ShaderSwitches& shaders, PassPlan& plan) {
  const QualitySettings& q = first.quality;
  const double band = q.twilight_march_band_deg;
  const double below = TwilightSunElevationDeg(q);
  if (!(band > 0.0) || !(below > 0.0) || !NeedsSkyViewLut(pruned)) return;
  // A Sun past SunlitAirDepressionDeg leaves no sunlit air in view: the frame
  // reads the LUT alone (SkyRenderer::MarchesTwilightBand).
  const int runs = int(std::count_if(frames.begin(), frames.end(), [&](const SkyStyle& f) {
    const AtmosphereParams& a = f.atmosphere;
    return f.sun.elevation_deg < below && SunlitAirInView(f.sun.elevation_deg, a.bottom_radius_km, a.top_radius_km,
                                                          a.observer_altitude_m * 1e-3, a.sun_angular_radius_rad);
  }));
  if (runs == 0) return;  // no twilight frame: the pass never runs
  double texels = 0.0;
  for (const ViewRequest& v : PlanViews(first)) texels += double(v.width) * v.height;
  const int steps = q.twilight_march_steps > 0 ? q.twilight_march_steps : q.view_steps;
  const AtmosphereParams& a = first.atmosphere;
  const double ratio = a.bottom_radius_km / (a.bottom_radius_km + std::max(a.observer_altitude_m, 0.0) * 1e-3);
  const double dip_deg = std::acos(std::min(ratio, 1.0)) * 180.0 / M_PI;
  const std::string extent =
      dip_deg > 0.0
          ? fmt::format("the horizon ({:.2f} deg below the horizontal) to {:g} deg above the horizontal", dip_deg, band)
          : fmt::format("0..{:g} deg above the horizon", band);
  const double fraction = 0.5 * (std::sin(band * M_PI / 180.0) + std::sin(dip_deg * M_PI / 180.0));
  const double night_deg = SunlitAirDepressionDeg(a.bottom_radius_km, a.top_radius_km, a.observer_altitude_m * 1e-3,
                                                  a.sun_angular_radius_rad);
  // A sequence's frames whose half-float views the march would not change
  // are not marched; which ones needs renders (pipeline/twilight_skip.h).
  const bool probed = shaders.twilight_skip && frames.size() > 1 && first.output.pixel_type == PixelType::kHalf &&
                      !first.night.Any() && ActiveCloudLayers(pruned.clouds).empty();
  const std::string skip =
      probed ? ", less those it changes by under a quarter of a half-float step (probed at the exposure stage)" : "";
  plan.passes.push_back(
      {"twilight band march", extent,
       night_deg >= 180.0
           ? fmt::format("frames with the Sun below {:g} deg (sunlit air in view from space){}", below, skip)
           : fmt::format("frames with the Sun below {:g} deg and above -{:.1f} deg{}", below, night_deg, skip),
       runs, texels * (fraction + kTwilightAboveBandShare) * steps * std::max(q.light_steps, 1)});
}

// Whether the sun disc is a pass of its own (UsesSunDiscPass).
bool PlansSunDiscPass(const SkyStyle& first, const SkyStyle& pruned, const ShaderSwitches& shaders) {
  const AoasSettings& xp = pruned.aoas;
  AoasSwitches switches;
  switches.skydome = xp.skydome.enabled;
  switches.ambiguity = xp.ambiguity.enabled;
  // The spectral mode's groups leave the saturation to the style pass (spectral_sky.h).
  const bool spectral = first.quality.wavelengths > kRgbWavelengths;
  switches.cloud_noise = xp.clouds.enabled && !spectral;
  switches.cloud_shapes = xp.shapes.enabled && !spectral;
  return UsesSunDiscPass(first.quality, pruned.effects, switches, shaders);
}

// Frame numbers (plan order) as runs: "0-17, 80-95".
std::string FrameRanges(const std::vector<int>& frames) {
  std::string out;
  for (size_t i = 0; i < frames.size();) {
    size_t j = i;
    while (j + 1 < frames.size() && frames[j + 1] == frames[j] + 1) ++j;
    out +=
        (out.empty() ? "" : ", ") + (j == i ? std::to_string(frames[i]) : fmt::format("{}-{}", frames[i], frames[j]));
    i = j + 1;
  }
  return out;
}

// The Sun's elevation, deg, below which every band of the style's active
// cloud layers is in the Earth's shadow, and their highest top, km: from the
// values the renderer is given (the pruned style's cloud and atmosphere
// uniforms, as RendererCache::Update builds them), so the plan lists exactly
// the frames SkyRenderer::CloudsInEarthShadow marches without the light march.
double CloudShadowBelowDeg(const SkyStyle& style, double* top_km) {
  const SkyStyle pruned = PrunedStyle(style);
  const gpu::GpuClouds clouds = CloudGeometryUniform(pruned.clouds);
  *top_km = 0.0;
  for (int b = 0; b < clouds.resolution.w; ++b) *top_km = std::max(*top_km, double(clouds.bands[b].y));
  return CloudEarthShadowElevationDeg(
      clouds, ToGpuAtmosphere(StyledAtmosphere(pruned.atmosphere, pruned.aoas), pruned.quality, pruned.effects,
                              OutputScale(pruned.output.units)));
}

// Volumetric cloud layers: the noise volumes, the tables, every view; the
// effect "clouds in the Earth's shadow": the frames whose cloud march runs
// without the Sun's light march (SkyRenderer::CloudsInEarthShadow).
void PlanCloudPasses(const std::vector<SkyStyle>& frames, const SkyStyle& first, const ShaderSwitches& shaders,
                     PassPlan& plan) {
  const std::vector<CloudLayer> cloud_layers = ActiveCloudLayers(first.clouds);
  const CloudQuality& cq = first.clouds.quality;
  if (!cloud_layers.empty()) {
    double top_km = 0.0;
    const double below = CloudShadowBelowDeg(first, &top_km);
    std::vector<int> shadowed;
    for (size_t i = 0; i < frames.size(); ++i)
      if (frames[i].sun.elevation_deg < below) shadowed.push_back(int(i));
    const std::string geometry = fmt::format(
        "the Sun below {:.2f} deg: every band (top {:g} km, within {:g} km) in "
        "the Earth's shadow",
        below, top_km, cq.max_distance_km);
    const bool on = shaders.shadowed_clouds && !shadowed.empty();
    plan.effects.push_back(
        {"clouds in the Earth's shadow", true, on,
         !shaders.shadowed_clouds ? "SKYBAKE_SHADOWED_CLOUDS=0: every frame's clouds march the Sun's light"
         : on ? fmt::format("{} of {} frames (plan order {}) with {}: their cloud march runs without the Sun's "
                            "light march (constant 21 off), the same bytes",
                            shadowed.size(), frames.size(), FrameRanges(shadowed), geometry)
              : fmt::format("no frame with {}", geometry)});
    if (!shaders.shadowed_clouds) shadowed.clear();
    const int layers = int(cloud_layers.size());
    const double shape = double(cq.shape_resolution) * cq.shape_resolution * cq.shape_resolution;
    const double detail = double(cq.detail_resolution) * cq.detail_resolution * cq.detail_resolution;
    plan.passes.push_back({"cloud noise volumes",
                           fmt::format("{} x ({}^3 + {}^3 + {}^2)", layers, cq.shape_resolution, cq.detail_resolution,
                                       cq.weather_resolution),
                           "once per bake (from the seeds)", 1,
                           layers * (shape + detail + double(cq.weather_resolution) * cq.weather_resolution)});
    // CloudInputs: aerial perspective 32 x 64 x 32 (4 steps per slice),
    // ambient 16 altitudes x 64 directions x 16 steps.
    plan.passes.push_back({"cloud tables", "AP 32 x 64 x 32, ambient 16", "once per frame", plan.frames,
                           32.0 * 64 * 32 * 4 + 16.0 * 64 * 16});
    AddCloudMarchPlan(first, layers, PlanViews(first), plan.frames, int(shadowed.size()), below,
                      plan);  // cloud_plan.h: panorama or views
  }
}

// Moonlight: a second render of the sky with the Moon as the light.
void PlanMoonlitPasses(const SkyStyle& first, const SkyStyle& pruned, PassPlan& plan) {
  const NightSettings& night = first.night;
  const QualitySettings& q = first.quality;
  const int light = std::max(q.light_steps, 1);
  const bool sky_view = NeedsSkyViewLut(pruned);
  const double per_texel = SamplesPerTexel(first, pruned);
  if (night.moonlight && sky_view)
    plan.passes.push_back({"moonlit sky-view LUT", Size(q.sky_view_width, q.sky_view_height),
                           "per frame with the Sun down and the Moon above -10 deg", plan.frames,
                           double(q.sky_view_width) * q.sky_view_height * q.view_steps * light});
  if (night.moonlight)
    for (const ViewRequest& v : PlanViews(first))
      plan.passes.push_back({"moonlit sky " + (v.mapping == MAPPING_LATLONG      ? std::string("latlong")
                                               : v.mapping == MAPPING_CUBE_STRIP ? std::string("cube strip")
                                                                                 : fmt::format("face {}", v.face)),
                             Size(v.width, v.height), "per frame with the Sun down and the Moon above -10 deg",
                             plan.frames, double(v.width) * v.height * per_texel});
}

// Image-based lighting (ibl.h): only when an IBL output is asked for.
// Its samples are filtered cube reads, not medium samples: not in the total.
void PlanIblPasses(const SkyStyle& first, const SkyStyle& pruned, PassPlan& plan) {
  const double per_texel = SamplesPerTexel(first, pruned);
  const IblSettings& ibl = first.ibl;
  if (ibl.Requested()) {
    const double source_texels = 6.0 * ibl.size * ibl.size;
    plan.passes.push_back({"IBL source (no sun disc)", Size(ibl.size, ibl.size) + " x6", "once per frame", plan.frames,
                           source_texels * per_texel});
    if (ibl.specular) {
      double texels = 0.0, reads = 0.0;
      std::string counts;  // per level, with ibl.lobe_samples
      for (int level = 1; level < IblLevelCount(ibl); ++level) {
        const double t = 6.0 * std::pow(double(ibl.size >> level), 2);
        const double r = IblRoughness(level, IblLevelCount(ibl));
        const int n = IblLevelSamples(ibl, r);
        texels += t;
        reads += t * n;
        counts += (counts.empty() ? "" : " ") + std::to_string(n);
      }
      plan.passes.push_back({fmt::format("IBL specular {} levels", IblLevelCount(ibl)),
                             ibl.full_samples_roughness > 0.0 ? fmt::format("{} samples (levels 1..)", counts)
                                                              : fmt::format("{} samples", ibl.samples),
                             "once per frame (cube reads)", plan.frames, reads});
    }
    if (ibl.irradiance)
      plan.passes.push_back({"IBL irradiance", Size(ibl.irradiance_size, ibl.irradiance_size) + " x6",
                             "once per frame (cube reads)", plan.frames,
                             6.0 * ibl.irradiance_size * ibl.irradiance_size * ibl.irradiance_samples});
    if (ibl.dfg)
      plan.passes.push_back({"IBL DFG table", Size(ibl.dfg_size, ibl.dfg_size), "once per bake", 1,
                             double(ibl.dfg_size) * ibl.dfg_size * ibl.dfg_samples});
  }
}

// The specialization constants of the render shader, the SPIR-V it comes
// from, the sun-disc and cloud passes.
std::string DescribeVariant(const SkyStyle& first, const SkyStyle& pruned, bool disc_pass,
                            const ShaderSwitches& shaders) {
  const EffectSettings& p = pruned.effects;
  const AoasSettings& xp = pruned.aoas;
  const QualitySettings& q = first.quality;
  const bool sky_view = NeedsSkyViewLut(pruned);
  const std::vector<CloudLayer> cloud_layers = ActiveCloudLayers(first.clouds);
  double top_km = 0.0;
  const CloudQuality& cq = first.clouds.quality;
  std::string variant;
  static const char* kIntegrators[] = {"analytic", "midpoint", "trapezoid", "simpson"};
  variant = fmt::format(
      "sky_render: multiple_scattering={} sun_disc={} ground={} mie={} ozone={} night={} skydome={} ambiguity={} "
      "cloud_noise={} cloud_shapes={} integrator={} sky_view={}",
      p.multiple_scattering, p.sun_disc, p.ground, p.mie, p.ozone, p.night_dimming, xp.skydome.enabled,
      xp.ambiguity.enabled, xp.clouds.enabled, xp.shapes.enabled, kIntegrators[std::clamp(q.integrator, 0, 3)],
      sky_view);
  const ShaderSources sources = ChooseShaderSources(q, xp.skydome.enabled, shaders);
  variant += fmt::format(
      "\n  SPIR-V: sky_render {}; LUT shaders {}",
      sources.sky_view_render ? "from the built-in sky-view variant (ray march compiled out)"
                              : "generic, specialized at pipeline creation",
      sources.analytic_luts ? "from the built-in analytic variants" : "generic, specialized at pipeline creation");
  if (disc_pass)
    variant += "\n  sun disc: compiled out of sky_render and added by a pass of its own over the texels near the Sun";
  if (!cloud_layers.empty())
    variant += fmt::format(
        "\n  clouds: cloud_render with {} layer(s) compiled in (constant 20), after the sky and sun-disc passes; "
        "per texel at most {} view steps per layer crossing (a third of them for a vertical crossing), {} light "
        "steps per lit sample, {} scattering octaves, no cloud beyond {} km; {}",
        cloud_layers.size(), cq.view_steps, cq.light_steps, cq.octaves, cq.max_distance_km,
        shaders.shadowed_clouds
            ? fmt::format("a frame with the Sun below {:.2f} deg (every band in the Earth's shadow) runs it with "
                          "constant 21 off: no Sun's light, no light march",
                          CloudShadowBelowDeg(first, &top_km))
            : "every frame with the Sun's light march (SKYBAKE_SHADOWED_CLOUDS=0)");
  else variant += "\n  clouds: none (no cloud pipeline, no noise volume, no cloud pass)";
  return variant;
}

// What a sequence computes once and reuses.
void PlanReuse(PassPlan& plan) {
  if (plan.frames > 1) {
    if (plan.atmospheres == 1)
      plan.reused.push_back("transmittance and multiple-scattering LUTs: built once, reused by all " +
                            std::to_string(plan.frames) + " frames (the atmosphere does not change)");
    else
      plan.reused.push_back(
          fmt::format("transmittance and multiple-scattering LUTs: built {} times, once per "
                      "distinct atmosphere of the schedule",
                      plan.atmospheres));
    plan.reused.push_back("pipelines: compiled once per atmosphere, never per frame");
  }
}

}  // namespace

PassPlan PlanPasses(const std::vector<SkyStyle>& frames, const ShaderSwitches& shaders,
                    const std::vector<double>& hours_from_start) {
  PassPlan plan;
  plan.frames = int(frames.size());
  if (frames.empty()) return plan;
  const SkyStyle& first = frames.front();
  const SkyStyle pruned = PrunedStyle(first);
  PlanEffects(first, pruned, plan);
  plan.atmospheres = DistinctAtmospheres(frames);
  // The passes in the order they run; medium samples over the bake.
  PlanSkyPasses(first, pruned, plan);
  PlanTwilightBand(frames, first, pruned, shaders, plan);
  const bool disc_pass = PlansSunDiscPass(first, pruned, shaders);
  if (disc_pass) plan.passes.push_back({"sun disc", "near the Sun", "once per frame", plan.frames, 0.0});
  // The spectral mode (spectral_sky.h): the passes so far run once per group of three bins.
  if (const int n = first.quality.wavelengths; n > kRgbWavelengths) {
    const int groups = (n + 2) / 3;
    for (PlannedPass& pass : plan.passes) pass.runs *= groups;
    plan.effects.push_back({"spectral mode", true, true,
                            fmt::format("quality.wavelengths = {}: {} groups of 3 wavelengths, each with its own "
                                        "LUTs and views (the sky passes' runs count them)",
                                        n, groups)});
    // The principles that act on a texel's colour, once on the combined colour.
    if (pruned.aoas.clouds.enabled || pruned.aoas.shapes.enabled || pruned.effects.night_dimming)
      plan.passes.push_back({"style", "every texel", "once per frame", plan.frames, 0.0});
  }
  PlanCloudPasses(frames, first, shaders, plan);
  PlanMoonlitPasses(first, pruned, plan);
  AddNightSkyPlan(frames, plan);                 // night_sky.h: the host's splat and glow, and what prunes them
  AddCloudShadowPlan(first, plan.frames, plan);  // cloud_plan.h
  for (const PlannedPass& pass : plan.passes) plan.total_samples += pass.samples * pass.runs;
  AddCloudFormationPlan(frames, hours_from_start, plan);  // CPU cell updates, not medium samples
  PlanIblPasses(first, pruned, plan);
  plan.variant = DescribeVariant(first, pruned, disc_pass, shaders);
  PlanReuse(plan);
  return plan;
}

std::string FormatPlan(const PassPlan& plan, const std::string& source) {
  std::string out = fmt::format("plan for {}: {} frame{}, {} atmosphere{}\n\neffects:\n", source, plan.frames,
                                plan.frames == 1 ? "" : "s", plan.atmospheres, plan.atmospheres == 1 ? "" : "s");
  for (const EffectDecision& e : plan.effects)
    out += fmt::format("  {:<28} {:<4} {}\n", e.name, e.on ? "on" : "off", e.reason);
  out += "\npasses:\n";
  for (const PlannedPass& p : plan.passes)
    out += fmt::format("  {:<26} {:>12}  {:<28} x{:<5} {:>10.3g} samples/run\n", p.name, p.size, p.frequency, p.runs,
                       p.samples);
  out += fmt::format("\nshader variant:\n  {}\n", plan.variant);
  out += fmt::format("\nestimated work: {:.3g} medium samples, about {:.3g} GFLOP at ~{} FLOP per sample\n",
                     plan.total_samples, plan.total_samples * kFlopPerSample * 1e-9, int(kFlopPerSample));
  if (!plan.reused.empty()) {
    out += "\nreused across frames:\n";
    for (const std::string& r : plan.reused) out += "  " + r + "\n";
  }
  return out;
}

}  // namespace skybake
