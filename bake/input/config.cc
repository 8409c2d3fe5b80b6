// Reading, validating and resolving sky styles.
//
// Every key of a style is declared once, in VisitStyle(), with its type and
// valid range. The same declaration drives reading (StyleReader), writing the
// resolved TOML for provenance (StyleWriter), and the unknown-key check.
#include "skybake/input/config.h"
#include "skybake/input/engine_preset.h"
#include "skybake/input/ocio_color_space.h"
#include "cloud_formation_config.h"

#include <algorithm>
#include <cmath>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <set>
#include <sstream>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>
#include <glm/glm.hpp>
#include <toml++/toml.h>

#include "skybake/base/file_door.h"
#include "toml_reader.h"

namespace skybake {
namespace {

// --------------------------------------------------------------- ranges

constexpr Range kUnit{0.0, 1.0, false, false};
constexpr Range kOpenUnitSymmetric{-1.0, 1.0, true, true};
constexpr Range kElevation{-90.0, 90.0, false, false};
constexpr Range kNoiseThreshold{-1.0, 1.0, false, true};
constexpr Range kShapeRadius{0.0, 90.0, true, false};
constexpr Range kAzimuth{-360.0, 360.0, false, false};
constexpr Range kDomeRadius{1e-6, 1e6, false, false};
constexpr Range kDomeFraction{0.0, 1.0, true, false};
constexpr Range kNoiseOffset{-1e4, 1e4, false, false};
constexpr int kMaxOctaves = 8;
constexpr Range kFlattening{0.0, 1.0, false, true};
constexpr Range kCloudDistance{1.0, 2000.0, false, false};
constexpr Range kCloudPanoramaScale{0.0, 4.0, false, false};
constexpr Range kStreakRatio{1.0, 50.0, false, false};  // a cirrus layer's streaks, length over width
constexpr Range kIblLodBias{-4.0, 4.0, false, false};
constexpr Range kIblFullSamplesRoughness{0.0, 1.0, false, false};

// The physical keys' ranges (configs/default.toml states them): wide enough
// for any planet and any sky a style can mean, narrow enough that every
// product the renderer forms stays finite in float32 (about 3.4e38) and no
// division meets a denormal. A planet from a 1 km moonlet to a 10^6 km
// giant (Jupiter: 69,911 km; hard_cases_test bakes 1 km and 10^5 km); an
// observer up to 10,000 km; coefficients
// up to 1000 per km (fog of 3 m visibility is about 1300 per km of
// extinction, Koschmieder 3.912 / V); scale heights and widths from 1 m to
// 1000 km; the Sun's disc from 1e-6 rad (a point) to 0.5 rad, its
// irradiance up to 1e4 W m^-2 nm^-1 (about 5000 times Earth's);
// artistic multipliers and the night floor up to 1000.
constexpr Range kPlanetRadiusKm{1.0, 1e6, false, false};
constexpr Range kObserverAltitudeM{0.0, 1e7, false, false};
constexpr Range kPerKm{0.0, 1e3, false, false};
constexpr Range kHeightKm{1e-3, 1e3, false, false};
constexpr Range kPeakAltitudeKm{0.0, 1e3, false, false};
constexpr Range kSunRadiusRad{1e-6, 0.5, false, false};
constexpr Range kSunAzimuth{-1e5, 1e5, false, false};
constexpr Range kIrradiance{0.0, 1e4, false, false};
constexpr Range kMultiplier{0.0, 1e3, false, false};
constexpr Range kEv100{-50.0, 50.0, false, false};         // moonless night about -10, snow in sunlight about 16
constexpr Range kViewerPosition{-1e6, 1e6, false, false};  // within the largest dome
constexpr Range kGltfRadiusM{1e-3, 1e8, false, false};     // finite in float32 with its vertices' products

// Documented limits (README "Limits"): beyond these a bake would need more
// than the memory budget or hours of lavapipe time.
constexpr int kMaxCubeSize = 8192;
constexpr int kMaxLatlongHeight = 8192;
constexpr int kMaxSteps = 4096;
constexpr int kMaxLutSize = 4096;

std::string JoinNames(const std::vector<std::string>& names) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i) {
    if (i) out += i + 1 == names.size() ? " or " : ", ";
    out += "'" + names[i] + "'";
  }
  return out;
}

// A name is safe as an output file name component: no separators, no "..",
// no leading dot, printable ASCII.
bool IsSafeFileName(const std::string& name) { return IsPlainFileName(name); }

// --------------------------------------------------------------- the schema

// The atmosphere (atmosphere.h): the planet, Rayleigh, Mie and ozone.
template <class Visitor>
void VisitAtmosphere(SkyStyle& s, Visitor& v) {
  AtmosphereParams& a = s.atmosphere;
  v.Real("atmosphere.bottom_radius_km", a.bottom_radius_km, kPlanetRadiusKm);
  v.Real("atmosphere.top_radius_km", a.top_radius_km, kPlanetRadiusKm);
  v.Real("atmosphere.observer_altitude_m", a.observer_altitude_m, kObserverAltitudeM);
  v.Triple("atmosphere.ground_albedo", a.ground_albedo, kUnit);
  v.Triple("atmosphere.rayleigh.scattering_per_km", a.rayleigh_scattering_per_km, kPerKm);
  v.Real("atmosphere.rayleigh.scale_height_km", a.rayleigh_scale_height_km, kHeightKm);
  v.Triple("atmosphere.mie.scattering_per_km", a.mie_scattering_per_km, kPerKm);
  v.Triple("atmosphere.mie.extinction_per_km", a.mie_extinction_per_km, kPerKm);
  v.Real("atmosphere.mie.scale_height_km", a.mie_scale_height_km, kHeightKm);
  v.Real("atmosphere.mie.g", a.mie_g, kOpenUnitSymmetric);
  v.Triple("atmosphere.ozone.absorption_per_km", a.ozone_absorption_per_km, kPerKm);
  v.Real("atmosphere.ozone.peak_altitude_km", a.ozone_peak_altitude_km, kPeakAltitudeKm);
  v.Real("atmosphere.ozone.half_width_km", a.ozone_half_width_km, kHeightKm);
}

// The Sun: where it is, its disc and irradiance.
template <class Visitor>
void VisitSun(SkyStyle& s, Visitor& v) {
  AtmosphereParams& a = s.atmosphere;
  v.Real("sun.elevation_deg", s.sun.elevation_deg, kElevation);
  v.Real("sun.azimuth_deg", s.sun.azimuth_deg, kSunAzimuth);
  v.Real("sun.angular_radius_rad", a.sun_angular_radius_rad, kSunRadiusRad);
  v.Triple("sun.irradiance", a.solar_irradiance, kIrradiance);
  v.Real("sun.limb_darkening_u", a.limb_darkening_u, kUnit);
}

// Which effects the sky has.
template <class Visitor>
void VisitEffects(SkyStyle& s, Visitor& v) {
  v.Bool("effects.multiple_scattering", s.effects.multiple_scattering);
  v.Bool("effects.sun_disc", s.effects.sun_disc);
  v.Bool("effects.ground", s.effects.ground);
  v.Bool("effects.mie", s.effects.mie);
  v.Bool("effects.ozone", s.effects.ozone);
  v.Real("effects.multiple_scattering_strength", s.effects.multiple_scattering_strength, kMultiplier);
  v.Real("effects.sun_disc_strength", s.effects.sun_disc_strength, kMultiplier);
  v.Bool("effects.night_dimming", s.effects.night_dimming);
  v.Real("effects.night_dimming_strength", s.effects.night_dimming_strength, kUnit);
  v.Real("effects.night_sky_luminance_cd_m2", s.effects.night_sky_luminance_cd_m2, kMultiplier);
}

template <class Visitor>
bool RecordsEveryKey(const Visitor& v) {
  if constexpr (requires { v.record_every_key; }) return v.record_every_key;
  return false;
}

