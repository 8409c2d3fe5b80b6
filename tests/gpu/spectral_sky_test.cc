// The spectral mode on lavapipe (spectral_sky.h), under the validation
// layer: the white-spectrum check, energy consistency with the
// three-wavelength renderer, the combination, and the style's checks.
#include "skybake/gpu/spectral_sky.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>

#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <gtest/gtest.h>

#include "skybake/input/config.h"
#include "skybake/input/schedule.h"
#include "skybake/model/aoas.h"
#include "skybake/model/clouds.h"
#include "skybake/model/spectrum.h"
#include "skybake/pipeline/pass_plan.h"
#include "skybake/pipeline/pipeline.h"
#include "skybake/tools/accuracy.h"
#include "skybake/tools/kider_spectral_study.h"
#include "skybake/tools/spectral_study.h"
#include "schedule_fixtures.h"
#include "test_support.h"

namespace skybake {
namespace {

std::array<double, 3> XyzOfRec709(const float* rgb) {
  // Inverse of XyzToRgb(kRec709).
  const Matrix3 m = XyzToRgb(ColorSpace::kRec709);
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  auto cof = [&](int r, int c) {
    const int r0 = (r + 1) % 3, r1 = (r + 2) % 3, c0 = (c + 1) % 3, c1 = (c + 2) % 3;
    return m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
  };
  std::array<double, 3> xyz{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) xyz[i] += cof(j, i) / det * rgb[j];
  return xyz;
}

// A flat solar spectrum seen through no atmosphere (no scattering, no
// absorption) integrates to the equal-energy white point, x = y = 1/3, and
// the sky beside the Sun is black.
TEST(SpectralSkyTest, FlatSunThroughNoAtmosphereIsTheEqualEnergyWhite) {
  AtmosphereParams empty;
  empty.rayleigh_scattering_per_km = {0.0, 0.0, 0.0};
  empty.mie_scattering_per_km = {0.0, 0.0, 0.0};
  empty.mie_extinction_per_km = {0.0, 0.0, 0.0};
  empty.ozone_absorption_per_km = {0.0, 0.0, 0.0};
  EffectSettings effects;
  effects.multiple_scattering = false;
  effects.ground = false;
  QualitySettings quality;
  quality.wavelengths = 16;
  for (int n : {4, 16, 48}) {
    const SpectralBins bins = WavelengthBins(n);
    std::vector<SpectralGroup> groups = SpectralGroups(empty, bins);
    for (SpectralGroup& g : groups) g.atmosphere.solar_irradiance = {1.0, 1.0, 1.0};  // W m^-2 nm^-1, flat
    quality.wavelengths = n;
    SpectralSky sky(testing::Vulkan(), bins, groups, quality, effects);
    const glm::dvec3 sun = SunDirectionFromElevationAzimuth(30.0, 90.0);
    const std::vector<float> rgba = sky.RenderDirections(sun, {sun, SunDirectionFromElevationAzimuth(60.0, 0.0)}, true);
    const std::array<double, 3> xyz = XyzOfRec709(rgba.data());
    const double sum = xyz[0] + xyz[1] + xyz[2];
    ASSERT_GT(sum, 0.0) << n << " bins: the disc is missing";
    EXPECT_NEAR(xyz[0] / sum, 1.0 / 3.0, 5e-4) << n << " bins";
    EXPECT_NEAR(xyz[1] / sum, 1.0 / 3.0, 5e-4) << n << " bins";
    // The disc's centre: E / (pi alpha^2 (1 - u / 3)) W m^-2 sr^-1 nm^-1 at
    // every wavelength (SunDiscRadiance, the limb-darkened disc of unit irradiance).
    const double alpha = empty.sun_angular_radius_rad;
    const double radiance = 1.0 / (M_PI * alpha * alpha * (1.0 - empty.limb_darkening_u / 3.0));
    EXPECT_NEAR(xyz[1], 683.0 * 106.857 * radiance, 683.0 * 106.857 * radiance * 0.01) << n << " bins";
    for (int c = 0; c < 3; ++c) EXPECT_EQ(rgba[4 + c], 0.0f) << "sky without an atmosphere, channel " << c;
  }
  testing::ExpectNoValidationMessages();
}

// At the named wavelengths 680/550/440 nm the spectral mode's group is the
// three-wavelength renderer: the same radiance, texel for texel.
TEST(SpectralSkyTest, NamedWavelengthsGiveTheThreeChannelRadiance) {
  const AtmosphereParams atmosphere;
  QualitySettings quality;
  const EffectSettings effects;
  const SpectralBins bins = BinsAt({680.0, 550.0, 440.0}, 10.0);
  quality.wavelengths = 3;
  SkyRenderer three(testing::Vulkan(), atmosphere, quality, effects, {1.0, 1.0, 1.0});
  SpectralSky spectral(testing::Vulkan(), bins, SpectralGroups(atmosphere, bins), quality, effects);
  const std::vector<ViewRequest> views = {{MAPPING_LATLONG, 64, 32, 0}};
  for (double elevation : {30.0, 2.0, -4.0}) {
    const glm::dvec3 sun = SunDirectionFromElevationAzimuth(elevation, 135.0);
    const std::vector<float> a = three.Render(sun, views)[0];
    const std::vector<float> b = spectral.group(0).Render(sun, views)[0];
    ASSERT_EQ(a.size(), b.size());
    double worst = 0.0;
    for (size_t i = 0; i < a.size(); ++i)
      if (a[i] > 0.0f) worst = std::max(worst, std::abs(double(b[i]) - a[i]) / a[i]);
    // The coefficients agree to double rounding; stored as float, they may
    // differ by one step, and the sky-view LUT keeps 12 mantissa bits.
    EXPECT_LE(worst, testing::kSkyViewLutStorageStep) << "sun " << elevation;
  }
  testing::ExpectNoValidationMessages();
}

// The spectral SkyRenderer is its groups' radiance times their CIE matrices.
TEST(SpectralSkyTest, RendererCombinesItsGroupsWithTheCieWeights) {
  const AtmosphereParams atmosphere;
  QualitySettings quality;
  quality.wavelengths = 8;
  const EffectSettings effects;
  SkyRenderer renderer(testing::Vulkan(), atmosphere, quality, effects, {1.0, 1.0, 1.0});
  SpectralSky groups(testing::Vulkan(), atmosphere, quality, effects, AoasInputs(), CloudInputs(), ShaderSwitches());
  ASSERT_EQ(groups.groups().size(), 3u);
  const std::vector<ViewRequest> views = {{MAPPING_LATLONG, 32, 16, 0}};
  const glm::dvec3 sun = SunDirectionFromElevationAzimuth(10.0, 200.0);
  const std::vector<float> combined = renderer.Render(sun, views)[0];
  std::vector<double> want(combined.size(), 0.0);
  for (size_t g = 0; g < groups.groups().size(); ++g) {
    const std::vector<float> radiance = groups.group(g).Render(sun, views)[0];
    const Matrix3& m = groups.groups()[g].to_rgb;
    for (size_t t = 0; t < radiance.size() / 4; ++t)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) want[4 * t + i] += m[i][j] * radiance[4 * t + j];
  }
  for (size_t i = 0; i < combined.size(); ++i) {
    if (i % 4 == 3) continue;
    EXPECT_NEAR(combined[i], want[i], 1e-5 * std::abs(want[i]) + 1e-9) << "value " << i;
  }
  EXPECT_EQ(renderer.counters().frames, 1);
  EXPECT_EQ(renderer.counters().skyview_lut_builds, 3) << "one sky-view LUT per group";
  testing::ExpectNoValidationMessages();
}

// A latlong of the styled sky as a bake renders it (renderer_cache.cc): the
// hue in the atmosphere, the per-texel principles in the AOAS inputs, whose
// colour scale is OutputScale(kLuminance); 3 wavelengths or the spectral mode.
std::vector<float> StyledLatlong(int wavelengths, const AoasSettings& aoas, const EffectSettings& effects,
                                 const glm::dvec3& sun) {
  QualitySettings quality;
  quality.wavelengths = wavelengths;
  const Rgb scale = OutputScale(OutputUnits::kLuminance);
  SkyRenderer renderer(testing::Vulkan(), StyledAtmosphere(AtmosphereParams(), aoas), quality, effects, scale, false,
                       ToAoasInputs(aoas, scale));
  return renderer.Render(sun, {{MAPPING_LATLONG, 96, 48, 0}})[0];
}

// Hue in [0, 1), saturation, value of RGB (the definitions of aoas.glsl's
// RgbToHsv, in double).
std::array<double, 3> Hsv(const float* c) {
  const double v = std::max({double(c[0]), double(c[1]), double(c[2])});
  const double lo = std::min({double(c[0]), double(c[1]), double(c[2])});
  const double delta = v - lo;
  double h = 0.0;
  if (delta > 0.0) {
    if (v == c[0]) h = (c[1] - c[2]) / delta;
    else if (v == c[1]) h = 2.0 + (c[2] - c[0]) / delta;
    else h = 4.0 + (c[0] - c[1]) / delta;
    h /= 6.0;
    if (h < 0.0) h += 1.0;
  }
  return {h, v > 0.0 ? delta / v : 0.0, v};
}

// No texel is NaN, infinite, or negative where the unstyled sky is not.
void ExpectFiniteAndNoNewNegatives(const std::vector<float>& on, const std::vector<float>& off, const char* what) {
  int bad = 0;
  for (size_t i = 0; i < on.size(); ++i)
    if (!std::isfinite(on[i]) || (on[i] < 0.0f && off[i] >= 0.0f)) ++bad;
  EXPECT_EQ(bad, 0) << what;
}

// The saturation principle (clouds or shapes) on against off: the texel's
// value (HSV V, the largest channel) and hue kept, its saturation scaled
// by the principle's keep factor. Returns the keep factor of each texel
// whose unstyled saturation is above 0.05 (-1 elsewhere).
std::vector<double> KeepFactors(const std::vector<float>& on, const std::vector<float>& off, const char* what) {
  std::vector<double> keep(on.size() / 4, -1.0);
  double worst_value = 0.0, worst_hue = 0.0;
  for (size_t t = 0; t < keep.size(); ++t) {
    const std::array<double, 3> a = Hsv(&off[4 * t]), b = Hsv(&on[4 * t]);
    if (a[2] <= 0.0) continue;
    worst_value = std::max(worst_value, std::abs(b[2] - a[2]) / a[2]);
    if (a[1] <= 0.05) continue;
    keep[t] = b[1] / a[1];
    if (b[1] > 0.01) worst_hue = std::max(worst_hue, std::min(std::abs(b[0] - a[0]), 1.0 - std::abs(b[0] - a[0])));
  }
  // Float rounding of a few operations (2^-24 = 6e-8 each) on the value
  // (seen: 7e-8); on the hue, of channel differences of at least 5% of the
  // value (seen: 2e-6).
  EXPECT_LE(worst_value, 1e-6) << what << ": the value (largest channel) changed";
  EXPECT_LE(worst_hue, 2e-5) << what << ": the hue changed";
  return keep;
}

// The saturation principles in the spectral mode do what they do with
// three wavelengths: the same keep factor at every texel (the principle's
// noise or shapes are geometry, the same in both), value and hue kept.
void ExpectSaturationAsWithThreeWavelengths(const AoasSettings& on_style, const std::string& what) {
  AoasSettings off_style = on_style;
  off_style.clouds.enabled = false;
  off_style.shapes.enabled = false;
  const EffectSettings effects;
  const glm::dvec3 sun = SunDirectionFromElevationAzimuth(25.0, 150.0);
  std::map<int, std::vector<double>> keep;
  for (int n : {3, 8}) {
    const std::vector<float> on = StyledLatlong(n, on_style, effects, sun);
    const std::vector<float> off = StyledLatlong(n, off_style, effects, sun);
    const std::string label = fmt::format("{}, {} wavelengths", what, n);
    ExpectFiniteAndNoNewNegatives(on, off, label.c_str());
    keep[n] = KeepFactors(on, off, label.c_str());
  }
  int compared = 0, clouded = 0;
  double worst = 0.0;
  for (size_t t = 0; t < keep[3].size(); ++t) {
    if (keep[3][t] < 0.0 || keep[8][t] < 0.0) continue;
    ++compared;
    if (keep[3][t] < 0.8) ++clouded;
    worst = std::max(worst, std::abs(keep[8][t] - keep[3][t]));
  }
  // Both keep factors are ratios of saturations of at least 0.05 rounded
  // to float: a few 2^-24 over 0.05 each, about 1e-6 (seen: 1.2e-6).
  EXPECT_LE(worst, 1e-5) << what << ": the spectral keep factor differs from the three-wavelength one";
  EXPECT_GT(compared, 1000) << what;
  EXPECT_GT(clouded, 50) << what << ": too few texels lose a fifth of their saturation for the test to mean anything";
  testing::ExpectNoValidationMessages();
}

TEST(SpectralSkyTest, SaturationCloudsActAsWithThreeWavelengths) {
  AoasSettings aoas;
  aoas.clouds.enabled = true;
  aoas.clouds.strength = 1.0;
  ExpectSaturationAsWithThreeWavelengths(aoas, "aoas.clouds");
}

TEST(SpectralSkyTest, CloudShapesActAsWithThreeWavelengths) {
  AoasSettings aoas;
  aoas.shapes.enabled = true;
  CloudShape arc;
  arc.kind = ShapeKind::kPolyline;
  arc.points = {{20.0, 60.0}, {45.0, 150.0}, {30.0, 260.0}};
  arc.radius_deg = 12.0;
  aoas.shapes.shapes = {arc};
  ExpectSaturationAsWithThreeWavelengths(aoas, "aoas.shapes");
}

// The night floor in the spectral mode adds the neutral the three-wavelength
// path adds: on = (1 - k) off + k L (1, 1, 1) above the horizon, (1 - k) off
// below it, with k the night weight of the Sun's elevation and L the floor's
// luminance in cd/m^2; so its luminance adds k L, energy for energy.
TEST(SpectralSkyTest, NightFloorAddsTheNeutralOfThreeWavelengths) {
  EffectSettings off;
  EffectSettings on = off;
  on.night_dimming = true;
  on.night_dimming_strength = 0.8;
  on.night_sky_luminance_cd_m2 = 2e-3;
  const double elevation = -12.0;
  const glm::dvec3 sun = SunDirectionFromElevationAzimuth(elevation, 200.0);
  // 1 - smoothstep(sin(-18 deg), sin(-6 deg), sin(elevation)), as NightDimmingWeight.
  const double a = std::sin(-18.0 * M_PI / 180.0), b = std::sin(-6.0 * M_PI / 180.0);
  const double x = std::clamp((std::sin(elevation * M_PI / 180.0) - a) / (b - a), 0.0, 1.0);
  const double k = on.night_dimming_strength * (1.0 - x * x * (3.0 - 2.0 * x));
  const double floor = on.night_sky_luminance_cd_m2;
  const AoasSettings aoas;
  const ViewRequest view{MAPPING_LATLONG, 96, 48, 0};
  for (int n : {3, 8}) {
    const std::vector<float> with = StyledLatlong(n, aoas, on, sun);
    const std::vector<float> without = StyledLatlong(n, aoas, off, sun);
    ExpectFiniteAndNoNewNegatives(with, without, "night floor");
    double worst = 0.0, sky_luminance = 0.0;
    for (int y = 0; y < view.height; ++y)
      for (int x = 0; x < view.width; ++x) {
        const size_t t = size_t(y) * view.width + x;
        const bool above = ViewTexelDirection(view, x, y).y > 0.0;
        for (int c = 0; c < 3; ++c) {
          const double want = (1.0 - k) * without[4 * t + c] + (above ? k * floor : 0.0);
          // Float rounding of the blend and the colour scale's two steps,
          // a few 2^-24 (seen: 2.4e-7).
          worst = std::max(worst,
                           std::abs(with[4 * t + c] - want) / ((1.0 - k) * std::abs(without[4 * t + c]) + k * floor));
        }
        if (above && y == 0) sky_luminance += without[4 * t + 1] / view.width;
      }
    EXPECT_LE(worst, 2e-6) << n << " wavelengths";
    // Both terms count: the twilight sky and the floor are within a few decades.
    EXPECT_GT(sky_luminance, 1e-3 * floor) << n << " wavelengths";
    EXPECT_LT(sky_luminance, 1e3 * floor) << n << " wavelengths";
  }
  // The spectral renderer's directions get the floor too.
  QualitySettings quality;
  quality.wavelengths = 8;
  const Rgb scale = OutputScale(OutputUnits::kLuminance);
  SkyRenderer night(testing::Vulkan(), AtmosphereParams(), quality, on, scale, false, ToAoasInputs(aoas, scale));
  SkyRenderer day(testing::Vulkan(), AtmosphereParams(), quality, off, scale, false, ToAoasInputs(aoas, scale));
  const std::vector<glm::dvec3> up = {{0.0, 1.0, 0.0}, {0.0, -1.0, 0.0}};
  const std::vector<float> lit = night.RenderDirections(sun, up), dark = day.RenderDirections(sun, up);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(lit[c], (1.0 - k) * dark[c] + k * floor, 2e-6 * ((1.0 - k) * std::abs(dark[c]) + k * floor)) << c;
    EXPECT_NEAR(lit[4 + c], (1.0 - k) * dark[4 + c], 2e-6 * std::abs(dark[4 + c]) + 1e-12) << c;
  }
  testing::ExpectNoValidationMessages();
}

