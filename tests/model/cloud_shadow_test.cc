// The cloud shadow map (cloud_shadow.h, shaders/cloud_shadow.comp) on
// lavapipe under the validation layer: the transmittance of a layer of
// known optical depth along its slant path, no clouds, tiling, drift, the
// sun at and below the horizon, and the file with its placement in the EXR
// header and manifest.json.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <OpenImageIO/imageio.h>
#include <glm/glm.hpp>

#include "skybake/gpu/cloud_panorama.h"
#include "skybake/model/cloud_shadow.h"
#include "skybake/model/clouds.h"
#include "skybake/model/tonemap.h"
#include "skybake/input/config.h"
#include "skybake/output/exr_io.h"
#include "skybake/pipeline/pass_plan.h"
#include "skybake/gpu/sky_renderer.h"
#include "schedule_fixtures.h"
#include "test_support.h"

namespace skybake {
namespace {

SkyStyle Style(const std::string& toml) {
  ConfigResult r = ParseSkyStyle(toml, "cloud_shadow_test.toml");
  EXPECT_TRUE(r.ok()) << (r.errors.empty() ? "" : r.errors[0].Format());
  return r.style;
}

std::unique_ptr<SkyRenderer> RendererOf(const SkyStyle& unpruned, double time_s = 0.0) {
  const SkyStyle style = PrunedStyle(unpruned);
  return std::make_unique<SkyRenderer>(testing::Vulkan(), StyledAtmosphere(style.atmosphere, style.aoas), style.quality,
                                       style.effects, OutputScale(style.output.units), false,
                                       ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)),
                                       ToCloudInputs(style.clouds, style.aoas.seed, "", time_s));
}

glm::dvec3 Sun(double elevation_deg, double azimuth_deg = 135.0) {
  const double e = glm::radians(elevation_deg), a = glm::radians(azimuth_deg);
  return {std::cos(e) * std::sin(a), std::sin(e), -std::cos(e) * std::cos(a)};
}

// A draft style with a 500 m layer at 1 km whose profile is 1 across the
// whole thickness, no detail noise: its coverage, extinction (1/m) and shape
// noise as TOML values.
std::string SlabLayer(const std::string& coverage, const std::string& density_per_m, const std::string& shape_amount) {
  return R"(
[quality]
preset = "draft"
[[cloud_layer]]
altitude_m = 1000
thickness_m = 500
type = "custom"
profile = [0.0, 0.0, 1.0, 1.0]
coverage = )" +
         coverage + "\ndensity_per_m = " + density_per_m + "\nshape_amount = " + shape_amount +
         "\ndetail_amount = 0.0\n";
}

// A slab of uniform extinction: coverage 1, no shape or detail noise.
const std::string kSlab = SlabLayer("1.0", "0.002", "0.0");

// tau = 0.002 /m x 500 m = 1 vertically; the map is exp(-tau / cos(zenith))
// at every texel, for several sun elevations, and exp(-strength tau / cos).
TEST(CloudShadow, UniformLayerCastsExpOfTauOverCosine) {
  const SkyStyle style = Style(kSlab);
  std::unique_ptr<SkyRenderer> r = RendererOf(style);
  CloudShadowSettings s{.enabled = true, .resolution = 16, .extent_m = 4000.0};
  for (double elevation : {90.0, 60.0, 30.0, 10.0}) {
    for (double strength : {1.0, 0.5}) {
      s.strength = strength;
      const glm::dvec3 sun = Sun(elevation);
      const std::vector<float> map = r->RenderCloudShadow(sun, s);
      ASSERT_EQ(map.size(), 256u);
      const double expected = std::exp(-strength * 1.0 / sun.y);
      for (float t : map) ASSERT_NEAR(t, expected, 2e-5 * std::max(expected, 1e-2)) << elevation << " " << strength;
    }
  }
  // A receiver inside the slab, 250 m above its base: half the optical depth.
  s.strength = 1.0;
  s.receiver_altitude_m = 1250.0;
  for (float t : r->RenderCloudShadow(Sun(45.0), s))
    ASSERT_NEAR(t, std::exp(-0.5 / std::sin(glm::radians(45.0))), 2e-5);
  // A receiver above the layer: nothing above it, all ones.
  s.receiver_altitude_m = 2000.0;
  for (float t : r->RenderCloudShadow(Sun(45.0), s)) ASSERT_EQ(t, 1.0f);
  testing::ExpectNoValidationMessages();
}