// The sampling: the preset, then the keys that refine it (sky and clouds).
template <class Visitor>
void VisitQuality(SkyStyle& s, Visitor& v) {
  QualitySettings& q = s.quality;
  v.Preset("quality.preset", s.quality_preset, q, s.clouds.quality);  // first: the keys below refine it
  v.Choice("quality.integrator", q.integrator,
           {{"analytic", INTEGRATOR_ANALYTIC},
            {"midpoint", INTEGRATOR_MIDPOINT},
            {"trapezoid", INTEGRATOR_TRAPEZOID},
            {"simpson", INTEGRATOR_SIMPSON}});
  v.Int("quality.light_steps", q.light_steps, 0, kMaxSteps);
  v.Choice("quality.step_distribution", q.step_distribution,
           {{"uniform", STEPS_UNIFORM}, {"quadratic", STEPS_QUADRATIC}});
  v.Bool("quality.sky_view_lut", q.sky_view_lut);
  v.Int("quality.sky_view_lut_width", q.sky_view_width, 4, kMaxLutSize);
  v.Int("quality.sky_view_lut_height", q.sky_view_height, 4, kMaxLutSize);
  v.Int("quality.view_steps", q.view_steps, 1, kMaxSteps);
  v.Int("quality.transmittance_steps", q.transmittance_steps, 1, kMaxSteps);
  v.Int("quality.multiscattering_steps", q.multiscattering_steps, 1, kMaxSteps);
  v.Int("quality.multiscattering_sqrt_directions", q.multiscattering_sqrt_dirs, 1, 64);
  v.Int("quality.transmittance_lut_width", q.transmittance_width, 2, kMaxLutSize);
  v.Int("quality.transmittance_lut_height", q.transmittance_height, 2, kMaxLutSize);
  v.Int("quality.multiscattering_lut_size", q.multiscattering_size, 2, kMaxLutSize);
  v.Int("quality.wavelengths", q.wavelengths, kRgbWavelengths, kMaxWavelengthBins);  // spectrum.h
  // The twilight settings: written into the resolved style only when they
  // differ from the named preset's (which the record names), so a style
  // that keeps them resolves (and its EXR headers record it) as before the
  // keys existed.
  const QualitySettings preset = QualityPreset(s.quality_preset);
  if (v.kReads || RecordsEveryKey(v) || q.twilight_march_band_deg != preset.twilight_march_band_deg ||
      q.twilight_march_steps != preset.twilight_march_steps ||
      q.twilight_sun_below_deg != preset.twilight_sun_below_deg) {
    v.Real("quality.twilight_march_band_deg", q.twilight_march_band_deg, Range{0.0, 90.0, false, false});
    v.Int("quality.twilight_march_steps", q.twilight_march_steps, 0, kMaxSteps);
    v.Real("quality.twilight_sun_below_deg", q.twilight_sun_below_deg, Range{0.0, 90.0, false, false});
  }
  // The cloud sampling keys: read always; written into the resolved style
  // only when it has cloud layers, so a style without them resolves (and
  // its EXR headers record it) as before clouds existed.
  CloudQuality& cq = s.clouds.quality;
  if (v.kReads || !s.clouds.layers.empty()) {
    v.Int("quality.cloud_view_steps", cq.view_steps, 1, kMaxSteps);
    v.Int("quality.cloud_light_steps", cq.light_steps, 1, 256);
    // Written only when it reads some light samples at the nearest voxel.
    if (v.kReads || cq.light_trilinear_steps < cq.light_steps)
      v.Int("quality.cloud_light_trilinear_steps", cq.light_trilinear_steps, 0, 256);
    v.Int("quality.cloud_octaves", cq.octaves, 1, 16);
    v.Int("quality.cloud_shape_resolution", cq.shape_resolution, 8, 256);
    v.Int("quality.cloud_detail_resolution", cq.detail_resolution, 8, 256);
    v.Int("quality.cloud_weather_resolution", cq.weather_resolution, 8, 2048);
    v.Real("quality.cloud_max_distance_km", cq.max_distance_km, kCloudDistance);
    v.Real("quality.cloud_panorama_scale", cq.panorama_scale, kCloudPanoramaScale);
    // Written only when on, so the reference's resolved style is as before.
    if (v.kReads || cq.light_volume_columns > 0) {
      v.Int("quality.cloud_light_volume_columns", cq.light_volume_columns, 0, 1024);
      v.Int("quality.cloud_light_volume_slices", cq.light_volume_slices, 2, 64);
      v.Int("quality.cloud_light_volume_near_steps", cq.light_volume_near_steps, 0, 16);
    }
  }
}

// The sizes, the files written and the preview's exposure.
template <class Visitor>
void VisitOutputs(SkyStyle& s, Visitor& v) {
  v.Int("render.cube_size", s.render.cube_size, 1, kMaxCubeSize);
  v.Int("render.latlong_height", s.render.latlong_height, 1, kMaxLatlongHeight);

  OutputSettings& o = s.output;
  v.FileName("output.basename", o.basename);
  v.Choice("output.pixel_type", o.pixel_type, {{"half", PixelType::kHalf}, {"float", PixelType::kFloat}});
  v.Choice("output.compression", o.compression,
           {{"none", std::string("none")},
            {"rle", std::string("rle")},
            {"zips", std::string("zips")},
            {"zip", std::string("zip")},
            {"piz", std::string("piz")}});
  v.Int("output.zip_level", o.zip_level, 1, 9);
  v.Choice("output.overflow", o.overflow, {{"scale", OverflowPolicy::kScale}, {"refuse", OverflowPolicy::kRefuse}});
  v.Choice("output.units", o.units, {{"luminance", OutputUnits::kLuminance}, {"spectral", OutputUnits::kSpectral}});
  v.Choice("output.sun", o.sun, {{"light", SunOutput::kLight}, {"map", SunOutput::kMap}});
  v.Text("output.color_space", o.color_space.name);  // resolved by CheckColorSpace
  if (v.kReads || !o.ocio_config.empty()) v.Text("output.ocio_config", o.ocio_config);
  v.Bool("output.faces", o.faces);
  v.Bool("output.cube_strip", o.cube_strip);
  v.Bool("output.latlong", o.latlong);
  v.Bool("output.preview", o.preview);
  v.FileNames("output.face_names", o.face_names, 6);
  v.Engines("output.engine", o.engine);

  v.Bool("preview.auto_exposure", s.preview.auto_exposure);
  v.Real("preview.ev100", s.preview.ev100, kEv100);
}

// AOAS (Shen, Mallett, Shkurko 2019): the aesthetic principles.
template <class Visitor>
void VisitAoas(SkyStyle& s, Visitor& v) {
  AoasSettings& x = s.aoas;
  v.Uint("aoas.seed", x.seed);
  v.Bool("skydome.enabled", x.skydome.enabled);
  v.Real("skydome.radius", x.skydome.radius, kDomeRadius);
  v.Vector("skydome.viewer_position", x.skydome.viewer_position, kViewerPosition);
  v.Bool("hue.enabled", x.hue.enabled);
  v.Color("hue.color", x.hue.color);
  v.Triple("hue.rayleigh_per_km", x.hue.rayleigh_per_km, kPerKm);
  v.Real("hue.strength", x.hue.strength, kUnit);
  v.Bool("ambiguity.enabled", x.ambiguity.enabled);
  v.Real("ambiguity.l_pt", x.ambiguity.l_pt, kUnit);  // 0: no perturbation (pruned)
  v.Real("ambiguity.grain", x.ambiguity.grain, kDomeFraction);
  v.Bool("clouds.enabled", x.clouds.enabled);
  v.Real("clouds.s_noise", x.clouds.s_noise, kDomeFraction);
  v.Int("clouds.octaves", x.clouds.octaves, 1, kMaxOctaves);
  v.Real("clouds.threshold", x.clouds.threshold, kNoiseThreshold);
  v.Real("clouds.strength", x.clouds.strength, kUnit);
  v.Vector("clouds.drift", x.clouds.drift, kNoiseOffset);
  v.Bool("shapes.enabled", x.shapes.enabled);
  v.Real("shapes.strength", x.shapes.strength, kUnit);
  v.Shapes("shapes.shape", x.shapes.shapes);
}

// Volumetric cloud layers (clouds.h, docs/clouds.md) and their shadow map.
template <class Visitor>
void VisitClouds(SkyStyle& s, Visitor& v) {
  v.CloudLayers("cloud_layer", s.clouds.layers);
  // The cloud shadow map (cloud_shadow.h): written into the resolved style
  // only when on, so a style without it resolves as before it existed.
  CloudShadowSettings& cs = s.cloud_shadow;
  if (v.kReads || cs.enabled) {
    static constexpr Range kShadowExtent{10.0, 1e7, false, false}, kShadowCenter{-1e7, 1e7, false, false};
    static constexpr Range kShadowAltitude{0.0, 1e5, false, false}, kShadowStrength{0.0, 10.0, false, false};
    v.Bool("cloud_shadow.enabled", cs.enabled);
    v.Int("cloud_shadow.resolution", cs.resolution, 8, 4096);
    v.Real("cloud_shadow.extent_m", cs.extent_m, kShadowExtent);
    v.Real("cloud_shadow.center_east_m", cs.center_east_m, kShadowCenter);
    v.Real("cloud_shadow.center_north_m", cs.center_north_m, kShadowCenter);
    v.Real("cloud_shadow.receiver_altitude_m", cs.receiver_altitude_m, kShadowAltitude);
    v.Real("cloud_shadow.strength", cs.strength, kShadowStrength);
    // At most 256: 4 bands x 256 x 5 loop iterations stay within the 5535 lavapipe
    // leaves the cloud pass above its own 60000 (CloudLoopIterationsPerTexel).
    v.Int("cloud_shadow.steps", cs.steps, 1, 256);
    v.Bool("cloud_shadow.ground", cs.ground);
  }
}

// The glTF scene (gltf_scene.h).
template <class Visitor>
void VisitGltf(SkyStyle& s, Visitor& v) {
  GltfSettings& g = s.gltf;
  v.Bool("gltf.enabled", g.enabled);
  v.Choice("gltf.dome", g.dome, {{"sphere", DomeShape::kSphere}, {"hemisphere", DomeShape::kHemisphere}});
  v.Real("gltf.radius_m", g.radius_m, kGltfRadiusM);
  v.Real("gltf.flattening", g.flattening, kFlattening);
  v.Int("gltf.segments", g.segments, 8, 1024);
  v.Bool("gltf.image_based_light", g.image_based_light);
}

