// Cirrus (type = "cirrus"; shaders/cloud_cirrus.glsl, cloud_ice_phase.glsl,
// docs/clouds.md "Cirrus"):
// - the streaks: on a cloud shadow map with the Sun overhead (the layer's
//   vertical transmittance, lavapipe under the validation layer), the
//   autocorrelation length along the wind is at least 3 times that across
//   it, whichever way the wind blows; a stratocumulus layer of the same
//   noise is within 1.5 times either way (the measure sees isotropy too);
// - the ice phase integrates to 1 over the sphere and its asymmetry
//   parameter is the cited 0.75 (Baum et al. 2011), and the render uses it:
//   the same cloud lit through it is brighter near the Sun and darker 90 deg
//   from it than through the water phase;
// - configs/styles/cirrus_uncinus.toml is thin: its vertical optical depth
//   stays within the thin-to-opaque cirrus range 0.03-3 (Sassen and Cho 1992)
//   and its transmittance is never below exp(-3);
// - the switch: only a cirrus layer sets GpuCloudLayer.streaks, so a style
//   without cirrus compiles the cirrus code out (SPEC_CLOUD_CIRRUS; its bytes
//   are the golden tests').
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "skybake/gpu/sky_renderer.h"
#include "skybake/input/config.h"
#include "skybake/model/cloud_shadow.h"
#include "skybake/model/clouds.h"
#include "skybake/model/atmosphere.h"
#include "skybake/model/view.h"
#include "skybake/model/shared_glsl.h"
#include "skybake/model/tonemap.h"
#include "skybake/pipeline/pass_plan.h"
#include "test_support.h"

namespace skybake {
namespace {

// A thin high layer at draft quality: `type` and its wind as given.
SkyStyle HighLayer(const std::string& type, const std::string& wind, const std::string& shear) {
  const std::string toml = R"(
[quality]
preset = "draft"
[aoas]
seed = 31
[[cloud_layer]]
altitude_m = 8500.0
thickness_m = 500.0
coverage = 0.5
density_per_m = 0.002
shape_size_m = 5000.0
detail_amount = 0.8
detail_size_m = 900.0
type = ")" + type +
                           "\"\nwind_m_s = " + wind + "\nshear_m_s_per_km = " + shear + "\n";
  ConfigResult r = ParseSkyStyle(toml, "cloud_cirrus_test.toml");
  EXPECT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].Format());
  return PrunedStyle(r.style);
}

// The layer's transmittance straight down (the Sun overhead), n x n texels
// over extent_km; row 0 north, column 0 west (cloud_shadow.h).
std::vector<float> VerticalTransmittance(const SkyStyle& style, int n, double extent_km) {
  SkyRenderer r(testing::Vulkan(), StyledAtmosphere(style.atmosphere, style.aoas), style.quality, style.effects,
                OutputScale(style.output.units), false, ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)),
                ToCloudInputs(style.clouds, style.aoas.seed, "", 0.0));
  const CloudShadowSettings s{.enabled = true, .resolution = n, .extent_m = extent_km * 1e3, .steps = 8};
  return r.RenderCloudShadow(glm::dvec3(0.0, 1.0, 0.0), s);
}

// The autocorrelation length of the map along columns (dx = 1, east) or rows
// (dy = 1, south): the first shift at which the autocorrelation (of the map
// less its mean, the mean of f(p) f(p + s) over the texels both hold, over
// the variance) falls below 1/e, in km (linear between shifts).
double CorrelationLength(const std::vector<float>& map, int n, double texel_km, int dx, int dy) {
  double mean = 0.0;
  for (float v : map) mean += v;
  mean /= double(map.size());
  auto at = [&](int x, int y) { return double(map[size_t(y) * n + x]) - mean; };
  double variance = 0.0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) variance += at(x, y) * at(x, y);
  variance /= double(n) * n;
  double previous = 1.0;
  for (int s = 1; s < n / 2; ++s) {
    double sum = 0.0;
    const int w = n - s * dx, h = n - s * dy;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) sum += at(x, y) * at(x + s * dx, y + s * dy);
    const double r = sum / (double(w) * h) / variance;
    if (r < std::exp(-1.0)) return texel_km * (s - 1 + (previous - std::exp(-1.0)) / (previous - r));
    previous = r;
  }
  return texel_km * n / 2;
}

struct Lengths {
  double east_km, south_km;
};

Lengths MeasureLengths(const SkyStyle& style, const char* name) {
  constexpr int kN = 256;
  constexpr double kExtentKm = 80.0, kTexelKm = kExtentKm / kN;
  const std::vector<float> map = VerticalTransmittance(style, kN, kExtentKm);
  const auto [lo, hi] = std::minmax_element(map.begin(), map.end());
  EXPECT_LT(*lo, 0.9f) << name << ": some cloud";  // the measure is not of a clear sky
  EXPECT_GT(*hi, 0.99f) << name << ": some clear sky";
  const Lengths l{CorrelationLength(map, kN, kTexelKm, 1, 0), CorrelationLength(map, kN, kTexelKm, 0, 1)};
  std::printf("%s: autocorrelation length east-west %.2f km, north-south %.2f km (transmittance %.3f..%.3f)\n", name,
              l.east_km, l.south_km, *lo, *hi);
  return l;
}

