// Volumetric cloud layers (clouds.h): the style's keys and their checks, the
// noise volumes (deterministic, tiling, spread over [0, 1]), and the cloud
// pass on lavapipe under the validation layer.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <OpenImageIO/imageio.h>
#include <glm/glm.hpp>

#include "skybake/model/clouds.h"
#include "skybake/model/cloud_shadow.h"
#include "skybake/input/config.h"
#include "skybake/model/envmap.h"
#include "skybake/pipeline/pass_plan.h"
#include "skybake/pipeline/pipeline.h"
#include "skybake/tools/reference_model.h"
#include "skybake/gpu/sky_renderer.h"
#include "schedule_fixtures.h"
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
    renderer = std::make_unique<SkyRenderer>(testing::Vulkan(), StyledAtmosphere(style.atmosphere, style.aoas),
                                             style.quality, style.effects, OutputScale(style.output.units), false,
                                             ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)),
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
tiling = true
)");
  ASSERT_EQ(s.clouds.layers.size(), 1u);
  const CloudLayer& l = s.clouds.layers[0];
  EXPECT_EQ(l.type, CloudType::kCustom);
  EXPECT_TRUE(l.tiling);
  EXPECT_EQ(l.profile[3], 0.9);
  EXPECT_EQ(l.wind_m_s[1], -5.0);
  EXPECT_FALSE(l.seed.has_value());
  // The seed falls back to aoas.seed; wind x time moves the layer (east = +x, north = -z).
  CloudInputs in = ToCloudInputs(s.clouds, s.aoas.seed, "", 100.0);
  EXPECT_EQ(in.uniform.layers[0].noise.w, 9);
  EXPECT_FLOAT_EQ(in.uniform.layers[0].wind_offset.x, 1.0f);  // 10 m/s x 100 s = 1 km
  EXPECT_FLOAT_EQ(in.uniform.layers[0].wind_offset.y, 0.5f);  // 5 m/s south
  EXPECT_FLOAT_EQ(in.uniform.layers[0].wind_offset.z, 0.2f);  // 2 m/s per km x 100 s
  EXPECT_FLOAT_EQ(in.uniform.layers[0].shell.z, 20.0f);       // 0.02 /m = 20 /km
  // A tiling layer reads its tiles as they are (no warp: weather_origin.zw
  // 0); by default the warp of the 20 km weather tile and three weather reads.
  EXPECT_EQ(in.uniform.layers[0].weather_origin.z, 0.0f);
  EXPECT_EQ(in.uniform.layers[0].weather_origin.w, 0.0f);
  CloudSettings free_clouds = s.clouds;
  free_clouds.layers[0].tiling = false;
  const CloudInputs free_in = ToCloudInputs(free_clouds, s.aoas.seed, "", 100.0);
  EXPECT_FLOAT_EQ(free_in.uniform.layers[0].weather_origin.z, 20.0f);
  EXPECT_EQ(free_in.uniform.layers[0].weather_origin.w, 1.0f);
  // The resolved style records the layer, so a bake says what it used.
  EXPECT_NE(s.resolved_toml.find("[[cloud_layer]]"), std::string::npos) << s.resolved_toml;
  SkyStyle again = Style(s.resolved_toml);
  EXPECT_EQ(again.resolved_toml, s.resolved_toml);
  // A named type's resolved style round-trips too (its profile is the type's).
  SkyStyle named = Style(kCumulus);
  SkyStyle named_again = Style(named.resolved_toml);
  EXPECT_EQ(named_again.resolved_toml, named.resolved_toml);
  EXPECT_EQ(named_again.clouds.layers[0].profile, CloudTypeProfile(CloudType::kCumulus));
}

TEST(CloudStyle, PresetsSetTheCloudSampling) {
  EXPECT_EQ(Style("[quality]\npreset = \"draft\"\n").clouds.quality.view_steps, CloudQualityPreset("draft").view_steps);
  EXPECT_EQ(Style("[quality]\npreset = \"reference\"\n").clouds.quality.light_steps,
            CloudQualityPreset("reference").light_steps);
  EXPECT_LT(CloudQualityPreset("draft").view_steps, CloudQualityPreset("production").view_steps);
  EXPECT_LT(CloudQualityPreset("production").view_steps, CloudQualityPreset("reference").view_steps);
  EXPECT_EQ(Style("[quality]\npreset = \"draft\"\ncloud_view_steps = 7\n").clouds.quality.view_steps, 7);
  EXPECT_EQ(Style("[quality]\ncloud_light_trilinear_steps = 5\n").clouds.quality.light_trilinear_steps, 5);
  EXPECT_GE(CloudQualityPreset("reference").light_trilinear_steps, CloudQualityPreset("reference").light_steps)
      << "the reference preset keeps every light sample trilinear";
  EXPECT_EQ(CloudQualityPreset("reference").light_volume_columns, 0) << "the reference marches every light sample";
  EXPECT_GT(CloudQualityPreset("production").light_volume_columns, 0);
  EXPECT_EQ(Style("[quality]\ncloud_light_volume_columns = 64\n").clouds.quality.light_volume_columns, 64);
  for (const char* bad :
       {"cloud_light_volume_columns = 2000", "cloud_light_volume_slices = 1", "cloud_light_volume_near_steps = -1"}) {
    std::vector<std::string> errors = Errors(std::string("[quality]\n") + bad + "\n");
    ASSERT_EQ(errors.size(), 1u) << bad;
    EXPECT_NE(errors[0].find("clouds_test.toml:2:"), std::string::npos) << errors[0];
    EXPECT_NE(errors[0].find("quality.cloud_light_volume_"), std::string::npos) << errors[0];
  }
  // Too large for its buffer (at most 64 MiB), with a layer to use it.
  std::vector<std::string> big = Errors(std::string(kCumulus) + "[quality]\ncloud_light_volume_columns = 1024\n");
  ASSERT_EQ(big.size(), 1u);
  EXPECT_NE(big[0].find("clouds_test.toml:8:30: quality.cloud_light_volume_columns: 1024 x 1024 columns x 32 slices"),
            std::string::npos)
      << big[0];
  std::vector<std::string> e = Errors("[quality]\ncloud_light_trilinear_steps = 300\n");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("clouds_test.toml:2:31: quality.cloud_light_trilinear_steps"), std::string::npos) << e[0];
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
  EXPECT_TRUE(has(Errors("[[cloud_layer]]\ntiling = 1\n"),
                  "clouds_test.toml:2:10: cloud_layer[0].tiling: expected true or false"));
  std::string five;
  for (int i = 0; i < 5; ++i) five += fmt::format("[[cloud_layer]]\naltitude_m = {}\n", 1000 * i);
  e = Errors(five);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_TRUE(has(e, "cloud_layer[4]: 5 cloud layers; at most 4 fit")) << e[0];
  e = Errors("[quality]\ncloud_view_steps = 768\ncloud_light_steps = 128\n[[cloud_layer]]\n");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_TRUE(has(e,
                  "clouds_test.toml:3:21: quality.cloud_light_steps: 1 cloud layer(s) x 768 view steps x 128 "
                  "light steps may run"))
      << e[0];
  EXPECT_TRUE(Errors("[quality]\ncloud_view_steps = 768\ncloud_light_steps = 128\n").empty())
      << "without layers the cloud settings run nothing";
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