// The USD sky layer (usd_layer.h).
template <class Visitor>
void VisitUsd(SkyStyle& s, Visitor& v) {
  v.Bool("usd.enabled", s.usd.enabled);
}

// The prefiltered image-based light (ibl.h).
template <class Visitor>
void VisitIbl(SkyStyle& s, Visitor& v) {
  IblSettings& i = s.ibl;
  v.Bool("ibl.specular", i.specular);
  v.Bool("ibl.irradiance", i.irradiance);
  v.Bool("ibl.dfg_lut", i.dfg);
  v.Int("ibl.size", i.size, 8, 1024);
  v.Int("ibl.levels", i.levels, 0, 11);
  v.Int("ibl.samples", i.samples, 1, 65536);
  v.Int("ibl.irradiance_size", i.irradiance_size, 1, 256);
  v.Int("ibl.irradiance_samples", i.irradiance_samples, 1, 65536);
  v.Int("ibl.dfg_size", i.dfg_size, 2, 1024);
  v.Int("ibl.dfg_samples", i.dfg_samples, 1, 65536);
  v.Real("ibl.lod_bias", i.lod_bias, kIblLodBias);
  v.Real("ibl.full_samples_roughness", i.full_samples_roughness, kIblFullSamplesRoughness);
  v.Bool("ibl.include_sun", i.include_sun);
  v.Bool("ibl.exr", i.exr);
  v.Bool("ibl.ktx2", i.ktx2);
  v.Choice(
      "ibl.ktx2_format", i.ktx2_format,
      {{"rgba16f", KtxFormat::kRgba16f}, {"b10g11r11", KtxFormat::kB10g11r11}, {"e5b9g9r9", KtxFormat::kE5b9g9r9}});
  v.Int("ibl.ktx2_zstd_level", i.ktx2_zstd_level, 0, 19);
}

// The night sky (night_sky.h): read always; written into the resolved
// style only when a part of it is on, so a style without it resolves (and
// its EXR headers record it) as before the night sky existed.
template <class Visitor>
void VisitNight(SkyStyle& s, Visitor& v) {
  NightSettings& n = s.night;
  if (v.kReads || n.Any()) {
    v.Bool("night.stars", n.stars);
    v.Text("night.star_catalogue", n.star_catalogue);
    v.Real("night.star_magnitude_limit", n.star_magnitude_limit,
           Range{kMinStarMagnitudeLimit, kMaxStarMagnitudeLimit, false, false});
    v.Bool("night.moon", n.moon);
    v.Bool("night.moonlight", n.moonlight);
    v.Bool("night.airglow", n.airglow);
    v.Real("night.airglow_height_km", n.airglow_height_km, Range{0.0, 500.0, true, false});
  }
}

// Calls the visitor once per key of a style, in file order: one section
// after another.
template <class Visitor>
void VisitStyle(SkyStyle& s, Visitor& v) {
  VisitAtmosphere(s, v);
  VisitSun(s, v);
  VisitEffects(s, v);
  VisitQuality(s, v);
  VisitOutputs(s, v);
  VisitAoas(s, v);
  VisitClouds(s, v);
  VisitGltf(s, v);
  VisitUsd(s, v);
  VisitIbl(s, v);
  VisitNight(s, v);
}

// --------------------------------------------------------------- reading

class StyleReader : public TomlReader {
 public:
  static constexpr bool kReads = true;
  StyleReader(const toml::table& root, std::string file, std::vector<ConfigError>& errors)
      : TomlReader(std::move(file), errors), root_(root) {}

  void Real(const char* path, double& out, const Range& range) {
    const toml::node* node = Find(path);
    if (!node) return;
    if (std::optional<double> value = Number(*node, path, range)) out = *value;
  }

  // A scalar sets all three channels.
  void Triple(const char* path, Rgb& out, const Range& range) {
    const toml::node* node = Find(path);
    if (!node) return;
    if (std::optional<std::vector<double>> v = NumberOrTriple(*node, path, range))
      out = v->size() == 1 ? Rgb{(*v)[0], (*v)[0], (*v)[0]} : Rgb{(*v)[0], (*v)[1], (*v)[2]};
  }

  void Int(const char* path, int& out, int min, int max) {
    const toml::node* node = Find(path);
    if (!node) return;
    if (!node->is_integer()) {
      Error(node, path, fmt::format("expected an integer, got {}", TomlTypeName(*node)));
      return;
    }
    int64_t value = node->as_integer()->get();
    if (value < min || value > max) {
      Error(node, path, fmt::format("{} is out of range [{}, {}]", value, min, max));
      return;
    }
    out = int(value);
  }

  void Bool(const char* path, bool& out) {
    const toml::node* node = Find(path);
    if (!node) return;
    if (!node->is_boolean()) {
      Error(node, path, fmt::format("expected true or false, got {}", TomlTypeName(*node)));
      return;
    }
    out = node->as_boolean()->get();
  }

  template <class T>
  void Choice(const char* path, T& out, std::initializer_list<std::pair<const char*, T>> choices) {
    const toml::node* node = Find(path);
    if (!node) return;
    std::vector<std::string> names;
    for (const auto& c : choices) names.push_back(c.first);
    if (!node->is_string()) {
      Error(node, path, fmt::format("expected one of {}, got {}", JoinNames(names), TomlTypeName(*node)));
      return;
    }
    const std::string& text = node->as_string()->get();
    for (const auto& c : choices) {
      if (text == c.first) {
        out = c.second;
        return;
      }
    }
    Error(node, path, fmt::format("'{}' is not one of {}", text, JoinNames(names)));
  }

  void Preset(const char* path, std::string& name, QualitySettings& quality, CloudQuality& cloud_quality) {
    const toml::node* node = Find(path);
    if (!node) return;
    std::vector<std::string> list = QualityPresetNames();
    if (!node->is_string()) {
      Error(node, path, fmt::format("expected one of {}, got {}", JoinNames(list), TomlTypeName(*node)));
      return;
    }
    const std::string& text = node->as_string()->get();
    if (std::find(list.begin(), list.end(), text) == list.end()) {
      Error(node, path, fmt::format("'{}' is not one of {}", text, JoinNames(list)));
      return;
    }
    name = text;
    quality = QualityPreset(text);
    cloud_quality = CloudQualityPreset(text);
  }

  void FileName(const char* path, std::string& out) {
    const toml::node* node = Find(path);
    if (!node) return;
    if (!node->is_string()) {
      Error(node, path, fmt::format("expected a string, got {}", TomlTypeName(*node)));
      return;
    }
    const std::string& text = node->as_string()->get();
    if (!IsSafeFileName(text)) {
      Error(node, path,
            text.size() > 128
                ? fmt::format("a name of {} characters is longer than the 128 a plain file name may have", text.size())
                : fmt::format("{} is not a plain file name: use letters, digits, '_', '-', '.', '+', no '/' or "
                              "'..', not starting with '.' or '-', not a name Windows reserves (CON, NUL, COM1, "
                              "...)",
                              EscapedText(text)));
      return;
    }
    out = text;
  }

  // output.engine: "none", or preset names separated by commas, each once;
  // kept as the names joined by commas, in the order given.
  void Engines(const char* path, std::string& out) {
    const toml::node* node = Find(path);
    if (!node) return;
    std::vector<std::string> names = {"none"};
    for (const std::string& name : EngineNames()) names.push_back(name);
    const std::string choices = JoinNames(names) + " (or several presets separated by commas)";
    if (!node->is_string()) {
      Error(node, path, fmt::format("expected one of {}, got {}", choices, TomlTypeName(*node)));
      return;
    }
    const std::vector<std::string> list = SplitEngineList(node->as_string()->get());
    std::vector<std::string> kept;
    for (const std::string& name : list) {
      if (name == "none" && list.size() == 1) {
        out = "none";
        return;
      }
      if (!FindEnginePreset(name)) {
        Error(node, path,
              name == "none" ? fmt::format("'none' cannot be given with other presets: '{}'", node->as_string()->get())
                             : fmt::format("'{}' is not one of {}", name, choices));
        return;
      }
      if (std::find(kept.begin(), kept.end(), name) == kept.end()) kept.push_back(name);
    }
    out.clear();
    for (const std::string& name : kept) out += (out.empty() ? "" : ",") + name;
  }

  // Any string (a path).
  void Text(const char* path, std::string& out) {
    const toml::node* node = Find(path);
    if (!node) return;
    if (!node->is_string()) {
      Error(node, path, fmt::format("expected a string, got {}", TomlTypeName(*node)));
      return;
    }
    out = node->as_string()->get();
  }

  void FileNames(const char* path, std::vector<std::string>& out, size_t count) {
    const toml::node* node = Find(path);
    if (!node) return;
    const toml::array* array = node->as_array();
    if (!array || array->size() != count) {
      Error(node, path, fmt::format("expected an array of {} file names", count));
      return;
    }
    std::vector<std::string> result;
    for (size_t i = 0; i < count; ++i) {
      const toml::node& item = *array->get(i);
      std::string item_path = fmt::format("{}[{}]", path, i);
      if (!item.is_string() || !IsSafeFileName(item.as_string()->get())) {
        Error(&item, item_path, "expected a plain file name (letters, digits, '_', '-', '.', '+')");
        return;
      }
      result.push_back(item.as_string()->get());
    }
    out = result;
  }