TEST(Cirrus, StreaksAreLongerAlongTheWindThanAcross) {
  const Lengths east = MeasureLengths(HighLayer("cirrus", "[30.0, 0.0]", "[10.0, 0.0]"), "cirrus, wind east");
  EXPECT_GE(east.east_km, 3.0 * east.south_km);
  const Lengths north = MeasureLengths(HighLayer("cirrus", "[0.0, 30.0]", "[0.0, 10.0]"), "cirrus, wind north");
  EXPECT_GE(north.south_km, 3.0 * north.east_km);
  // The same layer as stratocumulus: no streaks, about as long either way.
  const Lengths plain = MeasureLengths(HighLayer("stratocumulus", "[30.0, 0.0]", "[10.0, 0.0]"), "stratocumulus");
  EXPECT_LT(plain.east_km, 1.5 * plain.south_km);
  EXPECT_LT(plain.south_km, 1.5 * plain.east_km);
}

TEST(Cirrus, IcePhaseIsNormalisedWithTheCitedAsymmetry) {
  // The integral over the sphere, 2 pi times that over cos_theta in [-1, 1]
  // (midpoint rule, 2e5 intervals: the forward lobe's peak, 82 times its
  // mean, is resolved), and the mean cosine g.
  for (double eccentricity : {1.0, 0.5, 0.25}) {
    constexpr int kSteps = 200000;
    double integral = 0.0, g = 0.0;
    for (int i = 0; i < kSteps; ++i) {
      const double mu = -1.0 + (i + 0.5) * 2.0 / kSteps;
      const double p = glsl::IceCrystalPhase(mu, eccentricity) * 2.0 * M_PI * 2.0 / kSteps;
      integral += p;
      g += mu * p;
    }
    std::printf("ice phase, eccentricity %.2f: integral %.6f, g %.4f\n", eccentricity, integral, g);
    EXPECT_NEAR(integral, 1.0, 1e-3) << eccentricity;
    EXPECT_NEAR(g, 0.75 * eccentricity, 1e-3) << eccentricity;
  }
  // Forward of sideways, as ice: the forward peak far above 90 deg.
  EXPECT_GT(glsl::IceCrystalPhase(1.0, 1.0), 100.0 * glsl::IceCrystalPhase(0.0, 1.0));
}

// The render uses the ice phase: a cirrus layer with streak_ratio 1 and no
// shear reads its noise where a custom layer of the cirrus profile does (the
// squeeze by 1 along east is exact in float), so the two differ by the
// phase alone. Near the Sun the ice phase's forward lobe (g = 0.75) is
// brighter than the water phase's (g = 0.25); 90 deg from it, darker (at
// single scattering, 0.0145 against 0.0471 sr^-1).
std::vector<float> LatlongOf(const std::string& layer_keys, std::vector<glm::dvec3>& directions, glm::dvec3& sun) {
  const std::string toml = R"(
[quality]
preset = "draft"
[sun]
elevation_deg = 40.0
azimuth_deg = 180.0
[aoas]
seed = 31
[[cloud_layer]]
altitude_m = 8500.0
thickness_m = 500.0
coverage = 0.7
density_per_m = 0.004
shape_size_m = 5000.0
wind_m_s = [30.0, 0.0]
)" + layer_keys;
  ConfigResult r = ParseSkyStyle(toml, "cloud_cirrus_test.toml");
  EXPECT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].Format());
  const SkyStyle style = PrunedStyle(r.style);
  SkyRenderer renderer(testing::Vulkan(), StyledAtmosphere(style.atmosphere, style.aoas), style.quality, style.effects,
                       OutputScale(style.output.units), false,
                       ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)),
                       ToCloudInputs(style.clouds, style.aoas.seed, "", 0.0));
  sun = SunDirectionFromElevationAzimuth(style.sun.elevation_deg, style.sun.azimuth_deg);
  const ViewRequest view{MAPPING_LATLONG, 256, 128, 0};
  directions = ViewDirections(view);
  std::vector<float> image = renderer.Render(sun, {view}, false)[0];
  testing::ExpectNoValidationMessages();
  return image;
}

TEST(Cirrus, TheRenderLightsCirrusThroughTheIcePhase) {
  std::vector<glm::dvec3> directions;
  glm::dvec3 sun;
  const std::vector<float> ice = LatlongOf("type = \"cirrus\"\nstreak_ratio = 1.0\n", directions, sun);
  const std::vector<float> water = LatlongOf("type = \"custom\"\nprofile = [0.0, 0.35, 0.65, 1.0]\n", directions, sun);
  double near_ice = 0.0, near_water = 0.0, side_ice = 0.0, side_water = 0.0;
  for (size_t i = 0; i < directions.size(); ++i) {
    if (directions[i].y < 0.1) continue;  // the sky above the horizon haze
    const double angle_deg = std::acos(std::clamp(glm::dot(directions[i], sun), -1.0, 1.0)) * 180.0 / M_PI;
    const double a = ice[4 * i + 1], b = water[4 * i + 1];  // green
    if (angle_deg < 15.0) near_ice += a, near_water += b;
    if (angle_deg > 80.0 && angle_deg < 100.0) side_ice += a, side_water += b;
  }
  std::printf("ice over water phase, same cloud: within 15 deg of the Sun %.3f, 80-100 deg from it %.3f\n",
              near_ice / near_water, side_ice / side_water);
  EXPECT_GT(near_ice, 1.2 * near_water);
  EXPECT_LT(side_ice, side_water);
}