// ---------------------------------------------------------------- the cloud pass

const char* kFast = R"(
[quality]
preset = "draft"
)";

// Every view of a small bake plus the SH faces and the sun direction, from
// one renderer.
std::vector<std::vector<float>> RenderAll(const SkyStyle& style, const glm::dvec3& sun, int n, double time_s = 0.0) {
  StyleRenderer r(style, time_s);
  std::vector<ViewRequest> views = {{MAPPING_LATLONG, 2 * n, n, 0}, {MAPPING_CUBE_STRIP, n, 6 * n, 0}};
  for (int f = 0; f < 6; ++f) views.push_back({MAPPING_VULKAN_FACE, n, n, f});
  std::vector<std::vector<float>> images = r.renderer->Render(sun, views);
  images.push_back(r.renderer->RenderDirections(sun, {sun}));
  images.push_back(r.renderer->RenderDirections(sun, {sun}, false));
  return images;
}

// A layer of coverage 0 or density 0 is pruned: no cloud pipeline, and the
// same bytes as the style without it.
TEST(CloudPass, PrunedLayerIsByteIdenticalToNoLayer) {
  const glm::dvec3 sun = Sun(20.0);
  const SkyStyle plain = Style(kFast);
  const std::vector<std::vector<float>> expected = RenderAll(plain, sun, 16);
  for (const char* layer : {"coverage = 0.0", "density_per_m = 0.0"}) {
    SkyStyle pruned = Style(std::string(kFast) + "[[cloud_layer]]\ntype = \"cumulus\"\n" + layer + "\n");
    ASSERT_EQ(pruned.clouds.layers.size(), 1u);
    EXPECT_FALSE(PlanPasses({pruned}).variant.find("clouds: none") == std::string::npos) << layer;
    StyleRenderer r(pruned);
    EXPECT_EQ(r.renderer->counters().pipelines, StyleRenderer(plain).renderer->counters().pipelines) << layer;
    const std::vector<std::vector<float>> images = RenderAll(pruned, sun, 16);
    ASSERT_EQ(images.size(), expected.size());
    for (size_t i = 0; i < images.size(); ++i) EXPECT_TRUE(images[i] == expected[i]) << layer << ", view " << i;
  }
  // The same layer with coverage does change the sky (the test is not vacuous).
  const std::vector<std::vector<float>> cloudy = RenderAll(Style(std::string(kFast) + kCumulus), sun, 16);
  EXPECT_FALSE(cloudy[0] == expected[0]);
  testing::ExpectNoValidationMessages();
}

// Wind moves the clouds by wind x time and nothing else: for a layer that
// tiles (`tiling = true`), after exactly one
// tile period of every noise (8 km at 80 m/s in 100 s) the sky is the same
// to float rounding; after half of it, it differs; two renders of the same
// time give the same bytes.
TEST(CloudPass, WindMovesTheCloudsWithoutReRandomising) {
  const SkyStyle style = Style(std::string(kFast) + R"(
[[cloud_layer]]
altitude_m = 1000
thickness_m = 1000
coverage = 0.5
weather_size_m = 8000
shape_size_m = 4000
detail_size_m = 400
tiling = true
wind_m_s = [80.0, 0.0]
)");
  const glm::dvec3 sun = Sun(30.0);
  const ViewRequest latlong{MAPPING_LATLONG, 64, 32, 0};
  auto render = [&](double t) { return StyleRenderer(style, t).renderer->Render(sun, {latlong})[0]; };
  const std::vector<float> t0 = render(0.0), t50 = render(50.0), t100 = render(100.0);
  EXPECT_TRUE(render(50.0) == t50);
  double moved = 0.0, back = 0.0, sum = 0.0;
  for (size_t i = 0; i < t0.size(); i += 4) {
    for (int c = 0; c < 3; ++c) {
      moved += std::abs(t50[i + c] - t0[i + c]);
      back = std::max(back, double(std::abs(t100[i + c] - t0[i + c])) / std::max(t0[i + c], 1e-3f));
      sum += t0[i + c];
    }
  }
  EXPECT_GT(moved / sum, 0.01) << "half a period later the clouds have moved";
  EXPECT_LT(back, 2e-3) << "a whole period later they are back where they were";
  // UpdateClouds (what a sequence does between frames) gives the same bytes
  // as a renderer built for that time.
  StyleRenderer r(style, 0.0);
  r.renderer->Render(sun, {latlong});
  ASSERT_TRUE(r.renderer->UpdateClouds(ToCloudInputs(PrunedStyle(style).clouds, 1, "", 50.0)));
  EXPECT_TRUE(r.renderer->Render(sun, {latlong})[0] == t50);
  EXPECT_EQ(r.renderer->counters().cloud_noise_builds, 1) << "the wind does not regenerate the noise";
  testing::ExpectNoValidationMessages();
}

struct CloudCase {
  std::string name;
  std::string toml;              // after kFast
  std::vector<double> suns_deg;  // sun elevations
  int cube = 24;
  bool dim_not_black = false;  // overcast: the sky under it is dim but not black
};

void CheckFiniteNonNegative(const std::vector<float>& image, const std::string& what) {
  for (size_t i = 0; i < image.size(); ++i) {
    if (i % 4 == 3) continue;
    ASSERT_TRUE(std::isfinite(image[i]) && image[i] >= 0.0f) << what << ": texel " << i / 4 << " = " << image[i];
  }
}

class CloudHardCase : public ::testing::TestWithParam<CloudCase> {};