  void Uint(const char* path, uint32_t& out) {
    const toml::node* node = Find(path);
    if (!node) return;
    if (!node->is_integer() || node->as_integer()->get() < 0 || node->as_integer()->get() > int64_t(UINT32_MAX)) {
      Error(node, path, fmt::format("expected an integer in [0, {}]", UINT32_MAX));
      return;
    }
    out = uint32_t(node->as_integer()->get());
  }

  void Vector(const char* path, glm::dvec3& out, const Range& range) {
    Rgb triple = {out.x, out.y, out.z};
    const toml::node* node = Find(path);
    if (!node) return;
    if (!node->is_array()) {
      Error(node, path, "expected an array of 3 numbers [x, y, z]");
      return;
    }
    Triple(path, triple, range);
    out = {triple[0], triple[1], triple[2]};
  }

  void Color(const char* path, std::string& out) {
    const toml::node* node = Find(path);
    if (!node) return;
    Rgb unused;
    if (!node->is_string() || !ParseHexColor(node->as_string()->get(), unused)) {
      Error(node, path, "expected a colour \"#rrggbb\" (sRGB, hexadecimal), e.g. \"#ffcc33\"");
      return;
    }
    out = node->as_string()->get();
  }

  // [[shapes.shape]] tables: kind, points, closed, radius_deg, strength.
  void Shapes(const char* path, std::vector<CloudShape>& out) {
    const toml::node* node = Find(path);
    if (!node) return;
    const toml::array* array = node->as_array();
    if (!array || !array->is_array_of_tables()) {
      Error(node, path, "expected [[shapes.shape]] tables");
      return;
    }
    std::vector<CloudShape> shapes;
    for (size_t i = 0; i < array->size(); ++i) {
      const toml::table& t = *array->get(i)->as_table();
      std::string where = fmt::format("{}[{}]", path, i);
      CloudShape shape;
      bool ok = true;
      for (const auto& [key, value] : t) {
        std::string k(key.str());
        std::string key_path = where + "." + k;
        if (k == "kind") {
          std::string kind = value.value_or(std::string());
          if (kind == "point") shape.kind = ShapeKind::kPoint;
          else if (kind == "polyline") shape.kind = ShapeKind::kPolyline;
          else if (kind == "spline") shape.kind = ShapeKind::kSpline;
          else ok = false, Error(&value, key_path, "expected 'point', 'polyline' or 'spline'");
        } else if (k == "closed") {
          if (!value.is_boolean()) ok = false, Error(&value, key_path, "expected true or false");
          else shape.closed = value.as_boolean()->get();
        } else if (k == "radius_deg" || k == "strength") {
          std::optional<double> v = value.value<double>();
          const Range& range = k == "radius_deg" ? kShapeRadius : kUnit;
          if (!v || value.is_boolean() || !std::isfinite(*v) || !range.Contains(*v)) {
            ok = false;
            Error(&value, key_path, fmt::format("expected a number in {}", range.Describe()));
          } else {
            (k == "radius_deg" ? shape.radius_deg : shape.strength) = *v;
          }
        } else if (k == "points") {
          const toml::array* points = value.as_array();
          if (!points || points->empty()) {
            ok = false;
            Error(&value, key_path, "expected [[elevation_deg, azimuth_deg], ...]");
            continue;
          }
          for (size_t j = 0; j < points->size(); ++j) {
            const toml::array* pair = points->get(j)->as_array();
            std::optional<double> el, az;
            if (pair && pair->size() == 2) {
              el = pair->get(0)->value<double>();
              az = pair->get(1)->value<double>();
            }
            if (!el || !az || !kElevation.Contains(*el) || !kAzimuth.Contains(*az)) {
              ok = false;
              Error(points->get(j), fmt::format("{}[{}]", key_path, j),
                    "expected [elevation_deg in [-90, 90], azimuth_deg in [-360, 360]]");
              continue;
            }
            shape.points.push_back({*el, *az});
          }
        } else {
          ok = false;
          Error(&value, key_path,
                fmt::format("unknown key '{}' (a shape has kind, points, closed, radius_deg, "
                            "strength)",
                            k));
        }
      }
      if (ok && shape.points.empty()) {
        ok = false;
        Error(array->get(i), where, "a shape needs points = [[elevation_deg, azimuth_deg], ...]");
      }
      if (ok && shape.kind != ShapeKind::kPoint && shape.points.size() < 2) {
        ok = false;
        Error(array->get(i), where, "a polyline or spline needs at least 2 points");
      }
      if (ok) shapes.push_back(std::move(shape));
    }
    out = std::move(shapes);
  }

  // [[cloud_layer]] tables (clouds.h): every key optional, checked against
  // its range; an explicit profile needs type = "custom".
  void CloudLayers(const char* path, std::vector<CloudLayer>& out) {
    const toml::node* node = Find(path);
    if (!node) return;
    const toml::array* array = node->as_array();
    if (!array || !array->is_array_of_tables()) {
      Error(node, path, "expected [[cloud_layer]] tables");
      return;
    }
    std::vector<CloudLayer> layers;
    for (size_t i = 0; i < array->size(); ++i) {
      const toml::table& t = *array->get(i)->as_table();
      const std::string where = fmt::format("{}[{}]", path, i);
      CloudLayer layer;
      bool ok = true;
      bool has_profile = false;
      bool has_streak_ratio = false;
      auto number = [&](const toml::node& value, const std::string& key_path, const Range& range, double& to) {
        std::optional<double> v = value.value<double>();
        if (!v || value.is_boolean() || !std::isfinite(*v) || !range.Contains(*v)) {
          ok = false;
          Error(&value, key_path, fmt::format("expected a number in {}", range.Describe()));
          return;
        }
        to = *v;
      };
      auto numbers = [&](const toml::node& value, const std::string& key_path, const Range& range, double* to,
                         size_t count, const char* shape) {
        const toml::array* a = value.as_array();
        if (!a || a->size() != count) {
          ok = false;
          Error(&value, key_path, fmt::format("expected {}", shape));
          return;
        }
        for (size_t j = 0; j < count; ++j) number(*a->get(j), fmt::format("{}[{}]", key_path, j), range, to[j]);
      };
      static const Range kAltitude{0.0, 1e5, false, false}, kThickness{0.0, 1e5, true, false};
      static const Range kDensity{0.0, 10.0, false, false}, kNoiseSize{1.0, 1e6, false, false};
      static const Range kWeatherSize{10.0, 1e7, false, false}, kWind{-200.0, 200.0, false, false};
      static const Range kShear{-100.0, 100.0, false, false}, kOrigin{-1e7, 1e7, false, false};
      for (const auto& [key, value] : t) {
        const std::string k(key.str());
        const std::string key_path = where + "." + k;
        if (k == "altitude_m") number(value, key_path, kAltitude, layer.altitude_m);
        else if (k == "thickness_m") number(value, key_path, kThickness, layer.thickness_m);
        else if (k == "coverage") number(value, key_path, kUnit, layer.coverage);
        else if (k == "density_per_m") number(value, key_path, kDensity, layer.density_per_m);
        else if (k == "albedo") number(value, key_path, kUnit, layer.albedo);
        else if (k == "shape_amount") number(value, key_path, kUnit, layer.shape_amount);
        else if (k == "shape_size_m") number(value, key_path, kNoiseSize, layer.shape_size_m);
        else if (k == "detail_amount") number(value, key_path, kUnit, layer.detail_amount);
        else if (k == "detail_size_m") number(value, key_path, kNoiseSize, layer.detail_size_m);
        else if (k == "weather_size_m") number(value, key_path, kWeatherSize, layer.weather_size_m);
        else if (k == "streak_ratio") {
          number(value, key_path, kStreakRatio, layer.streak_ratio);
          has_streak_ratio = true;
        } else if (k == "tiling") {
          if (!value.is_boolean()) ok = false, Error(&value, key_path, "expected true or false");
          else layer.tiling = value.as_boolean()->get();
        } else if (k == "wind_m_s") numbers(value, key_path, kWind, layer.wind_m_s.data(), 2, "[east, north] in m/s");
        else if (k == "shear_m_s_per_km")
          numbers(value, key_path, kShear, layer.shear_m_s_per_km.data(), 2, "[east, north] in m/s per km");
        else if (k == "weather_extent_m")
          numbers(value, key_path, kWeatherSize, layer.weather_extent_m.data(), 2, "[east, north] size in m");
        else if (k == "weather_origin_m")
          numbers(value, key_path, kOrigin, layer.weather_origin_m.data(), 2,
                  "[east, north] of the south-west corner in m");
        else if (k == "profile") {
          numbers(value, key_path, kUnit, layer.profile.data(), 4, "[bottom_in, bottom_full, top_full, top_out]");
          has_profile = true;
        } else if (k == "type") {
          const std::string type = value.value_or(std::string());
          bool known = false;
          for (CloudType c : {CloudType::kStratus, CloudType::kStratocumulus, CloudType::kCumulus,
                              CloudType::kCumulonimbus, CloudType::kCirrus, CloudType::kCustom})
            if (type == CloudTypeName(c)) layer.type = c, known = true;
          if (!known) {
            ok = false;
            Error(&value, key_path,
                  "expected 'stratus', 'stratocumulus', 'cumulus', 'cumulonimbus', 'cirrus' or 'custom'");
          }
        } else if (k == "seed") {
          if (!value.is_integer() || value.as_integer()->get() < 0 || value.as_integer()->get() > int64_t(UINT32_MAX)) {
            ok = false;
            Error(&value, key_path, fmt::format("expected an integer in [0, {}]", UINT32_MAX));
          } else {
            layer.seed = uint32_t(value.as_integer()->get());
          }
        } else if (k == "formation") {
          ReadCloudFormation(value, key_path, layer.formation,
                             [&](const toml::node* n, const std::string& at, const std::string& message) {
                               ok = false;
                               Error(n, at, message);
                             });
        } else if (k == "weather_image") {
          if (!value.is_string() || value.as_string()->get().empty()) {
            ok = false;
            Error(&value, key_path, "expected the path of an EXR or PNG image (relative to the style file)");
          } else {
            layer.weather_image = value.as_string()->get();
          }
        } else {
          ok = false;
          Error(
              &value, key_path,
              fmt::format("unknown key '{}' (a cloud layer has altitude_m, thickness_m, type, profile, coverage, "
                          "density_per_m, albedo, shape_amount, shape_size_m, detail_amount, detail_size_m, "
                          "wind_m_s, shear_m_s_per_km, seed, weather_size_m, tiling, weather_image, weather_extent_m, "
                          "weather_origin_m, formation, streak_ratio)",
                          k));
        }
      }
      if (ok && has_streak_ratio && layer.type != CloudType::kCirrus) {
        ok = false;
        Error(t.get("streak_ratio"), where + ".streak_ratio", "streak_ratio needs type = \"cirrus\"");
      }
      if (ok && has_profile && layer.type != CloudType::kCustom) {
        ok = false;
        Error(t.get("profile"), where + ".profile", "an explicit profile needs type = \"custom\"");
      }
      if (ok && !has_profile && layer.type == CloudType::kCustom) {
        ok = false;
        Error(array->get(i), where + ".type",
              "type = \"custom\" needs profile = [bottom_in, bottom_full, top_full, top_out]");
      }
      if (ok && !has_profile) layer.profile = CloudTypeProfile(layer.type);
      if (ok) layers.push_back(std::move(layer));
    }
    out = std::move(layers);
  }