// Zero coverage casts no shadow: a layer of coverage 0 (pruned) and a
// layer whose automaton clears every cloud (its coverage map is 0, the layer
// is marched) both give a map of ones; the sun below the horizon gives
// zeros (no direct sunlight), also at exactly 0 deg.
TEST(CloudShadow, NoCloudsAllOnesSunBelowHorizonAllZeros) {
  const CloudShadowSettings s{.enabled = true, .resolution = 16};
  const std::vector<float> ones(256, 1.0f), zeros(256, 0.0f);
  EXPECT_EQ(RendererOf(Style("[[cloud_layer]]\ncoverage = 0.0\n"))->RenderCloudShadow(Sun(40.0), s), ones);
  const SkyStyle cleared = Style(R"(
[quality]
preset = "draft"
[[cloud_layer]]
coverage = 0.5
[cloud_layer.formation]
enabled = true
cells = [16, 16, 4]
extinction_probability = 1.0
)");
  std::unique_ptr<SkyRenderer> r = RendererOf(cleared);
  EXPECT_EQ(r->RenderCloudShadow(Sun(40.0), s), ones);
  const SkyStyle slab = Style(kSlab);
  std::unique_ptr<SkyRenderer> rs = RendererOf(slab);
  EXPECT_EQ(rs->RenderCloudShadow(Sun(-6.0), s), zeros);
  EXPECT_EQ(rs->RenderCloudShadow(Sun(0.0) * glm::dvec3(1, 0, 1), s), zeros);
  testing::ExpectNoValidationMessages();
}

// The sun just above the horizon: the slant path is 1 / cos(zenith) times
// the thickness (a 0.5 deg sun crosses 57 km of a 500 m slab); the map
// stays finite in [0, 1] and follows the same law, here all but zero.
TEST(CloudShadow, SunAtTheHorizonStretchesTheShadow) {
  const SkyStyle style = Style(kSlab);
  std::unique_ptr<SkyRenderer> r = RendererOf(style);
  // tau 0.01 vertically: the horizon's long path still lets light through.
  const CloudShadowSettings s{.enabled = true, .resolution = 16, .strength = 0.01};
  const glm::dvec3 sun = Sun(0.5);
  for (float t : r->RenderCloudShadow(sun, s)) {
    ASSERT_TRUE(std::isfinite(t));
    ASSERT_NEAR(t, std::exp(-0.01 / sun.y), 1e-4);
  }
  testing::ExpectNoValidationMessages();
}

const char* kNoisy = R"(
[quality]
preset = "draft"
[[cloud_layer]]
altitude_m = 1500
thickness_m = 1500
coverage = 0.5
shape_size_m = 4000
detail_size_m = 400
weather_size_m = 8000
tiling = true
)";