TEST_P(CloudHardCase, FiniteNonNegativeAndContinuous) {
  const CloudCase& c = GetParam();
  const SkyStyle style = Style(std::string(kFast) + c.toml);
  const SkyStyle clear = Style(kFast + std::string(c.toml.substr(0, c.toml.find("[[cloud_layer]]"))));
  ASSERT_FALSE(ActiveCloudLayers(style.clouds).empty());
  StyleRenderer r(style);
  for (double elevation : c.suns_deg) {
    const glm::dvec3 sun = Sun(elevation);
    const std::string what = fmt::format("{}, sun {} deg", c.name, elevation);
    const int n = c.cube;
    const ViewRequest strip{MAPPING_CUBE_STRIP, n, 6 * n, 0};
    const ViewRequest latlong{MAPPING_LATLONG, 64, 32, 0};
    std::vector<std::vector<float>> images = r.renderer->Render(sun, {strip, latlong});
    CheckFiniteNonNegative(images[0], what + ", strip");
    CheckFiniteNonNegative(images[1], what + ", latlong");
    // Cube edges: the strip's edge texels of neighbouring faces sit on the
    // same directions (Imf::CubeMap), so they must agree.
    const std::vector<glm::dvec3> dirs = ViewDirections(strip);
    std::map<std::array<long, 3>, std::vector<size_t>> by_direction;
    for (size_t i = 0; i < dirs.size(); ++i)
      by_direction[{std::lround(dirs[i].x * 1e6), std::lround(dirs[i].y * 1e6), std::lround(dirs[i].z * 1e6)}]
          .push_back(i);
    int pairs = 0;
    double worst = 0.0;
    for (const auto& [key, texels] : by_direction)
      for (size_t k = 1; k < texels.size(); ++k, ++pairs)
        for (int ch = 0; ch < 3; ++ch) {
          const double a = images[0][4 * texels[0] + ch], b = images[0][4 * texels[k] + ch];
          worst = std::max(worst, std::abs(a - b) / std::max(std::max(a, b), 1e-6));
        }
    EXPECT_EQ(pairs, 12 * (n - 2) + 8 * 2) << what;
    EXPECT_LT(worst, 2e-3) << what << ": cube edges";
    // Latlong seam: the step from the last column to the first is no larger
    // than the steps between neighbouring columns elsewhere in that row.
    const std::vector<float>& ll = images[1];
    double seam = 0.0, interior = 0.0;
    for (int y = 0; y < 32; ++y)
      for (int ch = 0; ch < 3; ++ch) {
        seam = std::max(seam, double(std::abs(ll[4 * (y * 64 + 63) + ch] - ll[4 * (y * 64) + ch])));
        for (int x = 0; x + 1 < 64; ++x)
          interior = std::max(interior, double(std::abs(ll[4 * (y * 64 + x + 1) + ch] - ll[4 * (y * 64 + x) + ch])));
      }
    EXPECT_LE(seam, interior * 1.0 + 1e-6) << what << ": latlong seam";
    if (c.dim_not_black) {
      // Straight up under the deck: dimmer than a white Lambertian ground
      // lit by the clear sky's sun (E cos(zenith) / pi; the deck passes on
      // only part of the light), and not black.
      StyleRenderer clear_renderer(clear);
      const double centre = clear_renderer.renderer->RenderDirections(sun, {sun})[1] -
                            clear_renderer.renderer->RenderDirections(sun, {sun}, false)[1];
      const AtmosphereParams& a = style.atmosphere;
      const double sun_illuminance =
          centre * M_PI * a.sun_angular_radius_rad * a.sun_angular_radius_rad * (1.0 - a.limb_darkening_u / 3.0);
      const double white = sun_illuminance * sun.y / M_PI;
      const std::vector<float> up = r.renderer->RenderDirections(sun, {glm::dvec3(0, 1, 0)}, false);
      EXPECT_LT(up[1], 0.5 * white) << what;
      EXPECT_GT(up[1], 1e-3 * white) << what;
    }
  }
  testing::ExpectNoValidationMessages();
}

std::string Layer(double altitude_m, double thickness_m, const std::string& extra) {
  return fmt::format("[[cloud_layer]]\naltitude_m = {}\nthickness_m = {}\n{}\n", altitude_m, thickness_m, extra);
}

// A named style (cloud layers after kFast) rendered at one sun elevation (deg).
struct StyleAtSun {
  const char* name;
  std::string toml;
  double sun;
};

INSTANTIATE_TEST_SUITE_P(
    Cases, CloudHardCase,
    ::testing::Values(
        CloudCase{"overcast_coverage_1",
                  Layer(1000, 800, "type = \"stratus\"\ncoverage = 1.0\ndensity_per_m = 0.05"),
                  {45.0},
                  24,
                  true},
        CloudCase{"extinction_1_per_m", Layer(1500, 1500, "coverage = 0.6\ndensity_per_m = 1.0"), {30.0}},
        CloudCase{"thin_layer_at_10_km",
                  Layer(10000, 100, "type = \"cirrus\"\ncoverage = 0.7\ndensity_per_m = 0.002"),
                  {30.0}},
        CloudCase{"overlapping_layers",
                  Layer(1000, 2000, "coverage = 0.5") +
                      Layer(2500, 1500, "type = \"stratocumulus\"\ncoverage = 0.4\nseed = 7"),
                  {30.0}},
        CloudCase{"observer_inside_a_layer",
                  "[atmosphere]\nobserver_altitude_m = 2000\n" + Layer(1500, 1500, "coverage = 0.6"),
                  {30.0}},
        CloudCase{"observer_2_km_above_the_top_layer",
                  "[atmosphere]\nobserver_altitude_m = 5000\n" + Layer(1500, 1500, "coverage = 0.6"),
                  {30.0}},
        CloudCase{"sun_at_zenith_horizon_and_minus_6_deg", Layer(1500, 1500, "coverage = 0.5"), {90.0, 0.0, -6.0}},
        CloudCase{"cube_size_16", Layer(1500, 1500, "coverage = 0.5"), {30.0}, 16}),
    [](const ::testing::TestParamInfo<CloudCase>& info) { return info.param.name; });

// A cube of 2048: the faces the clouds are in (+X, +Y) at full size, the
// draft preset with 8 view and 2 light steps to keep the case within a
// minute on lavapipe; no NaN, Inf or negative value.
TEST(CloudPass, CubeSize2048) {
  const SkyStyle style =
      Style(std::string(kFast) + "cloud_view_steps = 8\ncloud_light_steps = 2\n" + Layer(1500, 1500, "coverage = 0.5"));
  StyleRenderer r(style);
  for (int face : {0, 2}) {
    std::vector<float> image = r.renderer->Render(Sun(30.0), {{MAPPING_VULKAN_FACE, 2048, 2048, face}})[0];
    CheckFiniteNonNegative(image, fmt::format("face {}", face));
  }
  testing::ExpectNoValidationMessages();
}

// The sun disc: hidden behind a thick deck, seen through a thin one.
TEST(CloudPass, SunDiscHiddenByThickCloudsSeenThroughThin) {
  const glm::dvec3 sun = Sun(60.0);
  auto disc = [&](const std::string& toml) {
    StyleRenderer r(Style(std::string(kFast) + toml));
    const double with_disc = r.renderer->RenderDirections(sun, {sun})[1];
    const double without = r.renderer->RenderDirections(sun, {sun}, false)[1];
    return with_disc - without;
  };
  const double clear = disc("");
  const double thick =
      disc(Layer(1000, 1000, "type = \"stratus\"\ncoverage = 1.0\nshape_amount = 0.0\ndensity_per_m = 0.05"));
  const double thin =
      disc(Layer(9000, 300, "type = \"stratus\"\ncoverage = 1.0\nshape_amount = 0.0\ndensity_per_m = 0.001"));
  EXPECT_GT(clear, 0.0);
  // The march stops once the clouds' transmittance is below 1e-3 and drops
  // what lies behind: no disc at all.
  EXPECT_EQ(thick, 0.0);
  EXPECT_GT(thin, 0.2 * clear);
  EXPECT_LT(thin, 0.95 * clear);
  testing::ExpectNoValidationMessages();
}