// ------------------------------------------- the colour principles and cloud layers

// A cumulus deck that hides part of the sky (clouds_test.cc's), appended to a style.
const char* kCumulusLayer =
    "[[cloud_layer]]\naltitude_m = 1500\nthickness_m = 1500\ntype = \"cumulus\"\ncoverage = 0.5\n";

// A latlong of a style (TOML) as a bake renders it (renderer_cache.cc),
// with or without the cumulus deck, at 3 wavelengths or N bins; or its
// radiance along `directions` (RenderDirections, the SH's samples).
std::vector<float> LayeredLatlong(const std::string& toml, int wavelengths, bool layers, const glm::dvec3& sun,
                                  const std::vector<glm::dvec3>& directions = {}) {
  const ConfigResult r = ParseSkyStyle(layers ? toml + kCumulusLayer : toml, "layered.toml",
                                       {fmt::format("quality.wavelengths={}", wavelengths)});
  EXPECT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].Format());
  const SkyStyle style = PrunedStyle(r.style);
  const Rgb scale = OutputScale(OutputUnits::kLuminance);
  SkyRenderer renderer(testing::Vulkan(), StyledAtmosphere(style.atmosphere, style.aoas), style.quality, style.effects,
                       scale, false, ToAoasInputs(style.aoas, scale),
                       ToCloudInputs(style.clouds, style.aoas.seed, "", 0.0));
  if (!directions.empty()) return renderer.RenderDirections(sun, directions);
  return renderer.Render(sun, {{MAPPING_LATLONG, 96, 48, 0}})[0];
}