// A map of a tiling layer (`tiling = true`) whose extent is a whole number
// of every tile (8 km: 2 shape tiles, 20 detail tiles, 1 weather tile) repeats: the map one extent east is the
// same map, and the map half an extent east is this one rolled by half its
// width, so its middle (where this map's east and west edges meet) is as
// continuous as the rest. An extent of 7 km does not tile.
TEST(CloudShadow, TilingMapWrapsWithoutASeam) {
  const SkyStyle style = Style(kNoisy);
  EXPECT_TRUE(CloudShadowTiles(PrunedStyle(style).clouds, 8000.0));
  EXPECT_FALSE(CloudShadowTiles(PrunedStyle(style).clouds, 7000.0));
  // The same layer read through the non-repeating warp (the default) never tiles.
  SkyStyle free_style = style;
  free_style.clouds.layers[0].tiling = false;
  EXPECT_FALSE(CloudShadowTiles(PrunedStyle(free_style).clouds, 8000.0));
  std::unique_ptr<SkyRenderer> r = RendererOf(style);
  CloudShadowSettings s{.enabled = true, .resolution = 64, .extent_m = 8000.0};
  const glm::dvec3 sun = Sun(50.0);
  const std::vector<float> a = r->RenderCloudShadow(sun, s);
  const auto [lo, hi] = std::minmax_element(a.begin(), a.end());
  EXPECT_LT(*lo, 0.5f);  // there are shadows and gaps: the test is not vacuous
  EXPECT_GT(*hi, 0.9f);
  s.center_east_m = 8000.0;
  const std::vector<float> whole = r->RenderCloudShadow(sun, s);
  s.center_east_m = 4000.0;
  const std::vector<float> half = r->RenderCloudShadow(sun, s);
  double worst_whole = 0.0, worst_half = 0.0, seam = 0.0, step = 0.0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      worst_whole = std::max(worst_whole, double(std::abs(whole[y * 64 + x] - a[y * 64 + x])));
      worst_half = std::max(worst_half, double(std::abs(half[y * 64 + x] - a[y * 64 + (x + 32) % 64])));
      const double d = std::abs(a[y * 64 + (x + 1) % 64] - a[y * 64 + x]);
      if (x == 63) seam = std::max(seam, d);
      else step = std::max(step, d);
    }
  EXPECT_LT(worst_whole, 2e-3);
  EXPECT_LT(worst_half, 2e-3);
  EXPECT_LT(seam, step);  // across the wrap no larger a jump than between neighbours inside
  // Not tiling: one extent east is another map.
  s.extent_m = 7000.0;
  s.center_east_m = 0.0;
  const std::vector<float> b = r->RenderCloudShadow(sun, s);
  s.center_east_m = 7000.0;
  const std::vector<float> c = r->RenderCloudShadow(sun, s);
  double differ = 0.0;
  for (size_t i = 0; i < b.size(); ++i) differ = std::max(differ, double(std::abs(b[i] - c[i])));
  EXPECT_GT(differ, 0.05);
  testing::ExpectNoValidationMessages();
}

// Velocity: an automaton whose lattice cells are the map's texels (32 x 32
// cells over 8 km; a 32-texel map of 8 km), frozen (0 steps per hour),
// drifting one cell east per hour: the map an hour later is the first map
// moved one texel (one cell's extent) east. With only the coverage map
// carrying the clouds (no shape or detail noise), to float rounding.
TEST(CloudShadow, OneCellOfDriftMovesTheMapOneCell) {
  const SkyStyle style = Style(SlabLayer("0.6", "0.004", "0.0") + R"([cloud_layer.formation]
enabled = true
cells = [32, 32, 4]
size_m = [8000.0, 8000.0]
origin_m = [-4000.0, -4000.0]
steps_per_hour = 0.0
warmup_steps = 40
phase_probability = 0.01
velocity_cells_per_hour = [1.0, 0.0, 0.0]
)");
  const CloudShadowSettings s{.enabled = true, .resolution = 32, .extent_m = 8000.0};
  const glm::dvec3 sun(0.0, 1.0, 0.0);  // overhead: the map is the clouds' own pattern
  std::unique_ptr<SkyRenderer> r = RendererOf(style, 0.0);
  const std::vector<float> t0 = r->RenderCloudShadow(sun, s);
  const SkyStyle pruned = PrunedStyle(style);
  ASSERT_TRUE(r->UpdateClouds(ToCloudInputs(pruned.clouds, pruned.aoas.seed, "", 3600.0)));
  const std::vector<float> t1 = r->RenderCloudShadow(sun, s);
  // The new coverage map was copied in; the noise volumes were built once.
  EXPECT_EQ(r->counters().cloud_noise_builds, 1);
  double moved = 0.0, unmoved = 0.0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      moved = std::max(moved, double(std::abs(t1[y * 32 + (x + 1) % 32] - t0[y * 32 + x])));
      unmoved = std::max(unmoved, double(std::abs(t1[y * 32 + x] - t0[y * 32 + x])));
    }
  EXPECT_LT(moved, 1e-4);
  EXPECT_GT(unmoved, 0.1);  // it did move
  // The record says where: the drift of one 250 m cell east.
  const CloudShadowInfo info = CloudShadowInfoOf(pruned.clouds, s, sun, 3600.0);
  ASSERT_EQ(info.wind_offset_m.size(), 1u);
  EXPECT_DOUBLE_EQ(info.wind_offset_m[0][0], 250.0);
  EXPECT_TRUE(info.tiles);
  testing::ExpectNoValidationMessages();
}