// A sequence with wind bakes to the same bytes in shards and when resumed
// as in one go (the wind's offsets come from each frame's own clock time).
TEST(CloudSequence, ShardsAndResumeAreByteIdentical) {
  namespace fs = std::filesystem;
  const std::string root = testing::FreshTempDir("cloud_sequence");
  const std::string style = root + "/style.toml", schedule = root + "/schedule.toml";
  std::ofstream(style) << std::string(kFast) + Layer(1500, 1500, "coverage = 0.5\nwind_m_s = [15.0, 5.0]");
  std::ofstream(schedule) << testing::IthacaSchedule("09:00:00", "09:45:00", 15);
  EXPECT_EQ(testing::BakeWholeAndTwoShards(style, schedule, root, "shards"), 0);
  // Resume: one frame's files lost, the rest verified by checksum.
  fs::copy(root + "/whole", root + "/resumed");
  for (const std::string& name : testing::FileNames(root + "/resumed"))
    if (name.find(".0003.") != std::string::npos) fs::remove(root + "/resumed/" + name);
  testing::BakeSequence16(style, schedule, root + "/resumed", "--resume");
  std::set<std::string> whole = testing::FileNames(root + "/whole");
  EXPECT_GT(whole.size(), 30u);
  whole.erase("timings.json");
  for (const std::string& dir : {root + "/shards", root + "/resumed"})
    testing::ExpectSameBytes(dir, root + "/whole", whole);
  // The wind moved the clouds between frames: the frames differ.
  EXPECT_NE(testing::ReadFileBytes(root + "/whole/sky_latlong.0001.exr"),
            testing::ReadFileBytes(root + "/whole/sky_latlong.0002.exr"));
  fs::remove_all(root);
}

// ---------------------------------------------------------------- weather images

// The same value in every channel.
void WriteImage(const std::string& path, int w, int h, int channels, const std::function<float(int, int)>& value) {
  testing::WriteTestImage(path, w, h, channels, [&](int x, int y, int) { return value(x, y); });
}

// A weather image puts the clouds where its first channel says: the west
// half covered, the east half clear, in a PNG and in a one-channel EXR.
TEST(CloudWeather, ImageCoverageIsWhereTheImageSays) {
  const std::string dir = testing::FreshTempDir("cloud_weather");
  WriteImage(dir + "/west.png", 64, 64, 3, [](int x, int) { return x < 32 ? 1.0f : 0.0f; });
  WriteImage(dir + "/west.exr", 64, 64, 1, [](int x, int) { return x < 32 ? 1.0f : 0.0f; });
  const glm::dvec3 sun = Sun(50.0, 180.0);
  const glm::dvec3 west = SunDirectionFromElevationAzimuth(30.0, 270.0),
                   east = SunDirectionFromElevationAzimuth(30.0, 90.0);
  StyleRenderer clear(Style(kFast));
  const std::vector<float> sky = clear.renderer->RenderDirections(sun, {west, east}, false);
  for (const char* image : {"west.png", "west.exr"}) {
    // 20 km square centred on the viewer: x < 0 (west) covered.
    const std::string toml = std::string(kFast) + fmt::format(R"(
[[cloud_layer]]
altitude_m = 1500
thickness_m = 1000
type = "stratus"
shape_amount = 0.0
coverage = 0.5
weather_image = "{}"
weather_extent_m = [20000.0, 20000.0]
weather_origin_m = [-10000.0, -10000.0]
)",
                                                              image);
    ConfigResult r = ParseSkyStyle(toml, dir + "/style.toml");
    ASSERT_TRUE(r.ok()) << r.errors[0].Format();
    const SkyStyle style = PrunedStyle(r.style);
    SkyRenderer renderer(testing::Vulkan(), StyledAtmosphere(style.atmosphere, style.aoas), style.quality,
                         style.effects, OutputScale(style.output.units), false,
                         ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)),
                         ToCloudInputs(style.clouds, style.aoas.seed, dir, 0.0));
    const std::vector<float> cloudy = renderer.RenderDirections(sun, {west, east}, false);
    EXPECT_EQ(cloudy[4 + 1], sky[4 + 1]) << image << ": the east is clear";
    EXPECT_GT(std::abs(cloudy[1] - sky[1]), 0.05 * sky[1]) << image << ": the west is under the deck";
  }
  testing::ExpectNoValidationMessages();
}

TEST(CloudWeather, BadImagesAreReportedWithTheirPath) {
  const std::string dir = testing::FreshTempDir("cloud_weather_bad");
  WriteImage(dir + "/two.exr", 8, 8, 2, [](int, int) { return 0.5f; });
  std::ofstream(dir + "/broken.png") << "not a png";
  for (const auto& [file, message] : std::vector<std::pair<std::string, std::string>>{
           {"two.exr", "two.exr: 2 channels; expected 1 (coverage) or 3/4 (R = coverage)"},
           {"broken.png", "broken.png: cannot read it as an image"},
           {"missing.exr", "missing.exr: no such file"}}) {
    ConfigResult r = ParseSkyStyle("[[cloud_layer]]\nweather_image = \"" + file + "\"\n", dir + "/style.toml");
    ASSERT_EQ(r.errors.size(), 1u) << file;
    EXPECT_NE(r.errors[0].Format().find(dir + "/style.toml:2:17: cloud_layer[0].weather_image: " + dir + "/" + message),
              std::string::npos)
        << r.errors[0].Format();
  }
}

// The bake's SH irradiance, sun irradiance and preview see the clouds: under
// an overcast deck the sun's transmitted irradiance is gone (the disc is
// hidden) and the sky's irradiance and the preview differ from the clear bake.
TEST(CloudBake, ShIrradianceAndPreviewIncludeTheClouds) {
  const std::string root = testing::FreshTempDir("cloud_bake");
  auto bake = [&](const std::string& toml, const std::string& out) {
    SkyStyle style = Style(std::string(kFast) + "[render]\ncube_size = 16\nlatlong_height = 16\n" + toml);
    BakeOptions options;
    options.out_dir = root + "/" + out;
    options.vulkan.validation = true;
    BakeResult r = BakeStyle(style, options);
    EXPECT_EQ(r.validation_messages, 0);
    return r;
  };
  const BakeResult clear = bake("", "clear");
  const BakeResult overcast = bake(
      Layer(1000, 1000, "type = \"stratus\"\ncoverage = 1.0\nshape_amount = 0.0\ndensity_per_m = 0.05"), "overcast");
  ASSERT_EQ(clear.frames.size(), 1u);
  ASSERT_EQ(overcast.frames.size(), 1u);
  EXPECT_GT(clear.frames[0].sun_illuminance_lux, 1e4);
  EXPECT_EQ(overcast.frames[0].sun_illuminance_lux, 0.0);
  const double clear_sky = clear.frames[0].sh_irradiance_without_sun[0][1];
  const double overcast_sky = overcast.frames[0].sh_irradiance_without_sun[0][1];
  EXPECT_GT(overcast_sky, 0.0);
  EXPECT_GT(std::abs(overcast_sky - clear_sky), 0.05 * clear_sky);
  EXPECT_NE(testing::ReadFileBytes(root + "/clear/sky_latlong.png"),
            testing::ReadFileBytes(root + "/overcast/sky_latlong.png"));
  std::filesystem::remove_all(root);
}