// Four latlongs of one path: the styling on and off, with and without the deck.
struct LayeredSkies {
  std::vector<float> on, off, clear_on, clear_off;
};
LayeredSkies RenderLayeredSkies(const std::string& styled, const std::string& plain, int wavelengths,
                                const glm::dvec3& sun, const std::vector<glm::dvec3>& directions = {}) {
  return {LayeredLatlong(styled, wavelengths, true, sun, directions),
          LayeredLatlong(plain, wavelengths, true, sun, directions),
          LayeredLatlong(styled, wavelengths, false, sun, directions),
          LayeredLatlong(plain, wavelengths, false, sun, directions)};
}

// The styling acts on the sky behind the clouds: at every texel the change
// it makes under the deck (on - off) is the change it makes to the clear sky,
// R = clear_on - clear_off, times one factor, the clouds' transmittance: the
// same in every channel, within [0, 1]. Errors are measured in the texel's
// colour (its largest channel): the residual of the fit, and how far t |R|
// lies outside [0, |R|]. Returns t, and |R| over that colour, for each texel
// where |R| is at least 1e-3 of it (elsewhere t = -1, and the change under
// the deck must be no larger than R).
struct ChangeUnderDeck {
  std::vector<double> t, weight;
};
ChangeUnderDeck TransmittanceOfTheChange(const LayeredSkies& s, const std::string& what) {
  const size_t texels = s.on.size() / 4;
  ChangeUnderDeck out{std::vector<double>(texels, -1.0), std::vector<double>(texels, 0.0)};
  double worst_fit = 0.0, worst_range = 0.0, worst_still = 0.0;
  for (size_t i = 0; i < texels; ++i) {
    double rr = 0.0, dr = 0.0, dd = 0.0, size = 0.0;
    std::array<double, 3> d{}, r{};
    for (int c = 0; c < 3; ++c) {
      d[c] = double(s.on[4 * i + c]) - s.off[4 * i + c];
      r[c] = double(s.clear_on[4 * i + c]) - s.clear_off[4 * i + c];
      rr += r[c] * r[c];
      dr += d[c] * r[c];
      dd += d[c] * d[c];
      size = std::max({size, std::abs(double(s.off[4 * i + c])), std::abs(double(s.clear_off[4 * i + c])),
                       std::abs(double(s.clear_on[4 * i + c]))});
    }
    if (size <= 0.0) continue;
    if (std::sqrt(rr) < 1e-3 * size) {
      worst_still = std::max(worst_still, (std::sqrt(dd) - std::sqrt(rr)) / size);
      continue;
    }
    const double t = dr / rr, weight = std::sqrt(rr) / size;
    out.t[i] = t;
    out.weight[i] = weight;
    for (int c = 0; c < 3; ++c) worst_fit = std::max(worst_fit, std::abs(d[c] - t * r[c]) / size);
    worst_range = std::max({worst_range, -t * weight, (t - 1.0) * weight});
  }
  // Float rounding of the colours (a few 2^-24 of the largest channel each)
  // and, in the spectral mode, of the groups' shares of the change (seen:
  // 7.6e-8 with three wavelengths, 2.6e-7 with 8 bins, for each of the three).
  EXPECT_LE(worst_fit, 2e-6) << what << ": the change under the deck is not the clear sky's change times one factor";
  EXPECT_LE(worst_range, 2e-6) << what << ": the factor is not a transmittance in [0, 1]";
  EXPECT_LE(worst_still, 2e-6) << what << ": the styling changed a texel under the deck more than its clear sky";
  std::printf("%s: fit residual %.3g, outside [0, 1] %.3g, small changes %.3g (of the texel's colour)\n", what.c_str(),
              worst_fit, worst_range, worst_still);
  return out;
}