// The ground the sky shows below the horizon lies in the clouds' shadow:
// for an observer on the ground the ground texels see the ground at the
// observer's feet, sunlit through the slab: exp(-tau / cos) of the
// unshadowed ground (to the sky-view LUT's rendering of that ground); the
// sky above the horizon is unchanged, byte for byte; ground = false leaves
// the ground as it was.
TEST(CloudShadow, GroundBelowTheHorizonIsShadowed) {
  const SkyStyle style = PrunedStyle(Style(std::string(kSlab) + "[cloud_shadow]\nenabled = true\n"));
  const glm::dvec3 sun = Sun(40.0);
  auto render = [&](bool ground) {
    SkyStyle s = style;
    s.cloud_shadow.ground = ground;
    CloudInputs clouds = ToCloudInputs(s.clouds, s.aoas.seed, "", 0.0);
    ApplyGroundCloudShadow(s.cloud_shadow, clouds);
    SkyRenderer r(testing::Vulkan(), StyledAtmosphere(s.atmosphere, s.aoas), s.quality, s.effects,
                  OutputScale(s.output.units), false, ToAoasInputs(s.aoas, OutputScale(OutputUnits::kLuminance)),
                  clouds);
    return r.Render(sun, {{MAPPING_LATLONG, 64, 32, 0}})[0];
  };
  const std::vector<float> lit = render(false), shadowed = render(true);
  const double expected = std::exp(-1.0 / sun.y);
  int ground_texels = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c) {
        const size_t i = (size_t(y) * 64 + x) * 4 + c;
        if (y < 16) {
          ASSERT_EQ(shadowed[i], lit[i]) << x << " " << y;
        } else {
          ASSERT_NEAR(shadowed[i] / lit[i], expected, 0.03) << x << " " << y << " " << c;
          ++ground_texels;
        }
      }
  EXPECT_EQ(ground_texels, 16 * 64 * 3);
  testing::ExpectNoValidationMessages();
}

// The ground shadow and the shadow map beside the cloud panorama
// (cloud_panorama.h): the panorama sits in the cloud table buffer after
// CloudLutTexels, the ground shadow's strength and steps in their own
// GpuClouds.ground_shadow, the shadow map in the renderer's own output
// buffer, so none overwrites another. With the panorama on, the ground the
// -Y face shows (no cloud in front of it) is shadowed per texel exactly as
// when every view marches its own texels, the same bytes; and a shadow map
// rendered between two renders of the frame changes neither, nor do the
// frame's views change the next map.
TEST(CloudShadow, GroundShadowAndMapBesideTheCloudPanorama) {
  SkyStyle style = PrunedStyle(Style(std::string(kSlab) + "[cloud_shadow]\nenabled = true\nresolution = 32\n"));
  ASSERT_GT(style.clouds.quality.panorama_scale, 0.0);
  const glm::dvec3 sun = Sun(40.0);
  const int n = 32;
  std::vector<ViewRequest> views;
  for (int f = 0; f < 6; ++f) views.push_back({MAPPING_VULKAN_FACE, n, n, f});
  views.push_back({MAPPING_LATLONG, 4 * n, 2 * n, 0});
  ASSERT_GT(ChooseCloudPanorama(views, style.clouds.quality.panorama_scale).width, 0) << "the panorama is used";
  auto renderer = [&](double panorama_scale, bool ground) {
    SkyStyle s = style;
    s.clouds.quality.panorama_scale = panorama_scale;
    s.cloud_shadow.ground = ground;
    CloudInputs clouds = ToCloudInputs(s.clouds, s.aoas.seed, "", 0.0);
    ApplyGroundCloudShadow(s.cloud_shadow, clouds);
    return std::make_unique<SkyRenderer>(testing::Vulkan(), StyledAtmosphere(s.atmosphere, s.aoas), s.quality,
                                         s.effects, OutputScale(s.output.units), false,
                                         ToAoasInputs(s.aoas, OutputScale(OutputUnits::kLuminance)), clouds);
  };
  std::unique_ptr<SkyRenderer> panorama = renderer(style.clouds.quality.panorama_scale, true);
  const std::vector<std::vector<float>> first = panorama->Render(sun, views);
  const std::vector<float> map = panorama->RenderCloudShadow(sun, style.cloud_shadow);
  const std::vector<std::vector<float>> second = panorama->Render(sun, views);
  EXPECT_TRUE(first == second) << "the shadow map left the frame's views as they were";
  EXPECT_TRUE(map == panorama->RenderCloudShadow(sun, style.cloud_shadow)) << "the views left the map as it was";
  const double expected = std::exp(-1.0 / sun.y);
  for (float t : map) ASSERT_NEAR(t, expected, 2e-5);

  const std::vector<std::vector<float>> direct = renderer(0.0, true)->Render(sun, views);
  const std::vector<std::vector<float>> lit = renderer(style.clouds.quality.panorama_scale, false)->Render(sun, views);
  EXPECT_TRUE(first[3] == direct[3]) << "-Y face: the ground, shadowed per texel in both";
  for (size_t i = 0; i < first[3].size(); i += 4)
    for (size_t c = 0; c < 3; ++c) ASSERT_NEAR(first[3][i + c] / lit[3][i + c], expected, 0.03) << i;
  testing::ExpectNoValidationMessages();
}