// The mean over the upper hemisphere of a 96 x 48 latlong of |a - reference|
// / mean reference, green channel: the cloud march tests' error.
double UpperHemisphereGreenError(const std::vector<float>& a, const std::vector<float>& reference) {
  double diff = 0.0, sum = 0.0;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 96; ++x) {
      const size_t i = 4 * (size_t(y) * 96 + x) + 1;
      diff += std::abs(double(a[i]) - reference[i]);
      sum += reference[i];
    }
  return diff / sum;
}

// Convergence of the cloud march: the presets' view and light steps against
// a fine march (400 view, 50 light steps: near lavapipe's 65535 loop
// iterations per invocation, CloudLoopIterationsPerTexel), same noise and
// model (8 octaves, production noise sizes). The error: mean over the upper
// hemisphere of |L - L_ref| / mean L_ref, green channel, 96 x 48 latlong.
TEST(CloudConvergence, PresetStepsApproachTheConvergedMarch) {
  const glm::dvec3 sun = Sun(30.0);
  const ViewRequest latlong{MAPPING_LATLONG, 96, 48, 0};
  auto render = [&](int view_steps, int light_steps) {
    SkyStyle style = Style(kCumulus);
    style.clouds.quality.view_steps = view_steps;
    style.clouds.quality.light_steps = light_steps;
    // Every light sample trilinear: the march whose steps converge
    // (the nearest-voxel far samples: CloudLightNearest below).
    style.clouds.quality.light_trilinear_steps = 256;
    style.clouds.quality.light_volume_columns = 0;  // every light sample marched
    return StyleRenderer(style).renderer->Render(sun, {latlong})[0];
  };
  const auto error = UpperHemisphereGreenError;
  const std::vector<float> converged = render(400, 50);
  const double half = error(render(200, 25), converged);
  struct Setting {
    const char* name;
    int view, light;
  };
  std::vector<double> errors;
  for (Setting s : {Setting{"draft", 32, 6}, Setting{"production", 48, 6}, Setting{"reference", 192, 32}}) {
    errors.push_back(error(render(s.view, s.light), converged));
    std::printf("cloud march %-10s view %3d light %2d: mean relative error %.4f\n", s.name, s.view, s.light,
                errors.back());
  }
  std::printf("400/50 against 200/25: %.5f\n", half);
  EXPECT_GT(errors[0], errors[1]);
  EXPECT_GT(errors[1], errors[2]);
  // The fine march is first order in its steps: halving them changes it by
  // about its own error, which is a tenth of the production preset's.
  EXPECT_LT(half, 0.1 * errors[1]);
  EXPECT_LT(errors[1], 0.1);
  testing::ExpectNoValidationMessages();
}

// The light march's far samples at the nearest voxel
// (quality.cloud_light_trilinear_steps): the key at light_steps or above is
// the trilinear march bit for bit; below it the march changes by less than
// 2% (about what halving the light steps changes; 0.8-1.2% with 6 of 24
// trilinear, 1.1-1.3% with none), less with the near samples trilinear
// than with none, at a low Sun (long light paths) and a high one. Green
// channel, upper hemisphere, 96 x 48.
TEST(CloudLightNearest, FarLightSamplesAtTheNearestVoxelStayClose) {
  const ViewRequest latlong{MAPPING_LATLONG, 96, 48, 0};
  auto render = [&](double elevation, int light_steps, int trilinear) {
    SkyStyle style = Style(kCumulus);
    style.clouds.quality.light_steps = light_steps;
    style.clouds.quality.light_trilinear_steps = trilinear;
    style.clouds.quality.light_volume_columns = 0;  // every light sample marched
    return StyleRenderer(style).renderer->Render(Sun(elevation), {latlong})[0];
  };
  const auto error = UpperHemisphereGreenError;
  for (double elevation : {10.0, 45.0}) {
    const std::vector<float> trilinear = render(elevation, 24, 256);
    EXPECT_EQ(render(elevation, 24, 24), trilinear) << "sun " << elevation << ": all light samples trilinear";
    const std::vector<float> far_nearest = render(elevation, 24, 6);
    const std::vector<float> all_nearest = render(elevation, 24, 0);
    const double far = error(far_nearest, trilinear), all = error(all_nearest, trilinear);
    std::printf("sun %4.1f deg: 6 of 24 light samples trilinear %.4f, none %.4f\n", elevation, far, all);
    EXPECT_GT(far, 0.0) << "the nearest reads run";
    EXPECT_LT(far, all) << "the near samples read trilinearly matter most";
    EXPECT_LT(far, 0.02);
    for (float v : far_nearest) EXPECT_TRUE(std::isfinite(v) && v >= 0.0f);
  }
  testing::ExpectNoValidationMessages();
}

// The light volume (quality.cloud_light_volume_*, clouds.h): a 512 x 32
// volume with 2 exact near steps against every light sample marched, at a
// low Sun and a high one: within 3% (green, upper hemisphere, 96 x 48), not
// equal (the volume is read), finite and non-negative; production's 256
// columns within 6%. Off
// where it cannot serve, with the exact march's bytes: a Sun below
// kCloudLightVolumeMinElevationDeg, and a style of two bands.
TEST(CloudLightVolume, StaysCloseToTheExactMarchAndOffKeepsTheBytes) {
  const ViewRequest latlong{MAPPING_LATLONG, 96, 48, 0};
  auto render = [&](const std::string& toml, double elevation, int columns) {
    SkyStyle style = Style(toml);
    style.clouds.quality.light_volume_columns = columns;
    return StyleRenderer(style).renderer->Render(Sun(elevation), {latlong})[0];
  };
  const auto error = UpperHemisphereGreenError;
  for (double elevation : {10.0, 45.0}) {
    const std::vector<float> exact = render(kCumulus, elevation, 0);
    const std::vector<float> volume = render(kCumulus, elevation, 512);
    const double e = error(volume, exact);
    std::printf("sun %4.1f deg: light volume 512 x 32, 2 near steps, against the exact march %.4f\n", elevation, e);
    EXPECT_GT(e, 0.0) << "the volume is read";
    EXPECT_LT(e, 0.03);
    for (float v : volume) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f);
    // Draft's 256 columns, still close.
    const double alone = error(render(kCumulus, elevation, 256), exact);
    EXPECT_LT(alone, 0.06) << "256 columns";
  }
  EXPECT_EQ(render(kCumulus, kCloudLightVolumeMinElevationDeg - 1.0, 512),
            render(kCumulus, kCloudLightVolumeMinElevationDeg - 1.0, 0))
      << "a low Sun marches every light sample";
  const std::string two_bands = Layer(1500, 1000, "coverage = 0.5") + Layer(6000, 500, "type = \"cirrus\"");
  EXPECT_EQ(render(two_bands, 30.0, 512), render(two_bands, 30.0, 0)) << "two bands march every light sample";
  testing::ExpectNoValidationMessages();
}