// Mean over the texels of |a - b| / |b| (sums of the three channels).
double MeanRelativeDifference(const std::vector<float>& a, const std::vector<float>& b) {
  double sum = 0.0;
  int n = 0;
  for (size_t i = 0; i + 3 < a.size(); i += 4) {
    double num = 0.0, den = 0.0;
    for (int c = 0; c < 3; ++c) {
      num += std::abs(double(a[i + c]) - b[i + c]);
      den += std::abs(double(b[i + c]));
    }
    if (den <= 0.0) continue;
    sum += num / den;
    ++n;
  }
  return n > 0 ? sum / n : 0.0;
}

// The three-wavelength path and the spectral mode (8 bins) style the sky
// behind the deck, with the same transmittance at each texel; the styled
// spectral sky is as close to the styled three-wavelength one as the
// unstyled pair.
void ExpectStyledBehindTheClouds(const std::string& styled, const std::string& plain, const glm::dvec3& sun,
                                 const std::string& what) {
  std::map<int, LayeredSkies> skies;
  std::map<int, ChangeUnderDeck> change;
  for (int n : {3, 8}) {
    skies[n] = RenderLayeredSkies(styled, plain, n, sun);
    const std::string label = fmt::format("{}, {} wavelengths", what, n);
    ExpectFiniteAndNoNewNegatives(skies[n].on, skies[n].off, label.c_str());
    change[n] = TransmittanceOfTheChange(skies[n], label);
  }
  int compared = 0, hidden = 0, clear = 0;
  double worst = 0.0;
  const std::vector<double>&t3 = change[3].t, &t8 = change[8].t;
  for (size_t i = 0; i < t3.size(); ++i) {
    if (t3[i] < 0.0 || t8[i] < 0.0) continue;
    ++compared;
    if (t3[i] < 0.5) ++hidden;
    if (t3[i] > 0.99) ++clear;
    // In the texel's colour: the change the two factors make of the smaller R.
    worst = std::max(worst, std::abs(t8[i] - t3[i]) * std::min(change[3].weight[i], change[8].weight[i]));
  }
  // Both factors fit to 2e-6 of the colour (above; seen: 2.7e-7).
  EXPECT_LE(worst, 4e-6) << what << ": the spectral sky behind the deck is not attenuated as with three wavelengths";
  EXPECT_GT(compared, 1000) << what;
  EXPECT_GT(hidden, 50) << what << ": too few texels behind the deck for the test to mean anything";
  EXPECT_GT(clear, 50) << what << ": too few clear texels for the test to mean anything";
  const double styled_gap = MeanRelativeDifference(skies[8].on, skies[3].on);
  const double plain_gap = MeanRelativeDifference(skies[8].off, skies[3].off);
  // Seen: 0.083 against 0.084 (saturation clouds and shapes), 0.199 against 0.210 (night floor).
  EXPECT_LE(styled_gap, 1.05 * plain_gap)
      << what << ": styled 8 bins against 3 wavelengths, the unstyled pair " << plain_gap;
  std::printf(
      "%s: t compared at %d texels (%d behind the deck, %d clear), |t8 - t3| |R| <= %.3g; "
      "8 bins against 3 wavelengths, mean relative difference: styled %.4g, unstyled %.4g\n",
      what.c_str(), compared, hidden, clear, worst, styled_gap, plain_gap);
  testing::ExpectNoValidationMessages();
}