// A formation that supplies the layer's whole density (formation.density):
// a lattice that is cloud everywhere (humidity and transition always,
// extinction never) makes the layer a uniform slab whatever its shape
// noise, so the map is exp(-tau / cos) at every texel; the same lattice
// supplying the coverage only leaves the shape noise carving the layer.
TEST(CloudShadow, FormationSuppliesTheWholeDensity) {
  const std::string toml = SlabLayer("1.0", "0.002", "1.0") + R"([cloud_layer.formation]
enabled = true
cells = [8, 8, 4]
warmup_steps = 4
extinction_probability = 0.0
humidity_probability = 1.0
phase_probability = 1.0
initial_humidity = 1.0
DENSITY
[cloud_shadow]
enabled = true
resolution = 32
)";
  auto map_of = [&](bool density) {
    std::string t = toml;
    t.replace(t.find("DENSITY"), 7, density ? "density = true" : "density = false");
    const SkyStyle style = PrunedStyle(Style(t));
    return RendererOf(style)->RenderCloudShadow(Sun(40.0), style.cloud_shadow);
  };
  const std::vector<float> whole = map_of(true), coverage = map_of(false);
  const double expected = std::exp(-1.0 / Sun(40.0).y);
  for (float t : whole) ASSERT_NEAR(t, expected, 2e-5);
  const auto [lo, hi] = std::minmax_element(coverage.begin(), coverage.end());
  EXPECT_GT(*hi - *lo, 0.05) << "with the coverage only, the shape noise carves the layer";
  testing::ExpectNoValidationMessages();
}

