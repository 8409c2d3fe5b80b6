// Volumetric cloud layers (clouds.h): the style's keys and their checks, the
// noise volumes (deterministic, tiling, spread over [0, 1]), and the cloud
// pass on lavapipe under the validation layer.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <glm/glm.hpp>

#include "skybake/clouds.h"
#include "skybake/config.h"
#include "skybake/envmap.h"
#include "skybake/pass_plan.h"
#include "skybake/sky_renderer.h"
#include "test_support.h"

namespace skybake {
namespace {

SkyStyle Style(const std::string& toml, const std::vector<std::string>& overrides = {}) {
  ConfigResult r = ParseSkyStyle(toml, "clouds_test.toml", overrides);
  EXPECT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].Format());
  return r.style;
}

std::vector<std::string> Errors(const std::string& toml) {
  ConfigResult r = ParseSkyStyle(toml, "clouds_test.toml");
  std::vector<std::string> out;
  for (const ConfigError& e : r.errors) out.push_back(e.Format());
  return out;
}

const char* kCumulus = R"(
[[cloud_layer]]
altitude_m = 1500
thickness_m = 1500
type = "cumulus"
coverage = 0.5
)";

// A renderer for a style as the bake builds it (pruned, styled).
struct StyleRenderer {
  explicit StyleRenderer(const SkyStyle& unpruned, double time_s = 0.0) {
    const SkyStyle style = PrunedStyle(unpruned);
    renderer = std::make_unique<SkyRenderer>(
        testing::Vulkan(), StyledAtmosphere(style.atmosphere, style.aoas), style.quality, style.effects,
        OutputScale(style.output.units), false, ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)),
        ToCloudInputs(style.clouds, style.aoas.seed, "", time_s));
  }
  std::unique_ptr<SkyRenderer> renderer;
};

[[maybe_unused]] glm::dvec3 Sun(double elevation_deg, double azimuth_deg = 135.0) {
  return SunDirectionFromElevationAzimuth(elevation_deg, azimuth_deg);
}

// ---------------------------------------------------------------- the style

TEST(CloudStyle, NoLayersByDefault) {
  SkyStyle s = Style("");
  EXPECT_TRUE(s.clouds.layers.empty());
  EXPECT_EQ(ToCloudInputs(s.clouds, s.aoas.seed, "", 0.0).layers(), 0);
}

TEST(CloudStyle, LayerKeysAreRead) {
  SkyStyle s = Style(R"(
[aoas]
seed = 9
[[cloud_layer]]
altitude_m = 800
thickness_m = 400
type = "custom"
profile = [0.0, 0.2, 0.4, 0.9]
coverage = 0.7
density_per_m = 0.02
albedo = 0.95
shape_amount = 0.5
shape_size_m = 3000
detail_amount = 0.2
detail_size_m = 300
wind_m_s = [10.0, -5.0]
shear_m_s_per_km = [2.0, 0.0]
weather_size_m = 20000
)");
  ASSERT_EQ(s.clouds.layers.size(), 1u);
  const CloudLayer& l = s.clouds.layers[0];
  EXPECT_EQ(l.type, CloudType::kCustom);
  EXPECT_EQ(l.profile[3], 0.9);
  EXPECT_EQ(l.wind_m_s[1], -5.0);
  EXPECT_FALSE(l.seed.has_value());
  // The seed falls back to aoas.seed; wind x time moves the layer (east = +x, north = -z).
  CloudInputs in = ToCloudInputs(s.clouds, s.aoas.seed, "", 100.0);
  EXPECT_EQ(in.uniform.layers[0].noise.w, 9);
  EXPECT_FLOAT_EQ(in.uniform.layers[0].wind_offset.x, 1.0f);   // 10 m/s x 100 s = 1 km
  EXPECT_FLOAT_EQ(in.uniform.layers[0].wind_offset.y, 0.5f);   // 5 m/s south
  EXPECT_FLOAT_EQ(in.uniform.layers[0].wind_offset.z, 0.2f);   // 2 m/s per km x 100 s
  EXPECT_FLOAT_EQ(in.uniform.layers[0].shell.z, 20.0f);        // 0.02 /m = 20 /km
  // The resolved style records the layer, so a bake says what it used.
  EXPECT_NE(s.resolved_toml.find("[[cloud_layer]]"), std::string::npos) << s.resolved_toml;
  SkyStyle again = Style(s.resolved_toml);
  EXPECT_EQ(again.resolved_toml, s.resolved_toml);
}

TEST(CloudStyle, PresetsSetTheCloudSampling) {
  EXPECT_EQ(Style("[quality]\npreset = \"draft\"\n").clouds.quality.view_steps, CloudQualityPreset("draft").view_steps);
  EXPECT_EQ(Style("[quality]\npreset = \"reference\"\n").clouds.quality.light_steps,
            CloudQualityPreset("reference").light_steps);
  EXPECT_LT(CloudQualityPreset("draft").view_steps, CloudQualityPreset("production").view_steps);
  EXPECT_LT(CloudQualityPreset("production").view_steps, CloudQualityPreset("reference").view_steps);
  EXPECT_EQ(Style("[quality]\npreset = \"draft\"\ncloud_view_steps = 7\n").clouds.quality.view_steps, 7);
}