// ---------------------------------------------------------------- empty space

// FillCloudSkipMaps (clouds.h): every cell's value is the maximum of the
// texels a bilinear or trilinear read at any point of the cell touches
// (brute force over random points and their 8 or 4 texels, wrapping, the
// cell found as the shader finds it), and exactly the maximum of the cell's
// own 2 texels a side (it is the tightest bound, not 1).
TEST(CloudSkip, CellMaximaBoundEveryReadOfTheirCell) {
  gpu::GpuClouds g{};
  g.counts = {2, 8, 4, 8};
  g.resolution = {9, 4, 10, 1};  // odd sizes: the last cell wraps to texel 0
  const size_t shape = 9 * 9 * 9, detail = 4 * 4 * 4, weather = 10 * 10;
  for (int l = 0; l < 2; ++l)
    g.layers[l].noise = {int(l * (shape + detail + weather)), int(l * (shape + detail + weather) + shape),
                         int(l * (shape + detail + weather) + shape + detail), 1};
  std::vector<float> noise(CloudNoiseFloats(g));
  ASSERT_EQ(noise.size(), CloudSkipFirst(g) + 2 * CloudSkipFloatsPerLayer(g));
  uint32_t state = 12345u;
  auto next = [&]() {
    state = state * 1664525u + 1013904223u;
    return float(state >> 8) / 16777216.0f;
  };
  for (size_t i = 0; i < CloudSkipFirst(g); ++i) noise[i] = next();
  FillCloudSkipMaps(g, noise.data());
  auto wrap = [](int i, int n) { return ((i % n) + n) % n; };
  for (int l = 0; l < 2; ++l) {
    const float* map = noise.data() + CloudSkipFirst(g) + l * CloudSkipFloatsPerLayer(g);
    const int wc = 10, sc = 9;  // one cell per texel
    ASSERT_EQ(CloudSkipFloatsPerLayer(g), size_t(wc * wc + sc * sc * sc));
    const float* shape_map = map + wc * wc;
    const float* volume = noise.data() + g.layers[l].noise.x;
    const float* wmap = noise.data() + g.layers[l].noise.z;
    int below_one = 0;
    for (int k = 0; k < 20000; ++k) {
      const glm::vec3 u(next(), next(), next());
      // The shader's cell (CloudSkipCell: the read's first texel, wrapped) and
      // the trilinear read's texels (SampleVolume).
      const glm::ivec3 base = glm::ivec3(glm::floor(u * 9.0f - 0.5f));
      const glm::ivec3 cell(wrap(base.x, 9), wrap(base.y, 9), wrap(base.z, 9));
      const float bound = shape_map[(cell.z * sc + cell.y) * sc + cell.x];
      for (int c = 0; c < 8; ++c) {
        const glm::ivec3 t(wrap(base.x + (c & 1), 9), wrap(base.y + ((c >> 1) & 1), 9), wrap(base.z + (c >> 2), 9));
        ASSERT_GE(bound, volume[(t.z * 9 + t.y) * 9 + t.x]) << "layer " << l << " point " << k;
      }
      const glm::ivec2 wbase = glm::ivec2(glm::floor(glm::vec2(u) * 10.0f - 0.5f));
      const float wbound = map[wrap(wbase.y, 10) * wc + wrap(wbase.x, 10)];
      for (int c = 0; c < 4; ++c)
        ASSERT_GE(wbound, wmap[wrap(wbase.y + (c >> 1), 10) * 10 + wrap(wbase.x + (c & 1), 10)]);
      below_one += bound < 0.999f;
    }
    // Each cell's value is the maximum of its own texels (2 a side: i and i + 1, wrapped).
    for (int z = 0; z < sc; ++z)
      for (int y = 0; y < sc; ++y)
        for (int x = 0; x < sc; ++x) {
          float m = 0.0f;
          for (int k = 0; k < 8; ++k)
            m = std::max(m,
                         volume[(wrap(z + (k >> 2), 9) * 9 + wrap(y + ((k >> 1) & 1), 9)) * 9 + wrap(x + (k & 1), 9)]);
          EXPECT_EQ(shape_map[(z * sc + y) * sc + x], m);
        }
    EXPECT_GT(below_one, 0) << "the bounds are maxima, not 1";
  }
}

// The view march skips the samples the bounds (CloudMargin) say hold no
// cloud; their density is 0, so every view, the SH faces and the sun
// direction keep their bytes with the bounds on and off (GpuClouds.range.w),
// for W3's cumulus at coverage 0.45 (where the bounds skip most), an
// overcast deck, two overlapping layers with shear, a thin high layer, and
// the observer inside and above the layers, at a high, a low and a set sun.
TEST(CloudSkip, SkippingEmptySpaceKeepsTheBytes) {
  const std::vector<StyleAtSun> cases = {
      {"W3 cumulus", Layer(1500, 1500, "type = \"cumulus\"\ncoverage = 0.45\nwind_m_s = [8.0, 2.0]"), 30.0},
      {"W3 cumulus, low sun", Layer(1500, 1500, "type = \"cumulus\"\ncoverage = 0.45"), 4.0},
      {"overcast stratus", Layer(800, 600, "type = \"stratus\"\ncoverage = 1.0"), 45.0},
      {"overlapping, shear",
       Layer(1500, 1500, "coverage = 0.6\nshear_m_s_per_km = [20.0, 5.0]\nwind_m_s = [10.0, 0.0]") +
           Layer(2500, 2000, "type = \"stratocumulus\"\ncoverage = 0.4"),
       20.0},
      {"thin cirrus at 10 km", Layer(10000, 300, "type = \"cirrus\"\ncoverage = 0.35"), -3.0},
      {"observer inside", "[atmosphere]\nobserver_altitude_m = 2000\n" + Layer(1500, 1500, "coverage = 0.45"), 30.0},
      {"observer above", "[atmosphere]\nobserver_altitude_m = 5000\n" + Layer(1500, 1500, "coverage = 0.45"), 30.0},
  };
  for (const StyleAtSun& c : cases) {
    const SkyStyle style = PrunedStyle(Style(std::string(kFast) + c.toml));
    auto render = [&](bool skip) {
      CloudInputs clouds = ToCloudInputs(style.clouds, style.aoas.seed, "", 600.0);
      clouds.uniform.range.w = skip ? 1.0f : 0.0f;
      SkyRenderer r(testing::Vulkan(), StyledAtmosphere(style.atmosphere, style.aoas), style.quality, style.effects,
                    OutputScale(style.output.units), false,
                    ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)), clouds);
      const int n = 24;
      std::vector<ViewRequest> views = {{MAPPING_LATLONG, 4 * n, 2 * n, 0}, {MAPPING_CUBE_STRIP, n, 6 * n, 0}};
      for (int f = 0; f < 6; ++f) views.push_back({MAPPING_VULKAN_FACE, n, n, f});
      const glm::dvec3 sun = Sun(c.sun);
      std::vector<std::vector<float>> images = r.Render(sun, views);
      images.push_back(r.Render(sun, {views[0]})[0]);  // one latlong: marched, no panorama
      images.push_back(r.RenderDirections(sun, {sun, glm::dvec3(0.0, 0.2, 0.98)}));
      return images;
    };
    const std::vector<std::vector<float>> off = render(false), on = render(true);
    ASSERT_EQ(on.size(), off.size());
    for (size_t i = 0; i < on.size(); ++i) EXPECT_TRUE(on[i] == off[i]) << c.name << ", image " << i;
    const SkyStyle clear = PrunedStyle(Style(std::string(kFast) + c.toml.substr(0, c.toml.find("[[cloud_layer]]"))));
    EXPECT_FALSE(StyleRenderer(clear).renderer->Render(Sun(c.sun), {{MAPPING_LATLONG, 96, 48, 0}})[0] == off[8])
        << c.name << ": the layer shows (the test is not vacuous)";
  }
  testing::ExpectNoValidationMessages();
}