// A bake writes BASE_cloudshadow.exr (frame-numbered in a sequence) with
// its placement in the header and in manifest.json, and the shadow map
// changes nothing else: the sky files are the same bytes as without it but
// for the resolved style recorded in their headers.
TEST(CloudShadowFile, HeaderAndManifestSayWhereTheMapLies) {
  const std::string root = testing::FreshTempDir("cloud_shadow_file");
  const std::string style = root + "/style.toml";
  std::ofstream(style) << std::string(kSlab) + R"(
[sun]
elevation_deg = 30.0
azimuth_deg = 180.0
[cloud_shadow]
enabled = true
resolution = 16
extent_m = 2000.0
center_east_m = 100.0
receiver_altitude_m = 20.0
)";
  testing::CommandRun run =
      testing::RunSkybake("bake '" + style + "' --size 16 -q --vulkan-validation --out '" + root + "/out'");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string path = root + "/out/sky_cloudshadow.exr";
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in) << path;
  const OIIO::ImageSpec& spec = in->spec();
  EXPECT_EQ(spec.width, 16);
  EXPECT_EQ(spec.height, 16);
  EXPECT_EQ(spec.get_string_attribute("skybake:shadow:extent_m"), "2000");
  EXPECT_TRUE(std::string(spec.get_string_attribute("skybake:shadow:origin_m")).starts_with("-900 20 -1000"))
      << spec.get_string_attribute("skybake:shadow:origin_m");
  EXPECT_TRUE(std::string(spec.get_string_attribute("skybake:shadow:axis_u")).starts_with("1 0 0"));
  EXPECT_TRUE(std::string(spec.get_string_attribute("skybake:shadow:axis_v")).starts_with("0 0 1"));
  EXPECT_EQ(spec.get_string_attribute("skybake:shadow:receiver_alt_m"), "20");
  EXPECT_EQ(spec.get_string_attribute("skybake:shadow:tiles"), "false");  // 2 km: not whole 4 km shape tiles
  EXPECT_FALSE(spec.get_string_attribute("skybake:shadow:sun_direction").empty());
  const std::vector<std::string> sun_text = [&] {
    std::vector<std::string> v;
    std::istringstream s(std::string(spec.get_string_attribute("skybake:shadow:sun_direction")));
    for (std::string w; s >> w;) v.push_back(w);
    return v;
  }();
  std::vector<float> pixels(16 * 16 * spec.nchannels);
  ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data()));
  in->close();
  // Sun 30 deg: exp(-1 / sin 30 deg), the slab's tau 1 along its slant path.
  ASSERT_EQ(sun_text.size(), 3u);
  const double sun_y = std::stod(sun_text[1]);
  EXPECT_NEAR(sun_y, 0.5, 1e-6);
  for (int i = 0; i < 256; ++i) EXPECT_NEAR(pixels[i * spec.nchannels], std::exp(-1.0 / sun_y), 2e-5);
  std::ifstream manifest_file(root + "/out/manifest.json");
  const nlohmann::json manifest = nlohmann::json::parse(manifest_file);
  const nlohmann::json& frame = manifest["frames"][0];
  ASSERT_TRUE(frame.contains("cloud_shadow"));
  EXPECT_EQ(frame["cloud_shadow"]["extent_m"].get<double>(), 2000.0);
  EXPECT_EQ(frame["cloud_shadow"]["origin_m"][0].get<double>(), -900.0);
  EXPECT_EQ(frame["cloud_shadow"]["receiver_altitude_m"].get<double>(), 20.0);
  EXPECT_FALSE(frame["cloud_shadow"]["tiles"].get<bool>());
  bool listed = false;
  for (const nlohmann::json& f : frame["files"])
    listed = listed || (f["file"] == "sky_cloudshadow.exr" && f["kind"] == "cloud_shadow");
  EXPECT_TRUE(listed);
  std::filesystem::remove_all(root);
}