  // Reports every key of the file that no Visit call asked for. Tables named
  // in `opaque` belong to another reader (a style's inline [schedule]).
  void ReportUnknownKeys(const std::set<std::string>& opaque = {}) {
    opaque_ = opaque;
    for (const std::string& name : opaque) known_.insert(name);
    WalkUnknown(root_, "");
  }

  // Whether the file (or an override) gives the key explicitly.
  bool Given(const std::string& path) const { return given_.count(path) > 0; }

 private:
  const toml::node* Find(const char* path) {
    known_.insert(path);
    if (root_.at_path(path).node()) given_.insert(path);
    std::string prefix;
    for (std::string_view rest = path; !rest.empty();) {  // parent tables are known too
      size_t dot = rest.find('.');
      if (dot == std::string_view::npos) break;
      prefix += std::string(rest.substr(0, dot));
      known_.insert(prefix);
      tables_.insert(prefix);
      prefix += '.';
      rest.remove_prefix(dot + 1);
    }
    toml::node_view<const toml::node> view = root_.at_path(path);
    return view.node();
  }

  void WalkUnknown(const toml::table& table, const std::string& prefix) {
    for (const auto& [key, node] : table) {
      std::string path = prefix + std::string(key.str());
      if (!known_.count(path)) {
        ErrorAt(key.source(), path, fmt::format("unknown key '{}'{}", key.str(), Suggest(path)));
        continue;
      }
      if (opaque_.count(path)) continue;
      // A table replaced by a value (`--set sun=1`) would drop every key of
      // it silently: refused.
      if (tables_.count(path) && !node.is_table()) {
        Error(&node, path, fmt::format("expected a table ([{}] with its keys), got {}", path, TomlTypeName(node)));
        continue;
      }
      if (const toml::table* sub = node.as_table()) WalkUnknown(*sub, path + ".");
    }
  }

  std::string Suggest(const std::string& path) const { return DidYouMean(path, known_); }

  const toml::table& root_;
  std::set<std::string> known_;
  std::set<std::string> tables_;  // prefixes of known keys: tables
  std::set<std::string> given_;
  std::set<std::string> opaque_;
};

// --------------------------------------------------------------- writing

class StyleWriter {
 public:
  static constexpr bool kReads = false;
  bool record_every_key = false;  // also the keys a resolved style leaves out where they are the preset's
  void Real(const char* path, double& v, const Range&) { Put(path, v); }
  void Triple(const char* path, Rgb& v, const Range&) { Put(path, toml::array{v[0], v[1], v[2]}); }
  void Int(const char* path, int& v, int, int) { Put(path, int64_t(v)); }
  void Bool(const char* path, bool& v) { Put(path, v); }
  template <class T>
  void Choice(const char* path, T& v, std::initializer_list<std::pair<const char*, T>> choices) {
    for (const auto& c : choices)
      if (c.second == v) Put(path, std::string(c.first));
  }
  void FileName(const char* path, std::string& v) { Put(path, v); }
  void Text(const char* path, std::string& v) { Put(path, v); }
  void Engines(const char* path, std::string& v) { Put(path, v); }
  void Preset(const char* path, std::string& name, QualitySettings&, CloudQuality&) { Put(path, name); }
  void Uint(const char* path, uint32_t& v) { Put(path, int64_t(v)); }
  void Vector(const char* path, glm::dvec3& v, const Range&) { Put(path, toml::array{v.x, v.y, v.z}); }
  void Color(const char* path, std::string& v) {
    if (!v.empty()) Put(path, v);
  }
  void Shapes(const char* path, std::vector<CloudShape>& shapes) {
    toml::array array;
    for (const CloudShape& shape : shapes) {
      toml::table t;
      t.insert("kind", shape.kind == ShapeKind::kPoint      ? "point"
                       : shape.kind == ShapeKind::kPolyline ? "polyline"
                                                            : "spline");
      toml::array points;
      for (const auto& p : shape.points) points.push_back(toml::array{p[0], p[1]});
      t.insert("points", std::move(points));
      t.insert("closed", shape.closed);
      t.insert("radius_deg", shape.radius_deg);
      t.insert("strength", shape.strength);
      array.push_back(std::move(t));
    }
    if (!array.empty()) Put(path, std::move(array));
  }
  void CloudLayers(const char* path, std::vector<CloudLayer>& layers) {
    toml::array array;
    for (const CloudLayer& l : layers) {
      toml::table t;
      t.insert("altitude_m", l.altitude_m);
      t.insert("thickness_m", l.thickness_m);
      t.insert("type", std::string(CloudTypeName(l.type)));
      // The type decides the profile, except "custom", which gives it.
      if (l.type == CloudType::kCustom)
        t.insert("profile", toml::array{l.profile[0], l.profile[1], l.profile[2], l.profile[3]});
      t.insert("coverage", l.coverage);
      t.insert("density_per_m", l.density_per_m);
      t.insert("albedo", l.albedo);
      t.insert("shape_amount", l.shape_amount);
      t.insert("shape_size_m", l.shape_size_m);
      t.insert("detail_amount", l.detail_amount);
      t.insert("detail_size_m", l.detail_size_m);
      t.insert("wind_m_s", toml::array{l.wind_m_s[0], l.wind_m_s[1]});
      t.insert("shear_m_s_per_km", toml::array{l.shear_m_s_per_km[0], l.shear_m_s_per_km[1]});
      if (l.seed) t.insert("seed", int64_t(*l.seed));
      t.insert("weather_size_m", l.weather_size_m);
      if (l.tiling) t.insert("tiling", true);
      if (l.type == CloudType::kCirrus) t.insert("streak_ratio", l.streak_ratio);
      if (l.formation.enabled) t.insert("formation", CloudFormationToml(l.formation));
      if (!l.weather_image.empty()) {
        t.insert("weather_image", l.weather_image);
        t.insert("weather_extent_m", toml::array{l.weather_extent_m[0], l.weather_extent_m[1]});
        t.insert("weather_origin_m", toml::array{l.weather_origin_m[0], l.weather_origin_m[1]});
      }
      array.push_back(std::move(t));
    }
    if (!array.empty()) Put(path, std::move(array));
  }
  void FileNames(const char* path, std::vector<std::string>& v, size_t) {
    toml::array array;
    for (const std::string& s : v) array.push_back(s);
    Put(path, std::move(array));
  }
  const toml::table& table() const { return root_; }

 private:
  template <class T>
  void Put(std::string_view path, T&& value) {
    toml::table* table = &root_;
    size_t dot;
    while ((dot = path.find('.')) != std::string_view::npos) {
      std::string_view part = path.substr(0, dot);
      auto [it, inserted] = table->insert(part, toml::table{});
      table = it->second.as_table();
      path.remove_prefix(dot + 1);
    }
    table->insert_or_assign(path, std::forward<T>(value));
  }
  toml::table root_;
};