TEST(CloudStyle, BadLayersAreLocated) {
  auto has = [](const std::vector<std::string>& errors, const std::string& text) {
    for (const std::string& e : errors)
      if (e.find(text) != std::string::npos) return true;
    return false;
  };
  std::vector<std::string> e = Errors("[[cloud_layer]]\ncoverage = 1.5\n");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0], "clouds_test.toml:2:12: cloud_layer[0].coverage: expected a number in [0, 1]");
  e = Errors("[[cloud_layer]]\naltitude_m = 99000\nthickness_m = 2000\n");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_TRUE(has(e, "clouds_test.toml:3:15: cloud_layer[0].thickness_m: the layer's top at 101000 m is above"))
      << e[0];
  EXPECT_TRUE(has(Errors("[[cloud_layer]]\naltitude_m = -10\n"), "cloud_layer[0].altitude_m: expected a number in [0"));
  EXPECT_TRUE(has(Errors("[[cloud_layer]]\nthickness_m = 0\n"), "cloud_layer[0].thickness_m"));
  EXPECT_TRUE(has(Errors("[[cloud_layer]]\ntype = \"nimbus\"\n"), "expected 'stratus'"));
  EXPECT_TRUE(has(Errors("[[cloud_layer]]\nprofile = [0, 0.1, 0.2, 0.3]\n"), "needs type = \"custom\""));
  EXPECT_TRUE(has(Errors("[[cloud_layer]]\ntype = \"custom\"\nprofile = [0.5, 0.1, 0.2, 0.3]\n"),
                  "cloud_layer[0].profile: [0.5, 0.1, 0.2, 0.3]: expected"));
  EXPECT_TRUE(has(Errors("[[cloud_layer]]\ncolour = 3\n"), "cloud_layer[0].colour: unknown key 'colour'"));
  EXPECT_TRUE(has(Errors("[[cloud_layer]]\nwind_m_s = [1.0]\n"), "cloud_layer[0].wind_m_s: expected [east, north]"));
  std::string five;
  for (int i = 0; i < 5; ++i) five += fmt::format("[[cloud_layer]]\naltitude_m = {}\n", 1000 * i);
  e = Errors(five);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_TRUE(has(e, "cloud_layer[4]: 5 cloud layers; at most 4 fit")) << e[0];
  e = Errors("[[cloud_layer]]\nweather_image = \"no_such_weather.png\"\n");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_TRUE(has(e, "clouds_test.toml:2:17: cloud_layer[0].weather_image: no_such_weather.png: no such file")) << e[0];
}

// ---------------------------------------------------------------- noise

TEST(CloudNoise, DeterministicSpreadAndSeeded) {
  SkyStyle style = Style(std::string("[quality]\npreset = \"draft\"\n") + kCumulus);
  StyleRenderer a(style);
  a.renderer->PrecomputeLuts();
  const std::vector<float> noise = a.renderer->ReadCloudNoise();
  const gpu::GpuClouds g = ToCloudInputs(PrunedStyle(style).clouds, 1, "", 0.0).uniform;
  ASSERT_EQ(noise.size(), CloudNoiseFloats(g));
  auto stats = [&](int first, size_t count, const char* name) {
    double mean = 0.0, mean2 = 0.0, lo = 1e9, hi = -1e9;
    for (size_t i = 0; i < count; ++i) {
      const double v = noise[first + i];
      ASSERT_TRUE(std::isfinite(v) && v >= 0.0 && v <= 1.0) << name << " " << i << " " << v;
      mean += v;
      mean2 += v * v;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    mean /= count;
    const double sd = std::sqrt(std::max(mean2 / count - mean * mean, 0.0));
    std::printf("%s: mean %.3f sd %.3f min %.3f max %.3f\n", name, mean, sd, lo, hi);
    EXPECT_GT(sd, 0.08) << name;
    EXPECT_GT(hi - lo, 0.5) << name;
  };
  const int ns = g.resolution.x, nd = g.resolution.y, nw = g.resolution.z;
  stats(g.layers[0].noise.x, size_t(ns) * ns * ns, "shape");
  stats(g.layers[0].noise.y, size_t(nd) * nd * nd, "detail");
  stats(g.layers[0].noise.z, size_t(nw) * nw, "weather");
  // The same seed gives the same bytes; another seed other noise.
  StyleRenderer b(style);
  b.renderer->PrecomputeLuts();
  EXPECT_EQ(std::memcmp(noise.data(), b.renderer->ReadCloudNoise().data(), noise.size() * 4), 0);
  style.aoas.seed = 2;
  StyleRenderer c(style);
  c.renderer->PrecomputeLuts();
  EXPECT_NE(std::memcmp(noise.data(), c.renderer->ReadCloudNoise().data(), noise.size() * 4), 0);
  testing::ExpectNoValidationMessages();
}

}  // namespace
}  // namespace skybake