// The glTF scene carries a ground plane textured with the cloud shadow map
// (gltf_scene.h "ground"), validator-clean: node "cloud_shadow_ground", a
// square whose UV (0, 0) corner is the map's origin and (1, 1) corner its
// origin + extent (axis_u + axis_v); its base colour texture sky_ground.png
// is the EXR's transmittance sRGB-encoded texel for texel (row 0 north);
// the manifest lists it with the scene. Without [cloud_shadow]: no plane.
TEST(CloudShadowFile, GltfGroundPlaneCarriesTheMap) {
  const std::string root = testing::FreshTempDir("cloud_shadow_gltf");
  const std::string style = testing::SourceDir() + "/configs/styles/afternoon_buildup.toml";
  testing::CommandRun run = testing::RunSkybake("bake '" + style +
                                                "' --size 16 -q --vulkan-validation "
                                                "--set cloud_shadow.resolution=32 --out '" +
                                                root + "/out'");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string out = root + "/out";
  auto [status, report] = testing::RunCommand("cd '" + testing::SourceDir() + "/tests/viewer' && node validate.mjs '" +
                                              out + "/sky.gltf' '" + out + "/sky.glb'");
  EXPECT_EQ(status, 0) << report;
  EXPECT_NE(report.find("sky.gltf: 0 errors, 0 warnings"), std::string::npos) << report;
  EXPECT_NE(report.find("sky.glb: 0 errors, 0 warnings"), std::string::npos) << report;

  const nlohmann::json manifest = nlohmann::json::parse(std::ifstream(out + "/manifest.json"));
  const nlohmann::json& info = manifest["frames"][0]["cloud_shadow"];
  bool listed = false;
  for (const nlohmann::json& f : manifest["scene"])
    listed = listed || (f["file"] == "sky_ground.png" && f["kind"] == "gltf_ground");
  EXPECT_TRUE(listed) << manifest["scene"].dump();

  const nlohmann::json gltf = nlohmann::json::parse(std::ifstream(out + "/sky.gltf"));
  int node = -1;
  for (size_t i = 0; i < gltf["nodes"].size(); ++i)
    if (gltf["nodes"][i].value("name", "") == "cloud_shadow_ground") node = int(i);
  ASSERT_GE(node, 0) << gltf["nodes"].dump();
  bool in_scene = false;
  for (const nlohmann::json& n : gltf["scenes"][0]["nodes"]) in_scene = in_scene || n.get<int>() == node;
  EXPECT_TRUE(in_scene);
  const nlohmann::json& primitive = gltf["meshes"][gltf["nodes"][node]["mesh"].get<int>()]["primitives"][0];
  const nlohmann::json& material = gltf["materials"][primitive["material"].get<int>()];
  const int texture = material["pbrMetallicRoughness"]["baseColorTexture"]["index"];
  const int image = gltf["textures"][texture]["source"];
  EXPECT_EQ(gltf["images"][image]["uri"], "sky_ground.png");
  EXPECT_FALSE(material.contains("extensions")) << "lit, not unlit";

  // The corners: read POSITION and TEXCOORD_0 from sky.bin.
  std::ifstream bin_file(out + "/sky.bin", std::ios::binary);
  const std::string bin((std::istreambuf_iterator<char>(bin_file)), std::istreambuf_iterator<char>());
  auto floats = [&](const std::string& attribute, int components) {
    const nlohmann::json& a = gltf["accessors"][primitive["attributes"][attribute].get<int>()];
    const nlohmann::json& view = gltf["bufferViews"][a["bufferView"].get<int>()];
    std::vector<float> v(a["count"].get<size_t>() * components);
    std::memcpy(v.data(), bin.data() + view.value("byteOffset", size_t(0)) + a.value("byteOffset", size_t(0)),
                v.size() * 4);
    return v;
  };
  const std::vector<float> positions = floats("POSITION", 3), uvs = floats("TEXCOORD_0", 2);
  ASSERT_EQ(positions.size(), 12u);
  const double extent = info["extent_m"];
  for (int k = 0; k < 4; ++k)
    for (int c = 0; c < 3; ++c) {
      const double expected =
          info["origin_m"][c].get<double>() +
          extent * (uvs[2 * k] * info["axis_u"][c].get<double>() + uvs[2 * k + 1] * info["axis_v"][c].get<double>());
      EXPECT_NEAR(positions[3 * k + c], expected, 1e-3 * extent) << "corner " << k << " axis " << c;
    }
  using Uv = std::pair<float, float>;
  const std::set<Uv> corners = {{uvs[0], uvs[1]}, {uvs[2], uvs[3]}, {uvs[4], uvs[5]}, {uvs[6], uvs[7]}};
  const std::set<Uv> unit_square = {{0.f, 0.f}, {1.f, 0.f}, {0.f, 1.f}, {1.f, 1.f}};
  EXPECT_EQ(corners, unit_square);

  // The texture is the map, texel for texel.
  auto read = [](const std::string& path, OIIO::TypeDesc type, int& channels) {
    std::vector<float> v;
    auto in = OIIO::ImageInput::open(path);
    EXPECT_TRUE(in) << path;
    if (!in) return v;
    channels = in->spec().nchannels;
    v.resize(size_t(in->spec().width) * in->spec().height * channels);
    if (type == OIIO::TypeDesc::UINT8) {
      std::vector<uint8_t> bytes(v.size());
      in->read_image(0, 0, 0, channels, type, bytes.data());
      v.assign(bytes.begin(), bytes.end());
    } else {
      in->read_image(0, 0, 0, channels, type, v.data());
    }
    return v;
  };
  int exr_channels = 0, png_channels = 0;
  const std::vector<float> map = read(out + "/sky_cloudshadow.exr", OIIO::TypeDesc::FLOAT, exr_channels);
  const std::vector<float> png = read(out + "/sky_ground.png", OIIO::TypeDesc::UINT8, png_channels);
  ASSERT_EQ(map.size() / exr_channels, 32u * 32u);
  ASSERT_EQ(png.size() / png_channels, 32u * 32u);
  float lo = 1.0f, hi = 0.0f;
  for (size_t i = 0; i < 32 * 32; ++i) {
    const float t = map[i * exr_channels];
    lo = std::min(lo, t), hi = std::max(hi, t);
    ASSERT_EQ(png[i * png_channels], std::lround(SrgbEncode(std::clamp(double(t), 0.0, 1.0)) * 255.0)) << i;
  }
  EXPECT_LT(lo, hi) << "the map has structure (broken clouds)";

  // Without the shadow map: no ground plane, no PNG.
  testing::CommandRun off = testing::RunSkybake(
      "bake '" + style + "' --size 16 -q --set cloud_shadow.enabled=false --out '" + root + "/off'");
  ASSERT_EQ(off.exit_code, 0) << off.output;
  EXPECT_FALSE(std::filesystem::exists(root + "/off/sky_ground.png"));
  const std::string off_gltf = nlohmann::json::parse(std::ifstream(root + "/off/sky.gltf")).dump();
  EXPECT_EQ(off_gltf.find("cloud_shadow_ground"), std::string::npos);
  std::filesystem::remove_all(root);
}