// --------------------------------------------------------------- input limits

// The first place where `text` has a dotted key of more than kMaxKeyParts
// parts (`a.b.c` is 3; a table header counts as a key), or nothing. The TOML
// parser recurses once per part: 50,000 parts overflow its stack. A linear
// scan that skips strings and comments; a float (`0.5`) is a 2-part chain,
// a date has none.
std::optional<toml::source_position> DeepKey(std::string_view text) {
  uint32_t line = 1, column = 0;
  size_t parts = 1;
  bool in_chain = false;  // after a bare-key character or a quoted key
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    ++column;
    if (c == '\n') {
      ++line;
      column = 0;
      parts = 1;
      in_chain = false;
      continue;
    }
    if (c == '#') {  // a comment, to the end of the line
      while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
      continue;
    }
    if (c == '"' || c == '\'') {  // a string: skipped, counts as one key part
      const bool multi = text.compare(i, 3, std::string(3, c)) == 0;
      const size_t open = multi ? 3 : 1;
      size_t j = i + open;
      for (; j < text.size(); ++j) {
        if (c == '"' && text[j] == '\\') {
          ++j;
          continue;
        }
        if (text[j] == '\n') {
          if (!multi) break;
          ++line;
          column = 0;
        }
        if (text[j] == c && (!multi || text.compare(j, 3, std::string(3, c)) == 0)) break;
      }
      const size_t end = std::min(text.size(), j + (multi ? 3 : 1));
      column += uint32_t(end - i - 1);
      i = end - 1;
      in_chain = true;
      continue;
    }
    const bool bare =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '+';
    if (bare) {
      in_chain = true;
    } else if (c == '.' && in_chain) {
      if (++parts > kMaxKeyParts) return toml::source_position{line, column};
      in_chain = false;
    } else if (c != ' ' && c != '\t' && c != '.') {
      parts = 1;
      in_chain = false;
    }
  }
  return std::nullopt;
}

// The [quality] keys in which the presets differ, in key order: every preset
// sets all of them, so a style that gives each one explicitly resolves to the
// same quality whichever preset it names.
std::vector<std::string> PresetKeys() {
  std::vector<toml::table> presets;
  for (const std::string& name : QualityPresetNames()) {
    SkyStyle style;
    style.quality = QualityPreset(name);
    StyleWriter writer;
    writer.record_every_key = true;  // the twilight keys too, where they are production's
    VisitStyle(style, writer);
    presets.push_back(*writer.table().get_as<toml::table>("quality"));
  }
  auto text = [](const toml::table& quality, std::string_view key) {
    toml::table one;
    one.insert(key, *quality.get(key));
    std::ostringstream out;
    out << one;
    return out.str();
  };
  std::vector<std::string> keys;
  for (const auto& [key, node] : presets[0]) {
    if (key.str() == "preset") continue;
    for (size_t i = 1; i < presets.size(); ++i) {
      if (text(presets[i], key.str()) != text(presets[0], key.str())) {
        keys.push_back("quality." + std::string(key.str()));
        break;
      }
    }
  }
  return keys;
}

// --------------------------------------------------------------- overrides

// Applies "a.b.c=value" on top of `root`. The value is TOML ("0.5", "[1,2,3]",
// "\"half\""); a bare word that is not valid TOML is taken as a string.
void ApplyOverride(toml::table& root, const std::string& text, std::vector<ConfigError>& errors) {
  std::string name = "--set " + text;
  size_t eq = text.find('=');
  auto fail = [&](const std::string& message) {
    ConfigError e;
    e.file = "--set";
    e.key = eq == std::string::npos ? text : text.substr(0, eq);
    if (e.key.empty()) e.key = "(key)";
    e.message = message;
    errors.push_back(e);
  };
  if (eq == std::string::npos || eq == 0) {
    fail("expected key.path=value, e.g. --set sun.elevation_deg=10");
    return;
  }
  std::string key = text.substr(0, eq);
  std::string value = text.substr(eq + 1);
  if (value.find_first_of("\n\r") != std::string::npos) {
    fail("the value has a line break, and what follows it would be ignored: give one value per --set");
    return;
  }
  if (key == "schedule" || key.rfind("schedule.", 0) == 0) {
    fail(
        "a schedule is not changed with --set (it would be ignored): edit the schedule file, or use its "
        "[schedule.ramp] or a frame's set");
    return;
  }
  if (KeyHasTooManyParts(key)) {
    // Refused before the key is split (the key named by its first part).
    fail(
        fmt::format("the key has more than {} dotted parts (skybake's keys have at most 5, e.g. "
                    "atmosphere.rayleigh.scale_height_km): give a style key",
                    kMaxKeyParts));
    errors.back().key = key.substr(0, key.find('.')) + ".(...)";
    return;
  }
  if (DeepKey(value)) {
    fail(fmt::format("the value nests more than {} dotted key parts: give a plain value", kMaxKeyParts));
    return;
  }
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + value, name);
  } catch (const toml::parse_error& e) {
    // A number TOML cannot hold (1e400) is not a bare word.
    static const std::regex kNumber(R"([+-]?[0-9][0-9_]*(\.[0-9_]+)?([eE][+-]?[0-9_]+)?)");
    if (std::regex_match(value, kNumber)) {
      (void)e;
      fail(fmt::format("{} is not a number a double holds (at most about 1.8e308 in size): give a smaller value",
                       value));
      return;
    }
    try {
      parsed = toml::parse("v = \"" + value + "\"", name);
    } catch (const toml::parse_error& e) {
      fail(fmt::format("value '{}' is not valid TOML: {}", value, e.description()));
      return;
    }
  }
  // Keys and tables made here are located at the --set argument (column:
  // where the key part starts), so errors about them name it, not the file.
  const toml::source_path_ptr where = std::make_shared<const std::string>(name);
  auto region_at = [&](size_t offset) {
    toml::source_region r;
    r.begin = {1, toml::source_index(offset + 1)};
    r.end = r.begin;
    r.path = where;
    return r;
  };
  toml::table* table = &root;
  std::string_view path = key;
  size_t dot;
  // An empty table located at the argument, copied for each part made.
  const toml::table made_in = toml::parse("t = {}", name);
  const toml::table& made = *made_in.get("t")->as_table();
  while ((dot = path.find('.')) != std::string_view::npos) {
    std::string_view part = path.substr(0, dot);
    if (part.empty()) {
      fail("empty part in the key path (two dots, or a leading dot): e.g. --set sun.elevation_deg=10");
      return;
    }
    auto [it, inserted] = table->insert(toml::key(part, region_at(key.size() - path.size())), toml::table(made));
    if (!it->second.is_table()) {
      fail(fmt::format("'{}' is not a table", part));
      return;
    }
    table = it->second.as_table();
    path.remove_prefix(dot + 1);
  }
  if (path.empty()) {
    fail("empty key");
    return;
  }
  table->insert_or_assign(toml::key(path, region_at(key.size() - path.size())), std::move(*parsed.get("v")));
}

}  // namespace

bool IsPlainFileName(const std::string& name) {
  // Not `-x` (read as an option by tools given the file), nor a name Windows
  // reserves (CON, NUL, COM1, ... with any extension) on a shared folder.
  if (name.empty() || name.size() > 128 || name[0] == '.' || name[0] == '-') return false;
  std::string stem = name.substr(0, name.find('.'));
  for (char& c : stem) c = char(std::toupper(static_cast<unsigned char>(c)));
  for (const char* reserved : {"CON", "PRN", "AUX", "NUL"})
    if (stem == reserved) return false;
  if (stem.size() == 4 && (stem.rfind("COM", 0) == 0 || stem.rfind("LPT", 0) == 0) && stem[3] >= '1' && stem[3] <= '9')
    return false;
  for (char c : name) {
    bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
              c == '.' || c == '+';
    if (!ok) return false;
  }
  return name.find("..") == std::string::npos;
}

std::string ConfigError::Format() const {
  std::string where = file;
  if (line > 0) where += fmt::format(":{}:{}", line, column);
  return fmt::format("{}: {}: {}", where, key, message);
}

Rgb OutputScale(OutputUnits units) {
  if (units == OutputUnits::kSpectral) return {1.0, 1.0, 1.0};
  // Bruneton 2017, SKY_SPECTRAL_RADIANCE_TO_LUMINANCE (lm/W): 683 lm/W, the
  // CIE 1931 tables and the XYZ -> sRGB matrix, for 680/550/440 nm samples.
  return {114974.916437, 71305.954816, 65310.548555};
}