TEST(SpectralSkyTest, SaturationCloudsStyleTheSkyBehindCloudLayers) {
  ExpectStyledBehindTheClouds("[clouds]\nenabled = true\nstrength = 1.0\n", "",
                              SunDirectionFromElevationAzimuth(25.0, 150.0), "aoas.clouds");
}

TEST(SpectralSkyTest, CloudShapesStyleTheSkyBehindCloudLayers) {
  ExpectStyledBehindTheClouds(
      "[shapes]\nenabled = true\n[[shapes.shape]]\nkind = \"polyline\"\n"
      "points = [[15.0, 20.0], [45.0, 150.0], [20.0, 260.0], [30.0, 340.0]]\nradius_deg = 20.0\n",
      "", SunDirectionFromElevationAzimuth(25.0, 150.0), "aoas.shapes");
}

TEST(SpectralSkyTest, NightFloorLiesBehindCloudLayers) {
  const std::string night =
      "[effects]\nnight_dimming = true\nnight_dimming_strength = 0.8\nnight_sky_luminance_cd_m2 = 2e-3\n";
  const glm::dvec3 sun = SunDirectionFromElevationAzimuth(-12.0, 200.0);
  ExpectStyledBehindTheClouds(night, "", sun, "night floor");
  // The spectral renderer's directions (the SH's samples) too: every tenth texel of the latlong.
  const ViewRequest view{MAPPING_LATLONG, 96, 48, 0};
  std::vector<glm::dvec3> directions;
  for (int t = 0; t < view.width * view.height; t += 10)
    directions.push_back(ViewTexelDirection(view, t % view.width, t / view.width));
  const LayeredSkies along = RenderLayeredSkies(night, "", 8, sun, directions);
  ExpectFiniteAndNoNewNegatives(along.on, along.off, "night floor, directions");
  const std::vector<double> t = TransmittanceOfTheChange(along, "night floor, directions").t;
  EXPECT_GT(std::count_if(t.begin(), t.end(), [](double x) { return x >= 0.0 && x < 0.5; }), 50)
      << "too few directions behind the deck for the test to mean anything";
  testing::ExpectNoValidationMessages();
}

// A drift of the clouds (a sequence's frames) updates the spectral renderer
// in place and renders what a new renderer renders.
TEST(SpectralSkyTest, SpectralCloudDriftUpdatesInPlace) {
  AoasSettings aoas;
  aoas.clouds.enabled = true;
  QualitySettings quality;
  quality.wavelengths = 4;
  const Rgb scale = OutputScale(OutputUnits::kLuminance);
  const EffectSettings effects;
  SkyRenderer kept(testing::Vulkan(), AtmosphereParams(), quality, effects, scale, false, ToAoasInputs(aoas, scale));
  const glm::dvec3 sun = SunDirectionFromElevationAzimuth(30.0, 100.0);
  const std::vector<ViewRequest> views = {{MAPPING_LATLONG, 48, 24, 0}};
  const std::vector<float> before = kept.Render(sun, views)[0];
  aoas.clouds.drift = {0.7, 0.0, 0.3};
  ASSERT_TRUE(kept.UpdateAoas(ToAoasInputs(aoas, scale)));
  const std::vector<float> after = kept.Render(sun, views)[0];
  SkyRenderer fresh(testing::Vulkan(), AtmosphereParams(), quality, effects, scale, false, ToAoasInputs(aoas, scale));
  EXPECT_EQ(after, fresh.Render(sun, views)[0]);
  EXPECT_NE(after, before) << "the drift moved no cloud";
  // Another set of switches needs another renderer.
  AoasSettings plain;
  EXPECT_FALSE(kept.UpdateAoas(ToAoasInputs(plain, scale)));
  testing::ExpectNoValidationMessages();
}