// A frame whose every band is in the Earth's shadow (the Sun below
// CloudEarthShadowElevationDeg) marches its clouds without the Sun's light
// march (SPEC_CLOUD_SUN_LIGHT off): the same bytes as the full march
// (SKYBAKE_SHADOWED_CLOUDS=0, ShaderSwitches::shadowed_clouds off) in every
// view, the panorama's and the marched latlong's and explicit directions, and
// the variant counted per frame; with the Sun 0.05 deg above the bound the
// full march runs. The night clouds still show (their ambient light and their
// transmittance over the sky): the test is not vacuous.
TEST(CloudEarthShadow, ShadowedFramesSkipTheLightMarchWithTheSameBytes) {
  struct ShadowCase {
    const char* name;
    std::string toml;
  };
  const std::vector<ShadowCase> cases = {
      {"W3 cumulus", Layer(1500, 1500, "type = \"cumulus\"\ncoverage = 0.45\nwind_m_s = [8.0, 2.0]")},
      {"overlapping, two bands", Layer(1500, 1500, "coverage = 0.6") +
                                     Layer(2500, 2000, "type = \"stratocumulus\"\ncoverage = 0.4") +
                                     Layer(8000, 500, "type = \"cirrus\"\ncoverage = 0.5")},
      {"observer above", "[atmosphere]\nobserver_altitude_m = 5000\n" + Layer(1500, 1500, "coverage = 0.45")},
  };
  for (const ShadowCase& c : cases) {
    const SkyStyle style = PrunedStyle(Style(std::string(kFast) + c.toml));
    double top_km = 0.0;
    for (const CloudLayer& l : ActiveCloudLayers(style.clouds))
      top_km = std::max(top_km, (l.altitude_m + l.thickness_m) * 1e-3);
    const double below = CloudEarthShadowElevationDeg(
        style.atmosphere.bottom_radius_km, style.atmosphere.observer_altitude_m * 1e-3, top_km,
        style.clouds.quality.max_distance_km, style.atmosphere.sun_angular_radius_rad);
    auto render = [&](bool variant, double elevation_deg, int* shadowed_frames) {
      ShaderSwitches shaders;
      shaders.shadowed_clouds = variant;
      SkyRenderer r(testing::Vulkan(), StyledAtmosphere(style.atmosphere, style.aoas), style.quality, style.effects,
                    OutputScale(style.output.units), false,
                    ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)),
                    ToCloudInputs(style.clouds, style.aoas.seed, "", 600.0), shaders);
      const int n = 24;
      std::vector<ViewRequest> views = {{MAPPING_LATLONG, 4 * n, 2 * n, 0}, {MAPPING_CUBE_STRIP, n, 6 * n, 0}};
      for (int f = 0; f < 6; ++f) views.push_back({MAPPING_VULKAN_FACE, n, n, f});
      const glm::dvec3 sun = Sun(elevation_deg);
      std::vector<std::vector<float>> images = r.Render(sun, views);  // the panorama
      images.push_back(r.Render(sun, {views[0]})[0]);                 // one latlong: marched
      images.push_back(r.RenderDirections(sun, {glm::dvec3(0.0, 0.2, 0.98), glm::dvec3(0.6, 0.05, -0.8)}));
      *shadowed_frames = r.counters().shadowed_cloud_frames;
      return images;
    };
    for (double elevation : {below - 0.05, below - 6.0}) {
      int on_frames = 0, off_frames = 0;
      const std::vector<std::vector<float>> on = render(true, elevation, &on_frames);
      const std::vector<std::vector<float>> off = render(false, elevation, &off_frames);
      EXPECT_EQ(on_frames, 3) << c.name << " at " << elevation << " deg: the variant runs";
      EXPECT_EQ(off_frames, 0) << c.name;
      ASSERT_EQ(on.size(), off.size());
      for (size_t i = 0; i < on.size(); ++i)
        EXPECT_TRUE(on[i] == off[i]) << c.name << " at " << elevation << " deg, image " << i;
      const SkyStyle clear = PrunedStyle(Style(std::string(kFast) + c.toml.substr(0, c.toml.find("[[cloud_layer]]"))));
      EXPECT_FALSE(StyleRenderer(clear).renderer->Render(Sun(elevation), {{MAPPING_LATLONG, 96, 48, 0}})[0] == on[8])
          << c.name << " at " << elevation << " deg: the night clouds show";
    }
    int above_frames = -1;
    render(true, below + 0.05, &above_frames);
    EXPECT_EQ(above_frames, 0) << c.name << ": 0.05 deg above the bound the Sun's light is marched";
  }
  // W3's layer (top 3 km, 300 km) from the ground: the bound of the header's comment.
  EXPECT_NEAR(CloudEarthShadowElevationDeg(6360.0, 0.0, 3.0, 300.0, 0.004675), -3.80, 0.005);
  testing::ExpectNoValidationMessages();
}

// The clouds of `style` at 600 s with its ground cloud shadow, and a
// renderer of them with the given shader switches.
CloudInputs CloudsAt600s(const SkyStyle& style) {
  CloudInputs clouds = ToCloudInputs(style.clouds, style.aoas.seed, "", 600.0);
  ApplyGroundCloudShadow(style.cloud_shadow, clouds);
  return clouds;
}
std::unique_ptr<SkyRenderer> RendererWithSwitches(const SkyStyle& style, const ShaderSwitches& shaders) {
  return std::make_unique<SkyRenderer>(testing::Vulkan(), StyledAtmosphere(style.atmosphere, style.aoas), style.quality,
                                       style.effects, OutputScale(style.output.units), false,
                                       ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)),
                                       CloudsAt600s(style), shaders);
}