namespace {

// The cross-field checks of a style, each located at the key it names
// (the second key of a pair), as the reader's own errors are.
struct StyleChecks {
  const toml::table& root;
  const std::string& name;
  std::vector<ConfigError>& errors;
  std::vector<ConfigError>& warnings;
  ConfigError Locate(const char* path) const {
    ConfigError e;
    e.file = name;
    e.key = path;
    if (const toml::node* node = root.at_path(path).node(); node && node->source().begin) {
      e.line = int(node->source().begin.line);
      e.column = int(node->source().begin.column);
      if (node->source().path) e.file = *node->source().path;
    }
    return e;
  }
};

void CheckAtmosphere(const SkyStyle& style, StyleChecks& c) {
  const AtmosphereParams& a = style.atmosphere;
  if (!(a.top_radius_km > a.bottom_radius_km)) {
    ConfigError e = c.Locate("atmosphere.top_radius_km");
    e.message =
        fmt::format("top radius {} km must be above the bottom radius {} km", a.top_radius_km, a.bottom_radius_km);
    c.errors.push_back(e);
  }
  for (int channel = 0; channel < 3; ++channel) {
    if (a.mie_extinction_per_km[channel] < a.mie_scattering_per_km[channel]) {
      ConfigError e = c.Locate("atmosphere.mie.extinction_per_km");
      e.message = fmt::format("extinction {} must be at least the scattering {} (channel {})",
                              a.mie_extinction_per_km[channel], a.mie_scattering_per_km[channel], channel);
      c.errors.push_back(e);
      break;
    }
  }
}

// The skydome's viewer, the shapes' arcs.
void CheckAoas(const SkyStyle& style, StyleChecks& c) {
  const AoasSettings& x = style.aoas;
  if (x.skydome.enabled) {
    const glm::dvec3& p = x.skydome.viewer_position;
    if (!(glm::length(p) < 0.99 * x.skydome.radius)) {
      ConfigError e = c.Locate("skydome.viewer_position");
      e.message = fmt::format(
          "the viewer must be inside the dome: |position| = {} must be below "
          "0.99 x radius = {}",
          glm::length(p), 0.99 * x.skydome.radius);
      c.errors.push_back(e);
    }
    if (p.y < 0.0) {
      ConfigError e = c.Locate("skydome.viewer_position");
      e.message = fmt::format("the viewer must be on or above the ground plane (y = {} < 0)", p.y);
      c.errors.push_back(e);
    }
  }
  if (x.shapes.enabled) {
    size_t arcs = ShapeArcs(x.shapes).size();
    if (arcs == 0) {
      ConfigError e = c.Locate("shapes.enabled");
      e.message = "shapes are enabled but there is no [[shapes.shape]]";
      c.errors.push_back(e);
    } else if (arcs > AOAS_MAX_SHAPE_SEGMENTS) {
      ConfigError e = c.Locate("shapes.shape");
      e.message = fmt::format("the shapes need {} arcs (a spline takes {} per span); at most {} fit", arcs,
                              kAoasSplineSubdivisions, AOAS_MAX_SHAPE_SEGMENTS);
      c.errors.push_back(e);
    }
  }
}

// Volumetric cloud layers: counts, the atmosphere's top, weather images.
void CheckCloudLayers(const SkyStyle& style, StyleChecks& c) {
  const AtmosphereParams& a = style.atmosphere;
  const std::string style_dir = std::filesystem::path(c.name).parent_path().string();
  for (const CloudProblem& p : ValidateClouds(style.clouds, a, style_dir)) {
    std::string key = p.layer < 0 ? "cloud_layer" : fmt::format("cloud_layer[{}]", p.layer);
    if (p.layer == -3) {  // the light volume's size
      ConfigError e =
          c.Locate(c.root.at_path("quality.cloud_light_volume_columns").node() ? "quality.cloud_light_volume_columns"
                                                                               : "quality.cloud_light_volume_slices");
      e.message = p.message;
      c.errors.push_back(e);
      continue;
    }
    if (p.layer == -2) {  // the sampling settings
      ConfigError e = c.Locate(c.root.at_path("quality.cloud_light_steps").node() ? "quality.cloud_light_steps"
                                                                                  : "quality.cloud_view_steps");
      e.message = p.message;
      c.errors.push_back(e);
      continue;
    }
    ConfigError e = c.Locate("cloud_layer");
    if (const toml::array* layers = c.root["cloud_layer"].as_array();
        layers && p.layer >= 0 && size_t(p.layer) < layers->size()) {
      const toml::node* at = layers->get(size_t(p.layer));
      if (const toml::table* t = at->as_table(); t && !p.key.empty() && t->at_path(p.key).node())
        at = t->at_path(p.key).node();
      if (at->source().begin) {
        e.line = int(at->source().begin.line);
        e.column = int(at->source().begin.column);
      }
    }
    e.key = p.key.empty() ? key : key + "." + p.key;
    e.message = p.message;
    c.errors.push_back(e);
  }
}

// Every file of a bake has its own name: face names differ from each other
// and from the cube strip's and latlong's suffixes.
// Compared without case: on a case-insensitive file system (macOS,
// Windows shares) "PX" and "px" are one file.
void CheckFaceNames(const SkyStyle& style, StyleChecks& c) {
  const std::vector<std::string>& faces = style.output.face_names;
  auto folded = [](std::string name) {
    for (char& ch : name) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    return name;
  };
  for (size_t i = 0; i < faces.size(); ++i) {
    bool reserved = folded(faces[i]) == "cube" || folded(faces[i]) == "latlong";
    size_t twin = 0;
    while (twin < i && folded(faces[twin]) != folded(faces[i])) ++twin;
    bool repeated = twin < i;
    if (reserved || repeated) {
      ConfigError e = c.Locate("output.face_names");
      e.key = fmt::format("output.face_names[{}]", i);
      e.message = reserved ? fmt::format("'{}' is the name of another output file: choose another face name", faces[i])
                  : faces[twin] == faces[i]
                      ? fmt::format("'{}' is given twice: each face is its own file", faces[i])
                      : fmt::format(
                            "'{}' and '{}' differ only in case, one file on a case-insensitive file "
                            "system: each face is its own file",
                            faces[twin], faces[i]);
      c.errors.push_back(e);
      break;
    }
  }
}

// What the glTF scene's image-based light and an engine preset need.
void CheckSceneAndEngine(const SkyStyle& style, StyleChecks& c) {
  if (style.gltf.image_based_light && (!style.ibl.specular || !style.gltf.enabled)) {
    ConfigError e = c.Locate("gltf.image_based_light");
    e.message =
        "the scene's image-based light is made of the prefiltered specular maps: set ibl.specular = true "
        "(and gltf.enabled = true), or gltf.image_based_light = false";
    c.errors.push_back(e);
  }
  // The USD layer's dome is the latlong EXR, in cd/m^2 (UsdLux: nits).
  if (style.usd.enabled && !style.output.latlong) {
    ConfigError e = c.Locate("usd.enabled");
    e.message =
        "the USD layer's DomeLight is textured with the latlong EXR: set output.latlong = true, or "
        "usd.enabled = false";
    c.errors.push_back(e);
  }
  if (style.usd.enabled && style.output.units != OutputUnits::kLuminance) {
    ConfigError e = c.Locate("usd.enabled");
    e.message =
        "UsdLux lights emit in nits (cd/m^2): the USD layer needs output.units = \"luminance\", or "
        "usd.enabled = false";
    c.errors.push_back(e);
  }
  if (std::optional<std::string> engine = EngineStyleError(style)) {
    ConfigError e = c.Locate("output.engine");
    e.message = *engine;
    c.errors.push_back(e);
  }
}

// IBL: a cube mip chain needs a power-of-two level 0 and at most one
// level per halving; some file format must be asked for.
void CheckIbl(const SkyStyle& style, StyleChecks& c) {
  const IblSettings& ibl = style.ibl;
  if (ibl.Requested()) {
    int log2_size = 0;
    while ((2 << log2_size) <= ibl.size) ++log2_size;
    if ((1 << log2_size) != ibl.size) {
      ConfigError e = c.Locate("ibl.size");
      e.message = fmt::format("{} is not a power of two: use {} or {}", ibl.size, 1 << log2_size, 2 << log2_size);
      c.errors.push_back(e);
    } else if (ibl.levels > log2_size + 1) {
      ConfigError e = c.Locate("ibl.levels");
      e.message = fmt::format("a {} cube has at most {} mip levels (down to 1 x 1): lower ibl.levels or raise ibl.size",
                              ibl.size, log2_size + 1);
      c.errors.push_back(e);
    }
    if (!ibl.exr && !ibl.ktx2) {
      ConfigError e = c.Locate("ibl.exr");
      e.message = "IBL maps are asked for but neither ibl.exr nor ibl.ktx2 is true: set one of them";
      c.errors.push_back(e);
    }
    if (ibl.ktx2_zstd_level > 0 && !ibl.ktx2) {
      ConfigError e = c.Locate("ibl.ktx2_zstd_level");
      e.message = "zstd supercompression applies to KTX2 files: set ibl.ktx2 = true or ibl.ktx2_zstd_level = 0";
      c.errors.push_back(e);
    }
  }
}

// The disc in half-float maps of luminance (output.sun = "map"): its centre,
// about 1e9 cd/m^2 by day, is beyond half range (65504) whatever the sky, so
// with output.overflow = "refuse" the bake could only fail after its GPU work.
void CheckSunInMaps(const SkyStyle& style, StyleChecks& c) {
  const OutputSettings& o = style.output;
  if (o.sun != SunOutput::kMap || o.pixel_type != PixelType::kHalf || o.overflow != OverflowPolicy::kRefuse ||
      o.units != OutputUnits::kLuminance || !style.effects.sun_disc || style.effects.sun_disc_strength <= 0.0)
    return;
  ConfigError e = c.Locate("output.sun");
  e.message =
      "the solar disc in half-float maps exceeds half range (65504 cd/m^2) and output.overflow = \"refuse\" "
      "forbids a scale: set output.sun = \"light\" (the Sun as a light, the default), "
      "output.pixel_type = \"float\", or output.overflow = \"scale\"";
  c.errors.push_back(e);
}

// output.color_space names a built-in space or one of an OpenColorIO config
// (output.ocio_config, relative to the style's folder, else $OCIO).
void CheckColorSpace(SkyStyle& style, StyleChecks& c) {
  OutputSettings& o = style.output;
  std::string config = o.ocio_config;
  if (!config.empty() && std::filesystem::path(config).is_relative())
    config = (std::filesystem::path(c.name).parent_path() / config).string();
  ColorSpaceLookup lookup = ResolveOutputColorSpace(o.color_space.name, config);
  if (lookup.space) {
    o.color_space = *lookup.space;
    return;
  }
  ConfigError e = c.Locate("output.color_space");
  e.message = lookup.error;
  c.errors.push_back(e);
}

// The spectral mode (quality.wavelengths > 3) integrates radiance to colour:
// radiance output keeps the three named wavelengths. (The per-texel effects
// that act on RGB colour, the AOAS saturation clouds and shapes and the night
// floor, are applied to the combined colour by the style pass, spectral_sky.h:
// with cloud layers to the sky behind them, as with three wavelengths.)
void CheckSpectral(SkyStyle& style, StyleChecks& c) {
  const bool radiance = style.output.units == OutputUnits::kSpectral;
  if (radiance && !style.output.color_space.IsRec709()) {
    ConfigError e = c.Locate("output.color_space");
    e.message =
        "radiance at 680/550/440 nm (output.units = \"spectral\") has no primaries: set "
        "output.units = \"luminance\" or output.color_space = \"rec709\"";
    c.errors.push_back(e);
  }
  if (style.quality.wavelengths <= kRgbWavelengths) return;
  if (radiance) {
    ConfigError w = c.Locate("quality.wavelengths");
    w.message = fmt::format(
        "output.units = \"spectral\" writes radiance at 680/550/440 nm, so the {} bins are "
        "not rendered (the three-wavelength path is): set output.units = \"luminance\" for "
        "the spectral mode's colour",
        style.quality.wavelengths);
    c.warnings.push_back(w);
    style.quality.wavelengths = kRgbWavelengths;
  }
}

// A preset that every explicit key overrides changes nothing: say so.
void WarnPresetChangesNothing(const SkyStyle& style, const StyleReader& reader, StyleChecks& c) {
  if (reader.Given("quality.preset")) {
    std::vector<std::string> keys = PresetKeys();
    bool all_given = std::all_of(keys.begin(), keys.end(), [&](const std::string& k) { return reader.Given(k); });
    if (all_given) {
      ConfigError w = c.Locate("quality.preset");
      std::string list;
      for (const std::string& k : keys) list += (list.empty() ? "" : ", ") + k;
      w.message = fmt::format(
          "preset '{}' changes nothing: every key it sets is given explicitly ({}), and "
          "explicit keys refine the preset; remove or comment out those keys to use it",
          style.quality_preset, list);
      c.warnings.push_back(w);
    }
  }
}

// The style as the bake records it (every EXR's skybake:config): every key
// resolved, in the writer's order.
std::string ResolvedToml(SkyStyle& style) {
  StyleWriter writer;
  VisitStyle(style, writer);
  // Without IBL outputs their keys are left out of the record, so such a
  // bake's files are the same bytes as before the keys existed.
  toml::table recorded = writer.table();
  if (!style.ibl.Requested()) recorded.erase("ibl");
  else if (style.ibl.full_samples_roughness == 0.0) recorded["ibl"].as_table()->erase("full_samples_roughness");
  if (style.output.engine == "none") recorded["output"].as_table()->erase("engine");
  if (!style.gltf.image_based_light) recorded["gltf"].as_table()->erase("image_based_light");
  if (!style.usd.enabled) recorded.erase("usd");
  if (style.quality.wavelengths == kRgbWavelengths) recorded["quality"].as_table()->erase("wavelengths");
  if (style.output.color_space.IsRec709()) recorded["output"].as_table()->erase("color_space");
  std::ostringstream resolved;
  resolved << recorded;
  return resolved.str();
}

}  // namespace