// The style's spectral keys: refused before any GPU work, located, with the fix.
TEST(SpectralSkyTest, BadSpectralSettingsAreRefusedWithTheirPlace) {
  auto errors = [](const std::string& toml, const std::vector<std::string>& overrides = {}) {
    return ParseSkyStyle(toml, "style.toml", overrides);
  };
  ConfigResult low = errors("[quality]\nwavelengths = 2\n");
  ASSERT_EQ(low.errors.size(), 1u);
  EXPECT_EQ(low.errors[0].key, "quality.wavelengths");
  EXPECT_EQ(low.errors[0].line, 2);
  EXPECT_NE(low.errors[0].message.find("[3, 48]"), std::string::npos) << low.errors[0].message;
  EXPECT_EQ(errors("[quality]\nwavelengths = 49\n").errors.size(), 1u);
  EXPECT_EQ(errors("[quality]\nwavelengths = 8.5\n").errors.size(), 1u);
  // The principles that act on RGB colour are the style pass's: accepted, no warning.
  for (const char* principle : {"[effects]\nnight_dimming = true\n", "[clouds]\nenabled = true\n",
                                "[shapes]\nenabled = true\n[[shapes.shape]]\npoints = [[30.0, 90.0]]\n"}) {
    ConfigResult styled = errors(std::string("[quality]\nwavelengths = 8\n") + principle);
    EXPECT_TRUE(styled.ok()) << principle << (styled.errors.empty() ? "" : styled.errors[0].message);
    EXPECT_TRUE(styled.warnings.empty()) << principle << styled.warnings[0].message;
    EXPECT_EQ(styled.style.quality.wavelengths, 8) << principle;
  }
  // With cloud layers too: the style pass acts on the sky behind them (*BehindCloudLayers).
  ConfigResult layered =
      errors("[quality]\nwavelengths = 8\n[effects]\nnight_dimming = true\n[[cloud_layer]]\ntype = \"cumulus\"\n");
  EXPECT_TRUE(layered.ok()) << (layered.errors.empty() ? "" : layered.errors[0].message);
  EXPECT_TRUE(layered.warnings.empty()) << layered.warnings[0].message;
  EXPECT_EQ(layered.style.quality.wavelengths, 8);
  ConfigResult space = errors("[output]\nunits = \"spectral\"\ncolor_space = \"acescg\"\n");
  ASSERT_EQ(space.errors.size(), 1u);
  EXPECT_EQ(space.errors[0].key, "output.color_space");
  EXPECT_EQ(space.errors[0].line, 3);
  EXPECT_EQ(errors("[output]\ncolor_space = \"p3\"\n").errors.size(), 1u);
  // Radiance output keeps the named wavelengths: a warning, and the three-wavelength path.
  ConfigResult radiance = errors("[quality]\nwavelengths = 16\n[output]\nunits = \"spectral\"\n");
  EXPECT_TRUE(radiance.ok());
  ASSERT_EQ(radiance.warnings.size(), 1u);
  EXPECT_EQ(radiance.warnings[0].key, "quality.wavelengths");
  EXPECT_EQ(radiance.style.quality.wavelengths, 3);
  // A good one is read, and recorded.
  ConfigResult good = errors("", {"quality.wavelengths=16", "output.color_space=\"acescg\""});
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(good.style.quality.wavelengths, 16);
  EXPECT_EQ(good.style.output.color_space.name, "acescg");
  EXPECT_NE(good.style.resolved_toml.find("wavelengths = 16"), std::string::npos);
  // Off, neither key is recorded (the EXR headers keep their bytes).
  ConfigResult plain = errors("");
  EXPECT_EQ(plain.style.resolved_toml.find("wavelengths"), std::string::npos);
  EXPECT_EQ(plain.style.resolved_toml.find("color_space"), std::string::npos);
}

// Exit 3 from the command line, before any device work, with the location.
TEST(SpectralSkyTest, CommandLineRefusesOutOfRangeBins) {
  const testing::CommandRun run =
      testing::RunSkybake("check " + testing::SourceDir() + "/configs/default.toml --set quality.wavelengths=1");
  EXPECT_EQ(run.exit_code, 3) << run.output;
  EXPECT_NE(run.output.find("quality.wavelengths"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("out of range [3, 48]"), std::string::npos) << run.output;
  const std::string out = testing::FreshTempDir("spectral_bad");
  const testing::CommandRun bake =
      testing::RunSkybake("bake " + testing::SourceDir() + "/configs/default.toml -q --size 8 --out " + out +
                          " --set quality.wavelengths=2 --set effects.night_dimming=true");
  EXPECT_EQ(bake.exit_code, 3) << bake.output;
  EXPECT_TRUE(testing::FileNames(out).empty()) << "nothing written";
}

// The night floor and the AOAS saturation clouds bake in the spectral mode.
TEST(SpectralSkyTest, CommandLineBakesTheColourPrinciplesSpectrally) {
  const std::string out = testing::FreshTempDir("spectral_styled");
  const testing::CommandRun bake =
      testing::RunSkybake("bake " + testing::SourceDir() + "/configs/default.toml -q --size 8 --out " + out +
                          " --set quality.wavelengths=4 --set effects.night_dimming=true --set clouds.enabled=true");
  ASSERT_EQ(bake.exit_code, 0) << bake.output;
  EXPECT_FALSE(testing::FileNames(out).empty());
}

// An EXR's chromaticities and RGB as floats.
struct ExrPixels {
  Imf::Chromaticities chromaticities;
  std::string units;
  std::vector<float> rgb;
};
ExrPixels ReadExrPixels(const std::string& path) {
  Imf::InputFile file(path.c_str());
  ExrPixels p;
  p.chromaticities = Imf::chromaticities(file.header());
  p.units = file.header().typedAttribute<Imf::StringAttribute>("skybake:units").value();
  const Imath::Box2i dw = file.header().dataWindow();
  const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
  p.rgb.resize(size_t(w) * h * 3);
  Imf::FrameBuffer frame;
  for (int c = 0; c < 3; ++c)
    frame.insert(std::string(1, "RGB"[c]), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(p.rgb.data() + c),
                                                      3 * sizeof(float), size_t(w) * 3 * sizeof(float)));
  file.setFrameBuffer(frame);
  file.readPixels(dw.min.y, dw.max.y);
  return p;
}