TEST(Cirrus, TheCirrusStyleIsThin) {
  ConfigResult r = LoadSkyStyle(testing::SourceDir() + "/configs/styles/cirrus_uncinus.toml");
  ASSERT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].Format());
  const SkyStyle style = PrunedStyle(r.style);
  constexpr int kN = 256;
  const std::vector<float> map = VerticalTransmittance(style, kN, 80.0);
  // Sassen and Cho 1992 (J. Appl. Meteor. 31, 1275-1285): subvisual cirrus
  // below an optical depth of 0.03, thin 0.03-0.3, opaque 0.3-3.
  int cloudy = 0;
  double tau_max = 0.0, tau_sum = 0.0;
  for (float t : map) {
    const double tau = -std::log(std::max(double(t), 1e-30));
    tau_max = std::max(tau_max, tau);
    if (tau > 0.03) ++cloudy, tau_sum += tau;
  }
  const double cloudy_fraction = double(cloudy) / map.size();
  std::printf(
      "cirrus_uncinus: vertical optical depth max %.3f, mean where > 0.03: %.3f, over %.1f%% of 80 km x 80 km\n",
      tau_max, cloudy ? tau_sum / cloudy : 0.0, 100.0 * cloudy_fraction);
  EXPECT_LE(tau_max, 3.0);
  EXPECT_GT(tau_max, 0.3);  // the thickest fibres reach the opaque end
  EXPECT_GT(cloudy_fraction, 0.1);
  EXPECT_LT(cloudy_fraction, 0.9);  // blue sky between the streaks
}

TEST(Cirrus, OnlyCirrusLayersSetTheSwitch) {
  const SkyStyle cirrus = HighLayer("cirrus", "[0.0, 30.0]", "[0.0, 10.0]");
  const gpu::GpuClouds g = ToCloudInputs(cirrus.clouds, 31, "", 0.0).uniform;
  EXPECT_TRUE(CloudCirrusOn(g));
  // North (world -Z), ratio 8, hook = 10 / (2 x 1 m/s) per km.
  EXPECT_NEAR(g.layers[0].streaks.x, 0.0, 1e-6);
  EXPECT_NEAR(g.layers[0].streaks.y, -1.0, 1e-6);
  EXPECT_EQ(g.layers[0].streaks.z, float(kCirrusDefaultStreakRatio));
  EXPECT_NEAR(g.layers[0].streaks.w, 10.0 / (2.0 * kCirrusFallSpeedM_s), 1e-5);
  for (const char* type : {"stratus", "stratocumulus", "cumulus", "cumulonimbus"}) {
    const SkyStyle other = HighLayer(type, "[0.0, 30.0]", "[0.0, 10.0]");
    const gpu::GpuClouds o = ToCloudInputs(other.clouds, 31, "", 0.0).uniform;
    EXPECT_FALSE(CloudCirrusOn(o)) << type;
    EXPECT_EQ(o.layers[0].streaks.z, 0.0f) << type;
  }
}

TEST(Cirrus, StreakRatioIsReadAndChecked) {
  const std::string base = "[[cloud_layer]]\ntype = \"cirrus\"\naltitude_m = 9000.0\n";
  ConfigResult ok = ParseSkyStyle(base + "streak_ratio = 12.0\n", "a.toml");
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok.style.clouds.layers[0].streak_ratio, 12.0);
  ConfigResult low = ParseSkyStyle(base + "streak_ratio = 0.5\n", "a.toml");
  ASSERT_FALSE(low.ok());
  EXPECT_NE(low.errors[0].Format().find("streak_ratio"), std::string::npos) << low.errors[0].Format();
  // The resolved style (the manifest's) keeps it, and reads back the same.
  EXPECT_NE(ok.style.resolved_toml.find("streak_ratio = 12"), std::string::npos) << ok.style.resolved_toml;
  ConfigResult again = ParseSkyStyle(ok.style.resolved_toml, "resolved.toml");
  ASSERT_TRUE(again.ok()) << again.errors[0].Format();
  EXPECT_EQ(again.style.clouds.layers[0].streak_ratio, 12.0);
  EXPECT_EQ(again.style.resolved_toml, ok.style.resolved_toml);
  ConfigResult wrong_type = ParseSkyStyle("[[cloud_layer]]\ntype = \"cumulus\"\nstreak_ratio = 4.0\n", "a.toml");
  ASSERT_FALSE(wrong_type.ok());
  EXPECT_NE(wrong_type.errors[0].Format().find("needs type = \"cirrus\""), std::string::npos)
      << wrong_type.errors[0].Format();
}

}  // namespace
}  // namespace skybake