ConfigResult ParseSkyStyle(std::string_view toml_text, const std::string& name,
                           const std::vector<std::string>& overrides) {
  ConfigResult result;
  result.style.source_path = name;
  std::optional<toml::table> parsed = ParseTomlText(toml_text, name, result.errors);
  if (!parsed) return result;
  toml::table& root = *parsed;
  for (const std::string& o : overrides) ApplyOverride(root, o, result.errors);

  StyleReader reader(root, name, result.errors);
  VisitStyle(result.style, reader);
  reader.ReportUnknownKeys({"schedule"});  // read by LoadSchedule (schedule.h)
  if (const toml::node* c = root.at_path("night.star_catalogue").node();
      c && c->source().path && *c->source().path != name)
    result.style.night.star_catalogue_set = *c->source().path;

  // Cross-field checks, located at the second key.
  StyleChecks checks{root, name, result.errors, result.warnings};
  CheckAtmosphere(result.style, checks);
  CheckAoas(result.style, checks);
  CheckCloudLayers(result.style, checks);
  CheckFaceNames(result.style, checks);
  CheckSceneAndEngine(result.style, checks);
  CheckIbl(result.style, checks);
  CheckColorSpace(result.style, checks);
  CheckSpectral(result.style, checks);
  CheckSunInMaps(result.style, checks);
  WarnPresetChangesNothing(result.style, reader, checks);
  if (!result.ok()) return result;

  // A target colour decides the hue vector (README "Styles").
  if (!result.style.aoas.hue.color.empty()) {
    Rgb target;
    ParseHexColor(result.style.aoas.hue.color, target);
    result.style.aoas.hue.rayleigh_per_km =
        RayleighForTargetColor(target, result.style.atmosphere, OutputScale(OutputUnits::kLuminance));
  }

  result.style.resolved_toml = ResolvedToml(result.style);
  return result;
}

bool KeyHasTooManyParts(std::string_view key) {
  size_t parts = 1;
  for (size_t at = key.find('.'); at != std::string_view::npos; at = key.find('.', at + 1))
    if (++parts > kMaxKeyParts) return true;
  return false;
}

std::optional<ConfigError> DeepKeyError(std::string_view text, const std::string& name) {
  std::optional<toml::source_position> at = DeepKey(text);
  if (!at) return std::nullopt;
  ConfigError e;
  e.file = name;
  e.line = int(at->line);
  e.column = int(at->column);
  e.key = "(syntax)";
  e.message = fmt::format(
      "a dotted key or table name of more than {} parts: skybake's keys have at most 5, e.g. "
      "atmosphere.rayleigh.scale_height_km",
      kMaxKeyParts);
  return e;
}

std::optional<ConfigError> ReadInputFile(const std::string& path, const char* what, std::string& text) {
  ConfigError e;
  e.file = path;
  e.key = "(file)";
  // Through the door (file_door.h): non-blocking, a regular file, capped
  // whatever the size says (a file in /proc says 0).
  const std::string problem = ReadRegularFile(path, kMaxInputBytes, FileLinks::kFollow, text);
  if (problem.empty()) return std::nullopt;
  if (problem == "no such file" || problem.rfind("cannot be opened", 0) == 0 ||
      problem.rfind("cannot be read (no", 0) == 0)
    e.message = fmt::format("cannot open the {} file: check the path", what);
  else if (problem == "is a directory, not a file")
    e.message = fmt::format("is a directory: give a {} TOML file", what);
  else if (problem.find("not a regular file") != std::string::npos)
    e.message = fmt::format("is not a regular file (a device, a pipe or a socket): give a {} TOML file", what);
  else if (problem.find("MiB") != std::string::npos)
    e.message = fmt::format(
        "is larger than {} MiB, the limit of a style or schedule file (a schedule of "
        "100,000 frames listed one by one is under 8 MiB): give a {} TOML file",
        kMaxInputBytes >> 20, what);
  else e.message = fmt::format("the {} file {}", what, problem);
  return e;
}

ConfigResult LoadSkyStyle(const std::string& path, const std::vector<std::string>& overrides) {
  std::string text;
  if (std::optional<ConfigError> e = ReadInputFile(path, "style", text)) {
    ConfigResult result;
    result.errors.push_back(*e);
    return result;
  }
  return ParseSkyStyle(text, path, overrides);
}

std::string EscapedText(std::string_view text) {
  std::string out = "'";
  for (char ch : text) {
    const unsigned char c = static_cast<unsigned char>(ch);
    if (c == '\\' || c == '\'') out += fmt::format("\\{}", ch);
    else if (c == '\n') out += "\\n";
    else if (c == '\t') out += "\\t";
    else if (c < 0x20 || c == 0x7f) out += fmt::format("\\x{:02x}", c);
    else out += ch;
  }
  return out + "'";
}

}  // namespace skybake