// A spectral bake in ACEScg: the maps are the Rec.709 bake's values through
// Rec709ToAcesCg, and their chromaticities attribute names AP1 and the ACES white.
TEST(SpectralSkyTest, AcesCgMapsCarryTheirChromaticities) {
  std::map<std::string, ExrPixels> maps;
  for (const std::string space : {"rec709", "acescg"}) {
    const std::string out = testing::FreshTempDir("spectral_" + space);
    const testing::CommandRun run = testing::RunSkybake(
        "bake " + testing::SourceDir() + "/configs/default.toml -q --size 8 --set render.latlong_height=8 --out " +
        out + " --set quality.wavelengths=4 --set output.pixel_type=\"float\" --set output.color_space=" + space);
    ASSERT_EQ(run.exit_code, 0) << run.output;
    maps[space] = ReadExrPixels(out + "/sky_latlong.exr");
    for (const char* face : {"px", "nz"})
      EXPECT_EQ(ReadExrPixels(out + "/sky_" + std::string(face) + ".exr").chromaticities.red,
                maps[space].chromaticities.red);
  }
  const ExrPixels& rec = maps["rec709"];
  const ExrPixels& aces = maps["acescg"];
  EXPECT_FLOAT_EQ(rec.chromaticities.red.x, 0.64f);
  EXPECT_FLOAT_EQ(rec.chromaticities.white.x, 0.3127f);
  EXPECT_FLOAT_EQ(aces.chromaticities.red.x, 0.713f);
  EXPECT_FLOAT_EQ(aces.chromaticities.green.y, 0.830f);
  EXPECT_FLOAT_EQ(aces.chromaticities.blue.y, 0.044f);
  EXPECT_FLOAT_EQ(aces.chromaticities.white.x, 0.32168f);
  EXPECT_FLOAT_EQ(aces.chromaticities.white.y, 0.33767f);
  EXPECT_NE(aces.units.find("ACEScg"), std::string::npos) << aces.units;
  ASSERT_EQ(rec.rgb.size(), aces.rgb.size());
  const Matrix3 m = Rec709ToAcesCg();
  for (size_t t = 0; t < rec.rgb.size() / 3; ++t)
    for (int i = 0; i < 3; ++i) {
      const double want = m[i][0] * rec.rgb[3 * t] + m[i][1] * rec.rgb[3 * t + 1] + m[i][2] * rec.rgb[3 * t + 2];
      EXPECT_NEAR(aces.rgb[3 * t + i], want, 1e-6 * std::abs(want) + 1e-9) << "texel " << t << " channel " << i;
    }
}

// The study's smoke run (the full one: `skybake accuracy --only spectral`):
// its files, 48 bins against themselves exactly, and 3 wavelengths off them.
TEST(SpectralSkyTest, StudyQuickRunWritesItsTablesAndPictures) {
  AccuracyStudyOptions options;
  options.quick = true;
  options.out_dir = testing::FreshTempDir("spectral_study");
  const std::string md = RunSpectralStudy(testing::Vulkan(), options);
  for (const char* file :
       {"spectral.csv", "spectral_results.md", "spectral_twilight_rgb3.png", "spectral_twilight_48.png"})
    EXPECT_FALSE(testing::ReadFileBytes(options.out_dir + "/" + file).empty()) << file;
  const std::string csv = testing::ReadFileBytes(options.out_dir + "/spectral.csv");
  EXPECT_NE(csv.find("\n48,-4,"), std::string::npos) << csv;
  std::istringstream lines(csv);
  std::string line;
  std::getline(lines, line);  // header
  int rows = 0;
  while (std::getline(lines, line)) {
    std::vector<double> f;
    std::istringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ',')) f.push_back(std::stod(cell));
    ASSERT_EQ(f.size(), 10u) << line;
    if (f[0] == 48) {
      EXPECT_EQ(f[5], 0.0) << "48 bins against themselves: " << line;
      EXPECT_EQ(f[7], 0.0) << line;
    }
    if (f[0] == 3) {
      EXPECT_GT(f[7], 0.0) << "three wavelengths differ from 48 bins: " << line;
    }
    ++rows;
  }
  EXPECT_EQ(rows, 6);  // 3 counts (quick: 3, 4, 48) x 2 elevations
  EXPECT_NE(md.find("Twilight pictures"), std::string::npos);
  testing::ExpectNoValidationMessages();
}

// The Sun of a spectral bake (the manifest's irradiance, the SH's sun and
// the glTF light's colour) is the spectral sun: each bin's solar irradiance
// through the atmosphere, with the CIE weights, here from the converged
// double-precision transmittance of every group's atmosphere, not from the
// renderer. The three-wavelength bake's sun is another colour.
TEST(SpectralSkyTest, SunOfASpectralBakeIsTheSpectralSun) {
  using nlohmann::json;
  const double elevation_deg = 12.0;
  std::vector<std::string> sets = {"render.cube_size=8", "render.latlong_height=8",
                                   fmt::format("sun.elevation_deg={}", elevation_deg)};
  std::string args = "bake " + testing::SourceDir() + "/configs/default.toml -q";
  for (const std::string& s : sets) args += " --set " + s;
  sets.push_back("quality.wavelengths=16");
  std::map<int, json> manifests, gltfs;
  for (int n : {3, 16}) {
    const std::string out = testing::FreshTempDir(fmt::format("spectral_sun_{}", n));
    const testing::CommandRun run =
        testing::RunSkybake(args + fmt::format(" --set quality.wavelengths={} --out ", n) + out);
    ASSERT_EQ(run.exit_code, 0) << run.output;
    manifests[n] = json::parse(std::ifstream(out + "/manifest.json"));
    gltfs[n] = json::parse(std::ifstream(out + "/sky.gltf"));
  }
  // The expected sun: sum over the groups of to_rgb (T E), lux per Rec.709 channel.
  const ConfigResult style = LoadSkyStyle(testing::SourceDir() + "/configs/default.toml", sets);
  ASSERT_TRUE(style.ok());
  const AtmosphereParams atmosphere = StyledAtmosphere(style.style.atmosphere, style.style.aoas);
  const double mu = std::sin(elevation_deg * M_PI / 180.0);
  std::array<double, 3> expected{};
  for (const SpectralGroup& g : SpectralGroups(atmosphere, WavelengthBins(16))) {
    const glm::dvec3 t = ConvergedReference(g.atmosphere, 4.0).Transmittance(atmosphere.observer_altitude_m * 1e-3, mu);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) expected[i] += g.to_rgb[i][j] * t[j] * g.atmosphere.solar_irradiance[j];
  }
  const json& sun = manifests[16]["frames"][0]["sun"];
  const double peak = std::max({expected[0], expected[1], expected[2]});
  const json& light = gltfs[16]["extensions"]["KHR_lights_punctual"]["lights"][0];
  const json& sh_with = manifests[16]["frames"][0]["sh_irradiance_with_sun"][0];
  const json& sh_without = manifests[16]["frames"][0]["sh_irradiance_without_sun"][0];
  for (int c = 0; c < 3; ++c) {
    const double irradiance = sun["irradiance"][c].get<double>();
    EXPECT_NEAR(irradiance, expected[c], 0.01 * expected[c]) << "channel " << c;
    EXPECT_NEAR(light["color"][c].get<double>(), expected[c] / peak, 0.01) << "channel " << c;
    // The SH's sun (band 0) is the same colour.
    const double sh_sun = sh_with[c].get<double>() - sh_without[c].get<double>();
    EXPECT_NEAR(sh_sun / irradiance,
                (sh_with[1].get<double>() - sh_without[1].get<double>()) / sun["irradiance"][1].get<double>(),
                1e-4 * sh_sun / irradiance)
        << "channel " << c;
  }
  // Three wavelengths give the Sun the spectral mode's colour too: its light
  // is converted with the Sun's own spectrum through the frame's air,
  // integrated over 48 bins (colour_conversion.h); 16 bins integrate the
  // same spectrum a little differently.
  const json& sun3 = manifests[3]["frames"][0]["sun"]["irradiance"];
  const double ratio3 = sun3[2].get<double>() / sun3[0].get<double>();
  const double ratio16 = sun["irradiance"][2].get<double>() / sun["irradiance"][0].get<double>();
  std::printf("sun at %.0f deg, blue / red: 3 wavelengths %.4f, 16 bins %.4f, expected %.4f\n", elevation_deg, ratio3,
              ratio16, expected[2] / expected[0]);
  EXPECT_LT(std::abs(ratio3 / ratio16 - 1.0), 0.02);
}