// Every view a bake renders, at 24 texels a face: the latlong, the strip and
// the six faces (from the cloud panorama), the latlong alone (marched), two
// explicit directions, and the cloud shadow map when the style has one.
std::vector<std::vector<float>> RenderEveryView(SkyRenderer& r, const SkyStyle& style, double sun_deg) {
  const int n = 24;
  std::vector<ViewRequest> views = {{MAPPING_LATLONG, 4 * n, 2 * n, 0}, {MAPPING_CUBE_STRIP, n, 6 * n, 0}};
  for (int f = 0; f < 6; ++f) views.push_back({MAPPING_VULKAN_FACE, n, n, f});
  const glm::dvec3 sun = Sun(sun_deg);
  std::vector<std::vector<float>> images = r.Render(sun, views);
  images.push_back(r.Render(sun, {views[0]})[0]);
  images.push_back(r.RenderDirections(sun, {glm::dvec3(0.0, 0.2, 0.98), glm::dvec3(0.6, -0.05, -0.8)}));
  if (style.cloud_shadow.enabled) images.push_back(r.RenderCloudShadow(sun, style.cloud_shadow));
  return images;
}

// The shaders read the LUTs, the cloud noise and the cloud tables through
// texel views (SPEC_TEXEL_VIEWS), the same bytes as their storage buffers
// hold: every view, the panorama's and the marched latlong's, explicit
// directions and the cloud shadow map keep their bytes with the views on and
// off (SKYBAKE_TEXEL_VIEWS=0, ShaderSwitches::texel_views), for a clear sky,
// W3's cumulus with the ground's cloud shadow, two bands and a cirrus in
// twilight, and the observer above the layers.
TEST(CloudTexelViews, StorageBufferReadsKeepTheBytes) {
  const std::vector<StyleAtSun> cases = {
      {"clear, day", "", 30.0},
      {"clear, twilight", "", -4.0},
      {"W3 cumulus, ground shadow",
       "[cloud_shadow]\nenabled = true\nresolution = 16\n" +
           Layer(1500, 1500, "type = \"cumulus\"\ncoverage = 0.45\nwind_m_s = [8.0, 2.0]"),
       20.0},
      {"two bands and a cirrus, twilight",
       Layer(1500, 1500, "coverage = 0.6") + Layer(2500, 2000, "type = \"stratocumulus\"\ncoverage = 0.4") +
           Layer(8000, 500, "type = \"cirrus\"\ncoverage = 0.5"),
       -2.0},
      {"observer above", "[atmosphere]\nobserver_altitude_m = 5000\n" + Layer(1500, 1500, "coverage = 0.45"), 30.0},
  };
  for (const StyleAtSun& c : cases) {
    const SkyStyle style = PrunedStyle(Style(std::string(kFast) + c.toml));
    auto render = [&](bool texel_views) {
      ShaderSwitches shaders;
      shaders.texel_views = texel_views;
      const std::unique_ptr<SkyRenderer> r = RendererWithSwitches(style, shaders);
      EXPECT_EQ(r->reads_texel_views(), texel_views) << c.name;
      return RenderEveryView(*r, style, c.sun);
    };
    const std::vector<std::vector<float>> on = render(true), off = render(false);
    ASSERT_EQ(on.size(), off.size());
    for (size_t i = 0; i < on.size(); ++i) EXPECT_TRUE(on[i] == off[i]) << c.name << ", image " << i;
  }
  testing::ExpectNoValidationMessages();
}

// A style without a formation's density volume (weather.w 2) compiles that
// read out of its cloud pipelines (SPEC_CLOUD_FORMATION): the same bytes as
// with it kept (ShaderSwitches::formation_read_always, SKYBAKE_FORMATION_READ=1)
// in every view, the panorama's and the marched latlong's, explicit
// directions and the cloud shadow map, for W3's cumulus with the ground's
// shadow and for two bands with a weather image's coverage. The switch
// follows the layers (CloudFormationDensityOn: only active layers count),
// and a renderer built without the read refuses clouds that need it
// (UpdateClouds false: a sequence builds a new one).
TEST(CloudFormationRead, CompiledOutWithoutAFormationKeepsTheBytes) {
  gpu::GpuClouds g{};
  g.counts.x = 2;
  g.layers[1].weather.w = 1.0f;  // a weather image's coverage
  EXPECT_FALSE(CloudFormationDensityOn(g));
  g.layers[1].weather.w = 2.0f;
  EXPECT_TRUE(CloudFormationDensityOn(g));
  g.counts.x = 1;
  EXPECT_FALSE(CloudFormationDensityOn(g)) << "layer 1 is not active";

  const std::string dir = testing::FreshTempDir("cloud_formation_read");
  const std::string image = dir + "/weather.png";
  {
    std::vector<unsigned char> pixels(32 * 32);
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) pixels[y * 32 + x] = (x / 8 + y / 8) % 2 ? 230 : 40;
    auto out = OIIO::ImageOutput::create(image);
    ASSERT_TRUE(out && out->open(image, OIIO::ImageSpec(32, 32, 1, OIIO::TypeDesc::UINT8)));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
    out->close();
  }
  const std::vector<StyleAtSun> cases = {
      {"W3 cumulus, ground shadow",
       "[cloud_shadow]\nenabled = true\nresolution = 16\n" +
           Layer(1500, 1500, "type = \"cumulus\"\ncoverage = 0.45\nwind_m_s = [8.0, 2.0]"),
       30.0},
      {"two bands, weather image",
       Layer(1500, 1000, "weather_image = \"" + image + "\"") + Layer(6000, 500, "type = \"cirrus\"\ncoverage = 0.5"),
       20.0},
  };
  for (const StyleAtSun& c : cases) {
    const SkyStyle style = PrunedStyle(Style(std::string(kFast) + c.toml));
    auto render = [&](bool always) {
      ShaderSwitches shaders;
      shaders.formation_read_always = always;
      const CloudInputs clouds = CloudsAt600s(style);
      EXPECT_FALSE(CloudFormationDensityOn(clouds.uniform)) << c.name;
      const std::unique_ptr<SkyRenderer> r = RendererWithSwitches(style, shaders);
      std::vector<std::vector<float>> images = RenderEveryView(*r, style, c.sun);
      // The same clouds are taken; without the read, clouds with a
      // formation's density are refused before anything changes.
      EXPECT_TRUE(r->UpdateClouds(clouds)) << c.name;
      if (!always) {
        CloudInputs formation = clouds;
        formation.uniform.layers[0].weather.w = 2.0f;
        EXPECT_FALSE(r->UpdateClouds(formation)) << c.name;
      }
      return images;
    };
    const std::vector<std::vector<float>> out = render(false), kept = render(true);
    ASSERT_EQ(out.size(), kept.size());
    for (size_t i = 0; i < out.size(); ++i) EXPECT_TRUE(out[i] == kept[i]) << c.name << ", image " << i;
  }
  std::filesystem::remove_all(dir);
  testing::ExpectNoValidationMessages();
}

}  // namespace
}  // namespace skybake
