#include "skybake/model/atmosphere.h"

#include <algorithm>
#include <cmath>

namespace skybake {

glm::dvec3 SunDirectionFromElevationAzimuth(double elevation_deg, double azimuth_deg) {
  const double kDegToRad = M_PI / 180.0;
  double elevation = elevation_deg * kDegToRad;
  double azimuth = azimuth_deg * kDegToRad;
  // North = -Z, East = +X: azimuth 0 -> -Z, azimuth 90 -> +X.
  return {std::sin(azimuth) * std::cos(elevation), std::sin(elevation), -std::cos(azimuth) * std::cos(elevation)};
}

// Each preset is the cheapest case of the accuracy study's Pareto front that
// meets its bound (docs/accuracy.md, `skybake accuracy`):
//   draft       analytic 24 quadratic steps, sky-view LUT 192 x 216   7.4e-3
//               (216 rows, not 108: within 5% at sun -6..90 deg, docs/accuracy.md "Twilight")
//   production  analytic 32 quadratic steps, sky-view LUT 256 x 144   8.59e-3
//   reference   Simpson 64 quadratic steps per texel, transmittance
//               LUT 1024 x 256 (1024 points)                          1.77e-4
// and at twilight (the Sun below 3 deg: the sun transmittance read in the
// logarithm; docs/accuracy.md "Twilight", sun 5 .. -10 deg):
//   draft       the sky up to 10 deg marched, 32 steps                1.24e-2
//   production  the sky up to 10 deg marched, 80 steps                5.31e-3
//   reference   128 steps per texel                                   7.08e-4
QualitySettings QualityPreset(const std::string& name) {
  QualitySettings q;  // production
  if (name == "draft") {
    q.sky_view_width = 192;
    q.sky_view_height = 216;
    q.view_steps = 24;
    q.twilight_march_steps = 32;
  } else if (name == "reference") {
    q.sky_view_lut = false;
    q.view_steps = 64;
    q.integrator = INTEGRATOR_SIMPSON;
    q.transmittance_width = 1024;
    q.transmittance_height = 256;
    q.transmittance_steps = 1024;
    q.twilight_march_band_deg = 0.0;  // no sky-view LUT: every texel is marched
    q.twilight_march_steps = 128;
  }
  return q;
}

std::vector<std::string> QualityPresetNames() { return {"draft", "production", "reference"}; }

Rgb NightSkyRadiance(const EffectSettings& e) {
  // Bruneton 2017's SKY_SPECTRAL_RADIANCE_TO_LUMINANCE (lm/W) per channel:
  // radiance L / K_c gives Rec.709 (L, L, L), neutral of luminance L.
  const Rgb k = {114974.916437, 71305.954816, 65310.548555};
  return {e.night_sky_luminance_cd_m2 / k[0], e.night_sky_luminance_cd_m2 / k[1], e.night_sky_luminance_cd_m2 / k[2]};
}

double TwilightSunElevationDeg(const QualitySettings& q) {
  return q.twilight_sun_below_deg > 0.0 ? q.twilight_sun_below_deg : q.twilight_march_band_deg;
}

double SunlitAirDepressionDeg(double bottom_radius_km, double top_radius_km, double observer_altitude_km,
                              double sun_angular_radius_rad) {
  const double r = bottom_radius_km + std::max(observer_altitude_km, 0.0);
  if (r >= top_radius_km) return 180.0;
  const double dip = std::acos(std::min(bottom_radius_km / r, 1.0));
  const double beyond = std::acos(std::min(bottom_radius_km / top_radius_km, 1.0));
  return (dip + 2.0 * beyond + sun_angular_radius_rad) * 180.0 / M_PI + 0.5;
}

bool SunlitAirInView(double sun_elevation_deg, double bottom_radius_km, double top_radius_km,
                     double observer_altitude_km, double sun_angular_radius_rad) {
  return sun_elevation_deg >
         -SunlitAirDepressionDeg(bottom_radius_km, top_radius_km, observer_altitude_km, sun_angular_radius_rad);
}

bool NeedsTransmittanceLut(const QualitySettings& q, const EffectSettings& e) {
  return q.light_steps <= 0 || e.multiple_scattering || e.ground || e.sun_disc;
}

gpu::GpuAtmosphere ToGpuAtmosphere(const AtmosphereParams& a, const QualitySettings& q, const EffectSettings& effects,
                                   const Rgb& output_scale) {
  auto v4 = [](const Rgb& rgb, double w) { return gpu::vec4{float(rgb[0]), float(rgb[1]), float(rgb[2]), float(w)}; };
  gpu::GpuAtmosphere g{};
  g.rayleigh_scattering = v4(a.rayleigh_scattering_per_km, a.rayleigh_scale_height_km);
  g.mie_scattering = v4(a.mie_scattering_per_km, a.mie_scale_height_km);
  g.mie_extinction = v4(a.mie_extinction_per_km, a.mie_g);
  g.absorption_extinction = v4(a.ozone_absorption_per_km, a.ozone_peak_altitude_km);
  g.ground_albedo = v4(a.ground_albedo, a.ozone_half_width_km);
  g.solar_irradiance = v4(a.solar_irradiance, a.sun_angular_radius_rad);
  g.radii = {float(a.bottom_radius_km), float(a.top_radius_km), float(a.observer_altitude_m * 1e-3),
             float(a.limb_darkening_u)};
  g.output_scale = v4(output_scale, 0.0);
  for (int i = 0; i < 3; ++i) {  // one conversion for every path until SetOutputConversion (colour_conversion.h)
    Rgb row{};
    row[i] = output_scale[i];
    g.sky_to_output[i] = v4(row, 0.0);
    Rgb identity{};
    identity[i] = 1.0;
    g.ambient_to_direct[i] = v4(identity, 0.0);
  }
  g.lut_sizes = {q.transmittance_width, q.transmittance_height, q.multiscattering_size, q.multiscattering_size};
  g.samples = {q.view_steps, q.transmittance_steps, q.multiscattering_steps, q.integrator};
  g.effects = {effects.multiple_scattering, effects.sun_disc, effects.ground, q.multiscattering_sqrt_dirs};
  g.render = {q.light_steps, q.sky_view_width, q.sky_view_height, q.step_distribution};
  g.strengths = {float(effects.multiple_scattering_strength), float(effects.sun_disc_strength), 0.0f, 0.0f};
  g.night = v4(NightSkyRadiance(effects), effects.night_dimming_strength);
  g.twilight = {float(q.twilight_march_band_deg * M_PI / 180.0),
                float(q.twilight_march_steps > 0 ? q.twilight_march_steps : q.view_steps),
                float(TwilightSunElevationDeg(q) > 0.0 ? std::sin(TwilightSunElevationDeg(q) * M_PI / 180.0) : -2.0),
                0.0f};
  return g;
}

}  // namespace skybake