// A sequence whose frames differ in their number of wavelengths gets a
// renderer for each (the renderer cache keys on it): every frame's files
// equal those of a bake of that frame alone.
TEST(SpectralSkyTest, SequenceChangingTheWavelengthsRendersEachFrameWithItsOwn) {
  ScheduleResult schedule =
      ParseSchedule(testing::IthacaSchedule("09:00:00", "09:30:00", 30), "spectral_sequence.toml");
  ASSERT_TRUE(schedule.ok()) << schedule.errors[0].Format();
  FrameStyles styles = ResolveFrameStyles(testing::SourceDir() + "/configs/default.toml",
                                          {"render.cube_size=16", "render.latlong_height=16"}, schedule.schedule);
  ASSERT_TRUE(styles.ok()) << styles.errors[0].Format();
  ASSERT_EQ(styles.styles.size(), 2u);
  styles.styles[1].quality.wavelengths = 6;
  BakeOptions options;
  options.out_dir = testing::FreshTempDir("spectral_sequence");
  options.vulkan.validation = true;
  options.force = true;
  const BakeResult whole = BakeSequence(styles.styles, schedule.schedule, options);
  EXPECT_EQ(whole.validation_messages, 0);
  ASSERT_EQ(whole.frames.size(), 2u);
  EXPECT_GE(whole.renderer_builds, 2);
  // The spectral frame (2) baked alone: the same files' checksums.
  BakeOptions alone = options;
  alone.out_dir += "-frame2";
  alone.frames = FrameRange{2, 2};
  const BakeResult spectral = BakeSequence(styles.styles, schedule.schedule, alone);
  ASSERT_EQ(spectral.frames.size(), 1u);
  std::vector<std::string> sums_whole, sums_alone;
  for (const BakedFile& f : whole.frames[1].files) sums_whole.push_back(f.sha256);
  for (const BakedFile& f : spectral.frames[0].files) sums_alone.push_back(f.sha256);
  EXPECT_EQ(sums_whole, sums_alone);
  std::filesystem::remove_all(alone.out_dir);
  std::filesystem::remove_all(options.out_dir);
}

// A spectral style's memory and time estimates count its groups of bins:
// 48 bins (16 groups) are budgeted above what the same style needs with 3
// wavelengths, and refused by a budget that the latter passes.
TEST(SpectralSkyTest, BudgetCountsTheWavelengthBins) {
  ConfigResult rgb = LoadSkyStyle(testing::SourceDir() + "/configs/default.toml");
  ConfigResult spectral = LoadSkyStyle(testing::SourceDir() + "/configs/default.toml", {"quality.wavelengths=48"});
  ASSERT_TRUE(rgb.ok() && spectral.ok());
  const ResourceEstimate e3 = EstimateResources(rgb.style), e48 = EstimateResources(spectral.style);
  // Every sky pass runs once per group; each group has an output buffer of its own.
  EXPECT_GT(e48.samples, 10.0 * e3.samples);
  EXPECT_GT(e48.memory_mib, 4.0 * e3.memory_mib);
  BakeOptions options;
  options.max_memory_mib = 0.5 * (e3.memory_mib + e48.memory_mib);
  options.max_frame_seconds = 1e9;
  EXPECT_NO_THROW(CheckBudget(rgb.style, options));
  try {
    CheckBudget(spectral.style, options);
    ADD_FAILURE() << "48 bins are within a budget they exceed";
  } catch (const BudgetError& e) {
    EXPECT_NE(std::string(e.what()).find("48 wavelengths in 16 groups of 3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("lower quality.wavelengths"), std::string::npos) << e.what();
  }
  options.max_memory_mib = 1e9;
  options.max_frame_seconds = 0.5 * (e3.seconds + e48.seconds);
  EXPECT_NO_THROW(CheckBudget(rgb.style, options));
  EXPECT_THROW(CheckBudget(spectral.style, options), BudgetError);
}

// Kider 2014 with Bruneton's protocol (`skybake accuracy --only
// kider-spectral`) in its quick form: the single-scattering 16/8 model over
// every capture at the 31 wavelengths, whose RMSE docs/accuracy.md gives as
// 37.4 mW/(m2 sr nm).
TEST(SpectralSkyTest, KiderSpectralQuickScoreIsTheDocumentedOne) {
  AccuracyStudyOptions options;
  options.quick = true;
  options.shared_dir = testing::SharedDir();
  options.out_dir = testing::FreshTempDir("kider_spectral");
  const std::vector<KiderSpectralScore> scores = ScoreKiderSpectral(testing::Vulkan(), options);
  testing::ExpectNoValidationMessages();
  ASSERT_EQ(scores.size(), 1u);
  EXPECT_EQ(scores[0].model, "single scattering, midpoint 16/8");
  EXPECT_EQ(scores[0].captures, 15);
  ASSERT_TRUE(std::isfinite(scores[0].rmse_mw));
  EXPECT_NEAR(scores[0].rmse_mw, 37.4, 0.5);
  const std::string csv = testing::ReadFileBytes(options.out_dir + "/kider2014_spectral.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 16) << csv;  // header + 15 captures
}

}  // namespace
}  // namespace skybake