// In a sequence the maps are frame-numbered, merge-manifest keeps their
// records, and parts give the whole bake's maps byte for byte.
TEST(CloudShadowFile, SequenceMapsAreNumberedAndPartsMatch) {
  const std::string root = testing::FreshTempDir("cloud_shadow_sequence");
  const std::string style = root + "/style.toml", schedule = root + "/schedule.toml";
  std::ofstream(style) << std::string(kNoisy) + R"(
wind_m_s = [20.0, 0.0]
[cloud_shadow]
enabled = true
resolution = 32
extent_m = 8000.0
)";
  std::ofstream(schedule) << testing::IthacaSchedule("12:00:00", "12:30:00", 15);
  ASSERT_EQ(testing::BakeWholeAndTwoShards(style, schedule, root, "parts"), 0);
  for (int n = 1; n <= 3; ++n) {
    const std::string name = fmt::format("sky_cloudshadow.{:04d}.exr", n);
    ASSERT_TRUE(std::filesystem::exists(root + "/whole/" + name)) << name;
    EXPECT_TRUE(testing::ReadFileBytes(root + "/parts/" + name) == testing::ReadFileBytes(root + "/whole/" + name))
        << name;
  }
  EXPECT_NE(testing::ReadFileBytes(root + "/whole/sky_cloudshadow.0001.exr"),
            testing::ReadFileBytes(root + "/whole/sky_cloudshadow.0002.exr"));
  EXPECT_EQ(testing::ReadFileBytes(root + "/parts/manifest.json"),
            testing::ReadFileBytes(root + "/whole/manifest.json"));
  std::filesystem::remove_all(root);
}

// An attribute OpenEXR refuses (a name longer than its 31 characters) is an
// OutputError naming the file, not a hang (the encoder's error handler once
// asked the locked context for its user data).
TEST(CloudShadowFile, AnEncoderErrorIsReportedNotHung) {
  RgbaImage image;
  image.width = image.height = 2;
  image.rgba.assign(16, 0.5f);
  ExrWriteOptions options;
  options.attributes["skybake:" + std::string(40, 'x')] = "value";
  try {
    EncodeExr("long_name.exr", image, options);
    ADD_FAILURE() << "no error";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("long_name.exr"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace skybake
