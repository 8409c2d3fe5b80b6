// The night sky in the maps (night_sky.h): the energy-conserving splat, the
// texel solid angles, the transmittance table, the Moon's disc, and bakes of
// a night schedule on lavapipe under the validation layer (moonlit sky,
// manifest, glTF, SH, bad input, byte identity when off).
#include "skybake/pipeline/night_sky.h"
#include "skybake/pipeline/night_prune.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <cstring>
#include <ctime>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <OpenImageIO/imageio.h>

#include "skybake/input/config.h"
#include "skybake/input/ephemeris.h"
#include "skybake/pipeline/pass_plan.h"
#include "skybake/pipeline/pipeline.h"
#include "skybake/tools/reference_model.h"
#include "skybake/input/schedule.h"
#include "skybake/model/spectrum.h"
#include "skybake/model/view.h"
#include "test_support.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::RunCommand;
using testing::RunSkybake;
using testing::SourceDir;

std::vector<ViewRequest> ViewsOfSize(int n) {
  std::vector<ViewRequest> views;
  for (int face = 0; face < 6; ++face) views.push_back({MAPPING_VULKAN_FACE, n, n, face});
  views.push_back({MAPPING_CUBE_STRIP, n, 6 * n, 0});
  views.push_back({MAPPING_LATLONG, 2 * n, n, 0});
  return views;
}

// A style with the stars, the Moon, the airglow and the night floor on.
SkyStyle EveryNightFeature() {
  SkyStyle style;
  style.night.stars = true;
  style.night.moon = true;
  style.night.airglow = true;
  style.effects.night_dimming = true;
  return style;
}

// The shipped star catalogue; a test that cannot load it fails with the reason.
std::optional<StarCatalogue> DefaultCatalogue() {
  std::string error;
  std::optional<StarCatalogue> catalogue = LoadStarCatalogue(DefaultStarCataloguePath(), error);
  EXPECT_TRUE(catalogue) << error;
  return catalogue;
}

// Energy (sum of radiance x solid angle) per channel of the additions.
glm::dvec3 Energy(const ViewRequest& view, const std::vector<TexelAdd>& adds) {
  glm::dvec3 e(0.0);
  for (const TexelAdd& a : adds) {
    const int x = int(a.texel % view.width), y = int(a.texel / view.width);
    const double omega = ViewTexelSolidAngle(view, x, y);
    for (int c = 0; c < 3; ++c) e[c] += double(a.rgb[c]) * omega;
  }
  return e;
}

TEST(NightSky, TexelSolidAnglesCoverTheSphere) {
  for (int n : {4, 64, 257}) {
    for (const ViewRequest& v :
         {ViewRequest{MAPPING_CUBE_STRIP, n, 6 * n, 0}, ViewRequest{MAPPING_LATLONG, 2 * n, n, 0}}) {
      double sum = 0.0;
      for (int y = 0; y < v.height; ++y)
        for (int x = 0; x < v.width; ++x) sum += ViewTexelSolidAngle(v, x, y);
      EXPECT_NEAR(sum, 4.0 * M_PI, 1e-9) << v.mapping << " " << n;
    }
    double faces = 0.0;
    for (int face = 0; face < 6; ++face)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) faces += ViewTexelSolidAngle({MAPPING_VULKAN_FACE, n, n, face}, x, y);
    EXPECT_NEAR(faces, 4.0 * M_PI, 1e-9) << n;
  }
}

// Each star's energy is its irradiance at cube sizes 64, 256 and 1024, in
// every layout; its splat's centroid is its direction.
TEST(NightSky, StarEnergyIsTheSameAtEveryResolution) {
  const std::vector<glm::dvec3> directions = {
      glm::normalize(glm::dvec3(0.3, 0.8, -0.2)), glm::normalize(glm::dvec3(1.0, 0.999, 0.2)),      // near a cube edge
      glm::normalize(glm::dvec3(-0.5, 0.05, 0.9)), glm::normalize(glm::dvec3(0.001, 1.0, -0.002)),  // near the pole
      glm::normalize(glm::dvec3(-1e-4, 0.3, -1.0))};  // at the latlong's seam
  for (const glm::dvec3& d : directions) {
    const PointSource star{d, {2.0e-6, 3.0e-6, 5.0e-6}};
    for (int n : {64, 256, 1024}) {
      glm::dvec3 cube_total(0.0);
      for (const ViewRequest& v : ViewsOfSize(n)) {
        const std::vector<TexelAdd> adds = SplatPointSources(v, {star});
        const glm::dvec3 e = Energy(v, adds);
        if (v.mapping == MAPPING_VULKAN_FACE) {
          cube_total += e;
          continue;
        }
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(e[c] / star.irradiance[c], 1.0, 1e-6) << v.mapping << " " << n;
        // Centroid of the splat: within a texel of the star.
        glm::dvec3 centroid(0.0);
        for (const TexelAdd& a : adds) {
          const int x = int(a.texel % v.width), y = int(a.texel / v.width);
          if (v.mapping == MAPPING_LATLONG && x == v.width - 1) continue;  // the repeated meridian
          centroid += double(a.rgb[1]) * ViewTexelSolidAngle(v, x, y) * ViewTexelDirection(v, x, y);
        }
        const double angle = std::acos(std::min(1.0, glm::dot(glm::normalize(centroid), d)));
        EXPECT_LT(angle, 2.0 * M_PI / n) << v.mapping << " " << n;
      }
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(cube_total[c] / star.irradiance[c], 1.0, 1e-6) << "faces " << n;
    }
  }
}

// A star moving by a tenth of a texel per frame: its energy stays put and its
// brightest texel's value changes smoothly (no popping between frames).
TEST(NightSky, MovingStarDoesNotAlias) {
  const ViewRequest v{MAPPING_LATLONG, 256, 128, 0};
  double previous_peak = -1.0;
  double largest_jump = 0.0;
  for (int step = 0; step < 40; ++step) {
    const double azimuth = 30.0 + step * (360.0 / 255.0) * 0.1;
    const PointSource star{SunDirectionFromElevationAzimuth(40.0, azimuth), {1.0, 1.0, 1.0}};
    const std::vector<TexelAdd> adds = SplatPointSources(v, {star});
    EXPECT_NEAR(Energy(v, adds).y, 1.0, 1e-6);
    double peak = 0.0;
    for (const TexelAdd& a : adds)
      peak = std::max(peak, double(a.rgb[1]) * ViewTexelSolidAngle(v, int(a.texel % v.width), int(a.texel / v.width)));
    if (previous_peak >= 0.0) largest_jump = std::max(largest_jump, std::abs(peak - previous_peak));
    previous_peak = peak;
  }
  // Bilinear weights move by at most 0.1 x 2 (both axes) per step.
  EXPECT_LT(largest_jump, 0.25);
}

TEST(NightSky, TransmittanceTableMatchesTheSharedIntegral) {
  AtmosphereParams atmosphere;
  const TransmittanceTable table(atmosphere, QualitySettings(), EffectSettings());
  const ReferenceModel model(atmosphere, QualitySettings(), EffectSettings(), {1.0, 1.0, 1.0});
  for (double mu : {1.0, 0.7, 0.2, 0.05, 0.01}) {
    const Rgb t = table.At(mu);
    const glm::dvec3 direct = model.TransmittanceDirect(0.0, mu, 256);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(t[c] / direct[c], 1.0, 2e-3) << mu;
  }
  for (double c : table.At(-0.01)) EXPECT_EQ(c, 0.0);  // behind the ground
  // Blue is attenuated more than red (Rayleigh).
  EXPECT_LT(table.At(0.2)[2], table.At(0.2)[0]);
}

TEST(NightSky, MoonDiscIsLitOnTheSunsSide) {
  const glm::dvec3 moon = glm::normalize(glm::dvec3(0.0, 0.6, -0.8));
  const Rgb total = {1.0, 2.0, 3.0};
  const double rho = 0.0045;
  // Full: the Sun behind the observer; Lommel-Seeliger makes the disc uniform.
  const std::vector<PointSource> full = MoonDiscSources(moon, rho, -moon, total, 64);
  glm::dvec3 sum(0.0);
  double lo = 1e30, hi = 0.0;
  for (const PointSource& p : full) {
    for (int c = 0; c < 3; ++c) sum[c] += p.irradiance[c];
    lo = std::min(lo, p.irradiance[0]);
    hi = std::max(hi, p.irradiance[0]);
    EXPECT_LT(std::acos(std::min(1.0, glm::dot(p.direction, moon))), rho * 1.0001);
  }
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], total[c], 1e-9);
  EXPECT_NEAR(lo / hi, 1.0, 1e-9);
  EXPECT_GT(full.size(), 3000u);
  // Quarter: the Sun 90 deg away, towards +X: the lit half is on the +X side.
  const std::vector<PointSource> quarter = MoonDiscSources(moon, rho, {1.0, 0.0, 0.0}, total, 64);
  glm::dvec3 centroid(0.0);
  double energy = 0.0;
  for (const PointSource& p : quarter) {
    centroid += p.irradiance[0] * p.direction;
    energy += p.irradiance[0];
    EXPECT_GT(glm::dot(p.direction - moon, glm::dvec3(1, 0, 0)), -1e-12);
  }
  EXPECT_NEAR(energy, total[0], 1e-9);
  EXPECT_GT(glm::dot(centroid / energy - moon, glm::dvec3(1, 0, 0)), 0.3 * rho);
  // New: the Sun behind the Moon, nothing lit (no earthshine).
  EXPECT_TRUE(MoonDiscSources(moon, rho, moon, total, 64).empty());
}

// van Rhijn: the glow's zenith value is the given luminance, it brightens
// towards the horizon until the extinction wins, and is zero behind the ground.
TEST(NightSky, AirglowBrightensTowardsTheHorizon) {
  AtmosphereParams atmosphere;
  const TransmittanceTable t(atmosphere, QualitySettings(), EffectSettings());
  const std::vector<Rgb> table = AirglowTable(atmosphere, t, 90.0, 1.7e-4, OutputUnits::kLuminance);
  auto luminance = [&](double mu) {
    const Rgb a = AirglowAt(table, mu);
    return 0.2126 * a[0] + 0.7152 * a[1] + 0.0722 * a[2];
  };
  EXPECT_NEAR(luminance(1.0) / 1.7e-4, 1.0, 1e-9);
  // At 60 deg from the zenith: van Rhijn 1 / sqrt(1 - (6360/6450)^2 0.75) = 1.88, less extinction.
  const double r = 6360.0 / 6450.0;
  const double v60 = 1.0 / std::sqrt(1.0 - r * r * 0.75);
  const Rgb t60 = t.At(0.5), t0 = t.At(1.0);
  const double expected =
      1.7e-4 * v60 * (0.2126 * t60[0] / t0[0] * 1 + 0.7152 * t60[1] / t0[1] + 0.0722 * t60[2] / t0[2]);
  EXPECT_NEAR(luminance(0.5) / expected, 1.0, 2e-3);
  EXPECT_GT(luminance(std::sin(15.0 * M_PI / 180.0)), 1.5 * luminance(1.0));
  EXPECT_EQ(luminance(-0.01), 0.0);
  for (int i = 0; i < kAirglowEntries; ++i)
    for (double c : table[i]) EXPECT_GE(c, 0.0);
}

TEST(NightSky, OffKeysResolveAsBefore) {
  const ConfigResult plain = ParseSkyStyle("", "plain.toml");
  const ConfigResult off = ParseSkyStyle("[night]\nstars = false\nmoon = false\nmoonlight = false\n", "plain.toml");
  ASSERT_TRUE(plain.ok() && off.ok());
  EXPECT_EQ(plain.style.resolved_toml, off.style.resolved_toml);
  EXPECT_EQ(plain.style.resolved_toml.find("[night]"), std::string::npos);
  const ConfigResult on = ParseSkyStyle("[night]\nstars = true\n", "on.toml");
  ASSERT_TRUE(on.ok());
  EXPECT_NE(on.style.resolved_toml.find("star_magnitude_limit"), std::string::npos);
  const ConfigResult bad = ParseSkyStyle("[night]\nstar_magnitude_limit = 15.0\n", "bad.toml");
  ASSERT_EQ(bad.errors.size(), 1u);
  EXPECT_EQ(bad.errors[0].Format(), "bad.toml:2:24: night.star_magnitude_limit: 15 is out of range [-1.5, 14]");
}

// --- Bakes on lavapipe

// A night at Cerro Paranal under the full moon (configs/schedules/night.toml):
// 21:00 (Moon 37 deg up, the Sun -37), and frames made for the hard cases.
// Nights at Cerro Paranal (configs/schedules/night.toml): dusk at first
// quarter with the Sun just up and then just down and the Moon high (frames 1,
// 2), the full moon 37 deg up (3), after midnight (4), the full moon setting
// through the horizon at dawn (5).
constexpr const char* kNightSchedule = R"([schedule]
date = 2024-04-23
latitude_deg = -24.6272
longitude_deg = -70.4042
utc_offset_hours = -4.0
[[schedule.frames]]
date = 2024-04-15
time = 18:20:00
[[schedule.frames]]
date = 2024-04-15
time = 18:50:00
[[schedule.frames]]
time = 21:00:00
[[schedule.frames]]
date = 2024-04-24
time = 01:00:00
[[schedule.frames]]
date = 2024-04-24
time = 07:22:00
)";

class NightBake : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = testing::FreshTempDir("night_bake");
    std::ofstream(dir_ + "/night.toml") << kNightSchedule;
    std::ofstream(dir_ + "/style.toml") << "[effects]\nnight_dimming = true\n[night]\nstars = true\nmoon = true\n"
                                           "moonlight = true\n[output]\npixel_type = \"float\"\n";
    run_ = RunSkybake(fmt::format("bake '{0}/style.toml' --schedule '{0}/night.toml' --size 64 --out '{0}/out' "
                                  "--quiet",
                                  dir_),
                      "SKYBAKE_VULKAN_VALIDATION=1");
    moonless_ = RunSkybake(fmt::format("bake '{0}/style.toml' --schedule '{0}/night.toml' --size 64 --out '{0}/plain' "
                                       "--quiet --frames 3:3 --set night.moonlight=false "
                                       "--set night.moon=false --set night.stars=false",
                                       dir_),
                           "SKYBAKE_VULKAN_VALIDATION=1");
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static std::vector<float> ReadExr(const std::string& path, int& w, int& h) {
    auto in = OIIO::ImageInput::open(path);
    EXPECT_TRUE(in) << path;
    if (!in) return {};
    const OIIO::ImageSpec& spec = in->spec();
    w = spec.width;
    h = spec.height;
    std::vector<float> pixels(size_t(w) * h * spec.nchannels);
    in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data());
    // As RGBA, whatever the file's channels.
    std::vector<float> rgba(size_t(w) * h * 4, 1.0f);
    for (size_t i = 0; i < size_t(w) * h; ++i)
      for (int c = 0; c < std::min(spec.nchannels, 4); ++c) rgba[4 * i + c] = pixels[i * spec.nchannels + c];
    return rgba;
  }

  static std::string dir_;
  static testing::CommandRun run_, moonless_;
};
std::string NightBake::dir_;
testing::CommandRun NightBake::run_, NightBake::moonless_;

TEST_F(NightBake, BakesWithoutValidationMessages) {
  EXPECT_EQ(run_.exit_code, 0) << run_.output;
  EXPECT_EQ(moonless_.exit_code, 0) << moonless_.output;
}

// Midnight, dusk with the Sun and the Moon both up, the Moon on the horizon:
// every texel of every map finite and non-negative (the hard cases).
TEST_F(NightBake, NoNanInfOrNegativeAtMidnightDuskAndMoonOnTheHorizon) {
  ASSERT_EQ(run_.exit_code, 0) << run_.output;
  const json manifest = json::parse(std::ifstream(dir_ + "/out/manifest.json"));
  ASSERT_EQ(manifest["frames"].size(), 5u);
  auto elevation = [&](int i, const char* body) { return manifest["frames"][i][body]["elevation_deg"].get<double>(); };
  EXPECT_GT(elevation(0, "sun"), 0.0);  // dusk, the Sun up
  EXPECT_GT(elevation(0, "moon"), 30.0);
  EXPECT_LT(elevation(1, "sun"), 0.0);  // the Sun just down, the Moon up: both lights
  EXPECT_GT(elevation(1, "sun"), -10.0);
  EXPECT_GT(elevation(1, "moon"), 30.0);
  EXPECT_LT(elevation(3, "sun"), -60.0);           // after midnight
  EXPECT_LT(std::abs(elevation(4, "moon")), 1.0);  // the Moon on the horizon
  for (int frame = 1; frame <= 5; ++frame)
    for (const char* name : {"sky_latlong", "sky_cube", "sky_px", "sky_nz", "sky_py"}) {
      int w = 0, h = 0;
      const std::vector<float> px = ReadExr(fmt::format("{}/out/{}.{:04d}.exr", dir_, name, frame), w, h);
      ASSERT_FALSE(px.empty());
      size_t bad = 0;
      for (float v : px) bad += !std::isfinite(v) || v < 0.0f;
      EXPECT_EQ(bad, 0u) << name << " frame " << frame;
    }
}

TEST_F(NightBake, ManifestRecordsTheMoonPerFrame) {
  ASSERT_EQ(run_.exit_code, 0) << run_.output;
  const json manifest = json::parse(std::ifstream(dir_ + "/out/manifest.json"));
  const json& moon = manifest["frames"][2]["moon"];
  EXPECT_NEAR(moon["elevation_deg"].get<double>(), 37.0, 1.5);
  EXPECT_LT(moon["phase_angle_deg"].get<double>(), 3.0);
  EXPECT_GT(moon["illuminated_fraction"].get<double>(), 0.99);
  // Krisciunas & Schaefer: 0.1..0.3 lux on the ground from a high full moon.
  EXPECT_GT(moon["illuminance_lux"].get<double>(), 0.1);
  EXPECT_LT(moon["illuminance_lux"].get<double>(), 0.3);
  EXPECT_TRUE(moon["light"].get<bool>());
  glm::dvec3 d(moon["direction"][0].get<double>(), moon["direction"][1].get<double>(),
               moon["direction"][2].get<double>());
  EXPECT_NEAR(glm::length(d), 1.0, 1e-9);
  // The SH with the lights has the Moon in it: brighter towards the Moon than without.
  const json& f = manifest["frames"][2];
  EXPECT_GT(f["sh_irradiance_with_sun"][0][1].get<double>(), f["sh_irradiance_without_sun"][0][1].get<double>());
  // The moonless style's manifest has no moon entry.
  const json plain = json::parse(std::ifstream(dir_ + "/plain/manifest.shard-0003-0003.json"));
  EXPECT_FALSE(plain["frames"][0].contains("moon"));
}

// Moonlight: a dim blue sky, far brighter than the same night without the
// Moon; the Moon's disc and the stars in the map.
TEST_F(NightBake, MoonlitSkyIsADimBlueSky) {
  ASSERT_EQ(run_.exit_code, 0) << run_.output;
  ASSERT_EQ(moonless_.exit_code, 0) << moonless_.output;
  int w = 0, h = 0;
  const std::vector<float> lit = ReadExr(dir_ + "/out/sky_latlong.0003.exr", w, h);
  const std::vector<float> dark = ReadExr(dir_ + "/plain/sky_latlong.0003.exr", w, h);
  ASSERT_EQ(lit.size(), dark.size());
  // The zenith (row 0): blue over red, 1e-3..1e-1 cd/m^2 (a moonlit sky is
  // about 1e-6 of a daylit one), over ten times the night floor alone.
  const int x = w / 4, y = h / 6;  // 60 deg up
  const float* l = &lit[(size_t(y) * w + x) * 4];
  const float* d = &dark[(size_t(y) * w + x) * 4];
  EXPECT_GT(l[2], l[0]);
  const double lum = 0.2126 * l[0] + 0.7152 * l[1] + 0.0722 * l[2];
  EXPECT_GT(lum, 1e-3);
  EXPECT_LT(lum, 1e-1);
  EXPECT_GT(lum, 10.0 * (0.2126 * d[0] + 0.7152 * d[1] + 0.0722 * d[2]));
  // The Moon's disc: the brightest texel is near the Moon's direction.
  size_t brightest = 0;
  for (size_t i = 0; i < lit.size() / 4; ++i)
    if (lit[4 * i + 1] > lit[4 * brightest + 1]) brightest = i;
  const json manifest = json::parse(std::ifstream(dir_ + "/out/manifest.json"));
  const json& md = manifest["frames"][2]["moon"]["direction"];
  const glm::dvec3 moon(md[0].get<double>(), md[1].get<double>(), md[2].get<double>());
  const glm::dvec3 at = ViewTexelDirection({MAPPING_LATLONG, w, h, 0}, int(brightest % w), int(brightest / w));
  EXPECT_LT(std::acos(std::min(1.0, glm::dot(at, moon))), 3.0 * M_PI / h)
      << "brightest " << brightest % w << "," << brightest / w << " " << at.x << " " << at.y << " " << at.z << " moon "
      << moon.x << " " << moon.y << " " << moon.z << " value " << lit[4 * brightest + 1];
}

TEST_F(NightBake, GltfHasTheMoonAsASecondLightAndValidates) {
  ASSERT_EQ(run_.exit_code, 0) << run_.output;
  const json gltf = json::parse(std::ifstream(dir_ + "/out/sky.gltf"));
  const json& lights = gltf["extensions"]["KHR_lights_punctual"]["lights"];
  ASSERT_EQ(lights.size(), 2u);
  EXPECT_EQ(lights[1]["name"].get<std::string>(), "moon");
  // lux, the brightest frame's: intensity x Y(colour), as clients light with colour x intensity.
  const double moon_lux = lights[1]["intensity"].get<double>() *
                          Rec709Luminance({lights[1]["color"][0].get<double>(), lights[1]["color"][1].get<double>(),
                                           lights[1]["color"][2].get<double>()});
  EXPECT_GT(moon_lux, 0.1);
  EXPECT_LT(moon_lux, 0.3);
  // Each light's rotation, intensity and colour per frame (KHR_animation_pointer).
  std::multiset<std::string> targets;
  for (const json& channel : gltf["animations"][0]["channels"])
    targets.insert(channel["target"]["path"] == "pointer"
                       ? channel["target"]["extensions"]["KHR_animation_pointer"]["pointer"].get<std::string>()
                       : channel["target"]["path"].get<std::string>());
  EXPECT_EQ(targets,
            (std::multiset<std::string>{"rotation", "rotation", "/extensions/KHR_lights_punctual/lights/0/intensity",
                                        "/extensions/KHR_lights_punctual/lights/0/color",
                                        "/extensions/KHR_lights_punctual/lights/1/intensity",
                                        "/extensions/KHR_lights_punctual/lights/1/color"}));
  auto [status, output] = RunCommand("cd '" + SourceDir() + "/tests/viewer' && node validate.mjs '" + dir_ +
                                     "/out/sky.gltf' '" + dir_ + "/out/sky.glb'");
  EXPECT_EQ(status, 0) << output << "\n(install with: bash .ci/setup)";
  size_t count = 0;
  for (size_t p = output.find("0 errors, 0 warnings"); p != std::string::npos;
       p = output.find("0 errors, 0 warnings", p + 1))
    ++count;
  EXPECT_EQ(count, 2u) << output;
}

// Shards of a night sequence merge into the unsharded bake's manifest and
// scene, the Moon's records and light included, byte for byte.
TEST_F(NightBake, ShardsMergeWithTheMoon) {
  ASSERT_EQ(run_.exit_code, 0) << run_.output;
  const std::string shards = dir_ + "/shards";
  for (const char* part : {"1/2", "2/2"}) {
    testing::CommandRun r =
        RunSkybake(fmt::format("bake '{0}/style.toml' --schedule '{0}/night.toml' --size 64 "
                               "--out '{1}' --quiet --shard {2}",
                               dir_, shards, part));
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  testing::CommandRun merge = RunSkybake(fmt::format("merge-manifest '{}'", shards));
  ASSERT_EQ(merge.exit_code, 0) << merge.output;
  for (const char* name : {"manifest.json", "sky.gltf", "sky.bin"})
    EXPECT_EQ(testing::ReadFileBytes(shards + "/" + name), testing::ReadFileBytes(dir_ + "/out/" + name)) << name;
}

// Bad input is refused before any GPU work, with exit code 3 and the fix.
TEST_F(NightBake, RefusesBadInputWithTheFix) {
  const std::string style = dir_ + "/style.toml";
  const std::string schedule = dir_ + "/night.toml";
  testing::CommandRun single = RunSkybake(fmt::format("bake '{}' --out '{}/x'", style, dir_));
  EXPECT_EQ(single.exit_code, 3) << single.output;
  EXPECT_NE(single.output.find("style.toml:4:9: night.stars: the night sky needs each frame's date, time and place"),
            std::string::npos)
      << single.output;
  EXPECT_NE(single.output.find("--schedule"), std::string::npos);
  // A schedule of sun positions has no clock time either.
  std::ofstream(dir_ + "/suns.toml") << "[schedule]\nsun = { elevation_deg = [-20.0, -30.0], azimuth_deg = 90.0 }\n";
  testing::CommandRun suns = RunSkybake(fmt::format("check '{}' --schedule '{}/suns.toml'", style, dir_));
  EXPECT_EQ(suns.exit_code, 3) << suns.output;
  EXPECT_NE(suns.output.find("suns.toml gives sun positions only"), std::string::npos) << suns.output;
  testing::CommandRun missing = RunSkybake(
      fmt::format("bake '{}' --schedule '{}' --out '{}/y' --set night.star_catalogue='\"/no/such/stars.json\"'", style,
                  schedule, dir_));
  EXPECT_EQ(missing.exit_code, 3) << missing.output;
  EXPECT_NE(missing.output.find("cannot read the star catalogue '/no/such/stars.json'"), std::string::npos)
      << missing.output;
  EXPECT_NE(missing.output.find("bash .ci/setup"), std::string::npos);
  // Given with --set, the error points at the argument, not at the style.
  EXPECT_EQ(missing.output.find("skybake: error: --set night.star_catalogue=\"/no/such/stars.json\":1:1: "
                                "night.star_catalogue: cannot read"),
            0u)
      << missing.output;
  // A relative path given with --set is taken from the working directory.
  testing::CommandRun relative =
      RunSkybake(fmt::format("check '{}' --schedule '{}' --set night.star_catalogue=night.toml", style, schedule),
                 fmt::format("cd '{}' &&", dir_));
  EXPECT_EQ(relative.exit_code, 3) << relative.output;
  EXPECT_NE(relative.output.find("--set night.star_catalogue=night.toml:1:1: night.star_catalogue:"), std::string::npos)
      << relative.output;
  testing::CommandRun limit =
      RunSkybake(fmt::format("check '{}' --schedule '{}' --set night.star_magnitude_limit=20", style, schedule));
  EXPECT_EQ(limit.exit_code, 3) << limit.output;
  EXPECT_NE(limit.output.find("night.star_magnitude_limit: 20 is out of range [-1.5, 14]"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ + "/x"));
  EXPECT_FALSE(fs::exists(dir_ + "/y/manifest.json"));
}

// With every night key off the bake is the one without the table, byte
// for byte (the golden outputs test covers the default styles); the pass
// plan names the night sky and why it is off.
TEST_F(NightBake, OffIsByteIdenticalAndPrunedInThePlan) {
  const std::string style = dir_ + "/style.toml";
  const std::string schedule = dir_ + "/night.toml";
  const std::string off = "--set night.stars=false --set night.moon=false --set night.moonlight=false";
  testing::CommandRun a = RunSkybake(fmt::format(
      "bake '{}' --schedule '{}' --size 16 --frames 2:2 --out '{}/off' --quiet {}", style, schedule, dir_, off));
  std::ofstream(dir_ + "/bare.toml") << "[effects]\nnight_dimming = true\n[output]\npixel_type = \"float\"\n";
  testing::CommandRun b = RunSkybake(fmt::format(
      "bake '{}/bare.toml' --schedule '{}' --size 16 --frames 2:2 --out '{}/bare' --quiet", dir_, schedule, dir_));
  ASSERT_EQ(a.exit_code, 0) << a.output;
  ASSERT_EQ(b.exit_code, 0) << b.output;
  for (const char* name : {"sky_latlong.0002.exr", "sky_cube.0002.exr", "sky_px.0002.exr", "sky_latlong.0002.png"}) {
    const std::string x = testing::ReadFileBytes(dir_ + "/off/" + name),
                      y = testing::ReadFileBytes(dir_ + "/bare/" + name);
    ASSERT_FALSE(x.empty()) << name;
    // The EXR headers record the style's path, which differs: compare the
    // pixels by decoding (EXR) and the PNG bytes.
    if (std::string(name).find(".png") != std::string::npos) {
      EXPECT_EQ(x, y) << name;
    } else {
      int w = 0, h = 0;
      EXPECT_EQ(ReadExr(dir_ + "/off/" + name, w, h), ReadExr(dir_ + "/bare/" + name, w, h)) << name;
    }
  }
  testing::CommandRun plan_off = RunSkybake(fmt::format("plan '{}' --schedule '{}' {}", style, schedule, off));
  testing::CommandRun plan_on = RunSkybake(fmt::format("plan '{}' --schedule '{}'", style, schedule));
  EXPECT_NE(plan_off.output.find("night sky"), std::string::npos) << plan_off.output;
  EXPECT_EQ(plan_off.output.find("moonlit sky"), std::string::npos) << plan_off.output;
  EXPECT_NE(plan_on.output.find("moonlit sky"), std::string::npos) << plan_on.output;
  EXPECT_EQ(plan_off.output.find("splat (host)"), std::string::npos) << plan_off.output;
  EXPECT_NE(plan_on.output.find("star and Moon splat (host)"), std::string::npos) << plan_on.output;
}

// The plan names the host's splat and glow and what prunes them by day:
// the 24-hour schedule's frames with the Sun up go through the tile bound.
TEST(NightSky, PlanSaysWhatPrunesTheSplatByDay) {
  const std::string root = SourceDir();
  const ScheduleResult schedule = LoadSchedule(root + "/configs/schedules/24h.toml");
  ASSERT_TRUE(schedule.ok());
  const FrameStyles resolved = ResolveFrameStyles(root + "/configs/night/moonlit.toml", {}, schedule.schedule);
  ASSERT_TRUE(resolved.ok());
  const std::vector<SkyStyle>& frames = resolved.styles;
  const int day =
      int(std::count_if(frames.begin(), frames.end(), [](const SkyStyle& f) { return f.sun.elevation_deg > 0.0; }));
  ASSERT_GT(day, 10);
  ASSERT_LT(day, int(frames.size()) - 10);
  const PassPlan plan = PlanPasses(frames);
  int found = 0;
  for (const PlannedPass& p : plan.passes) {
    if (p.name != "star and Moon splat (host)" && p.name != "airglow (host)") continue;
    ++found;
    EXPECT_EQ(p.runs, int(frames.size()));
    EXPECT_NE(p.frequency.find(fmt::format("{} of {} frames with the Sun up", day, frames.size())), std::string::npos)
        << p.frequency;
    EXPECT_NE(p.frequency.find("tile bound"), std::string::npos) << p.frequency;
    EXPECT_NE(p.frequency.find("bounded before any star is placed"), std::string::npos) << p.frequency;
    EXPECT_NE(p.frequency.find("places no star and splats nothing"), std::string::npos) << p.frequency;
  }
  EXPECT_EQ(found, 2);
  // Every frame at night: nothing to prune.
  std::vector<SkyStyle> nights = frames;
  for (SkyStyle& f : nights) f.sun.elevation_deg = -20.0;
  for (const PlannedPass& p : PlanPasses(nights).passes)
    if (p.name == "star and Moon splat (host)") {
      EXPECT_NE(p.frequency.find("every view splatted"), std::string::npos) << p.frequency;
    }
}

// A day frame does no night work: with the Sun 50 deg up and the Moon down
// (the 24-hour schedule at 12:30) no star is placed and nothing splatted,
// and every map is the same bytes as with the stars off; a twilight frame
// (19:30, the Sun 10 deg down) places its stars and shows them.
TEST_F(NightBake, DayFramePlacesNoStarAndTwilightDoes) {
  const std::string root = SourceDir();
  const std::string common = fmt::format(
      "bake '{0}/configs/night/moonlit.toml' --schedule '{0}/configs/schedules/24h.toml' "
      "--size 64 --set output.preview=false --set gltf.enabled=false",
      root);
  auto night_line = [](const std::string& output, int frame) {
    const std::string key = fmt::format("frame {}: ", frame);
    std::istringstream lines(output);
    for (std::string line; std::getline(lines, line);)
      if (line.find("night sky") != std::string::npos && line.find(key) != std::string::npos) return line;
    return std::string();
  };
  const testing::CommandRun day =
      RunSkybake(common + fmt::format(" --frames 26:26 --out '{}/day'", dir_), "SKYBAKE_VULKAN_VALIDATION=1");
  const testing::CommandRun day_off =
      RunSkybake(common + fmt::format(" --frames 26:26 --out '{}/day_off' --quiet --set night.stars=false", dir_));
  const testing::CommandRun dusk =
      RunSkybake(common + fmt::format(" --frames 40:40 --out '{}/dusk'", dir_), "SKYBAKE_VULKAN_VALIDATION=1");
  const testing::CommandRun dusk_off =
      RunSkybake(common + fmt::format(" --frames 40:40 --out '{}/dusk_off' --quiet --set night.stars=false", dir_));
  ASSERT_EQ(day.exit_code, 0) << day.output;
  ASSERT_EQ(day_off.exit_code, 0) << day_off.output;
  ASSERT_EQ(dusk.exit_code, 0) << dusk.output;
  ASSERT_EQ(dusk_off.exit_code, 0) << dusk_off.output;
  EXPECT_NE(night_line(day.output, 26).find("no star placed"), std::string::npos) << day.output;
  const std::string dusk_line = night_line(dusk.output, 40);
  EXPECT_EQ(dusk_line.find("no star placed"), std::string::npos) << dusk.output;
  EXPECT_NE(dusk_line.find(" stars"), std::string::npos) << dusk.output;
  const json manifest = json::parse(std::ifstream(dir_ + "/day/manifest.shard-0026-0026.json"));
  EXPECT_GT(manifest["frames"][0]["sun"]["elevation_deg"].get<double>(), 45.0);
  EXPECT_LT(manifest["frames"][0]["moon"]["elevation_deg"].get<double>(), 0.0);
  const json dusk_manifest = json::parse(std::ifstream(dir_ + "/dusk/manifest.shard-0040-0040.json"));
  EXPECT_LT(dusk_manifest["frames"][0]["sun"]["elevation_deg"].get<double>(), -6.0);
  // Each map against the same with the stars off: how many have the same
  // texels (the files' headers record the style).
  auto same_maps = [&](const std::string& on, const std::string& off, size_t& maps) {
    size_t same = 0;
    maps = 0;
    for (const auto& f : fs::directory_iterator(dir_ + "/" + on)) {
      if (f.path().extension() != ".exr") continue;
      ++maps;
      int w = 0, h = 0, w_off = 0, h_off = 0;
      const std::vector<float> a = ReadExr(f.path().string(), w, h);
      const std::vector<float> b = ReadExr(dir_ + "/" + off + "/" + f.path().filename().string(), w_off, h_off);
      same += !a.empty() && a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
    }
    return same;
  };
  size_t day_maps = 0, dusk_maps = 0;
  EXPECT_EQ(same_maps("day", "day_off", day_maps), day_maps);
  EXPECT_GT(day_maps, 2u);
  EXPECT_LT(same_maps("dusk", "dusk_off", dusk_maps), dusk_maps);  // the stars show at dusk
  EXPECT_GT(dusk_maps, 2u);
}

// night.airglow replaces the flat floor: the same zenith luminance, brighter
// towards the horizon.
TEST_F(NightBake, AirglowReplacesTheFlatFloor) {
  const std::string style = dir_ + "/style.toml";
  const std::string base =
      "--set night.stars=false --set night.moon=false --set night.moonlight=false --set output.faces=false";
  testing::CommandRun flat = RunSkybake(fmt::format(
      "bake '{}' --schedule '{}/configs/schedules/moonless.toml' --size 64 --frames 2:2 --out '{}/flat' --quiet {} "
      "--set night.airglow=false",
      style, SourceDir(), dir_, base));
  testing::CommandRun glow = RunSkybake(
      fmt::format(
          "bake '{}' --schedule '{}/configs/schedules/moonless.toml' --size 64 --frames 2:2 --out '{}/glow' --quiet {} "
          "--set night.airglow=true",
          style, SourceDir(), dir_, base),
      "SKYBAKE_VULKAN_VALIDATION=1");
  ASSERT_EQ(flat.exit_code, 0) << flat.output;
  ASSERT_EQ(glow.exit_code, 0) << glow.output;
  int w = 0, h = 0;
  const std::vector<float> f = ReadExr(dir_ + "/flat/sky_latlong.0002.exr", w, h);
  const std::vector<float> g = ReadExr(dir_ + "/glow/sky_latlong.0002.exr", w, h);
  auto lum = [&](const std::vector<float>& v, int row) {
    const float* t = &v[(size_t(row) * w + w / 3) * 4];
    return 0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2];
  };
  // The flat floor: 1.7e-4 cd/m^2 everywhere above the horizon.
  EXPECT_NEAR(lum(f, 1) / 1.7e-4, 1.0, 0.02);
  EXPECT_NEAR(lum(f, h / 2 - 3) / 1.7e-4, 1.0, 0.02);
  // The glow: the same at the zenith, brighter 10-15 deg up, black below the horizon.
  EXPECT_NEAR(lum(g, 0) / 1.7e-4, 1.0, 0.02);
  EXPECT_GT(lum(g, h / 2 - 5), 1.5 * lum(g, 0));
  EXPECT_EQ(lum(g, h - 1), 0.0);
  size_t bad = 0;
  for (float v : g) bad += !std::isfinite(v) || v < 0.0f;
  EXPECT_EQ(bad, 0u);
}

// Above the horizon the Sun's sky outshines the moonlit sky of a full moon
// by more than half float's resolution everywhere in the upper hemisphere,
// so moonlight is rendered only while the Sun is down.
TEST(NightSkyGpu, MoonlightIsBelowHalfFloatResolutionWhileTheSunIsUp) {
  AtmosphereParams atmosphere;
  EffectSettings effects;
  effects.sun_disc = false;
  SkyRenderer renderer(testing::Vulkan(), atmosphere, QualitySettings(), effects, OutputScale(OutputUnits::kLuminance));
  std::vector<glm::dvec3> directions;
  for (double el = 1.0; el <= 89.0; el += 8.0)
    for (double az = 0.0; az < 360.0; az += 30.0) directions.push_back(SunDirectionFromElevationAzimuth(el, az));
  const Rgb k_lum = OutputScale(OutputUnits::kLuminance);
  const double sun_lux = 0.2126 * atmosphere.solar_irradiance[0] * k_lum[0] +
                         0.7152 * atmosphere.solar_irradiance[1] * k_lum[1] +
                         0.0722 * atmosphere.solar_irradiance[2] * k_lum[2];
  const double k = MoonIlluminanceLux(0.0, 356500.0) / sun_lux;  // a full moon at perigee
  const std::vector<float> sunlit =
      renderer.RenderDirections(SunDirectionFromElevationAzimuth(0.0, 270.0), directions, false);
  for (double moon_elevation : {10.0, 45.0, 85.0}) {
    const std::vector<float> moonlit =
        renderer.RenderDirections(SunDirectionFromElevationAzimuth(moon_elevation, 90.0), directions, false);
    double worst = 0.0;
    for (size_t i = 0; i < directions.size(); ++i)
      for (int c = 0; c < 3; ++c) worst = std::max(worst, k * moonlit[4 * i + c] / sunlit[4 * i + c]);
    EXPECT_LT(worst, 1.0 / 2048.0) << moon_elevation;
  }
  testing::ExpectNoValidationMessages();
}

// The bounds (BoundByTiles, then SplatBound) skip only what cannot change a
// byte: the maps of one frame's stars, Moon and airglow, with the bounds and
// with every splat run whole and the glow checked texel by texel, are the
// same bytes at every sun elevation from high noon through the dusk where
// stars begin to show to the night, with the first-quarter Moon up (its disc
// shows in daylight: the bounds open only the texels around it) and down.
TEST(NightSkyGpu, SplatBoundChangesNoByte) {
  const SkyStyle style = EveryNightFeature();
  const std::optional<StarCatalogue> catalogue = DefaultCatalogue();
  ASSERT_TRUE(catalogue);
  const TransmittanceTable table(style.atmosphere, style.quality, style.effects);
  const Rgb scale = OutputScale(style.output.units);
  SkyRenderer renderer(testing::Vulkan(), style.atmosphere, style.quality, style.effects, scale);
  NightSkyRenderer bounded(testing::Vulkan()), exact(testing::Vulkan()), whole(testing::Vulkan());
  // The frames whose stars wait for a view that needs them (night_prune.h).
  NightSkyRenderer deferred(testing::Vulkan());
  const StarGrid grid(*catalogue, style.night.star_magnitude_limit, style.output.units);
  exact.set_tile_bound(false);
  whole.set_splat_bound(false);
  std::vector<ViewRequest> views = ViewsOfSize(64);
  for (const ViewRequest& v : ViewsOfSize(256)) views.push_back(v);
  // Cerro Paranal, 2024-04-15 22:20 UT: the first-quarter Moon 60 deg up
  // in the East; 2024-04-16 08:20 UT: the Moon down.
  const GeoLocation paranal{-24.6272, -70.4042};
  const double moon_up = 2460415.5 + 22.0 / 24.0 + 20.0 / 1440.0, moon_down = moon_up + 10.0 / 24.0;
  const std::vector<Rgb> airglow =
      AirglowTable(style.atmosphere, table, 90.0, style.effects.night_sky_luminance_cd_m2, style.output.units);
  size_t dusk_views_skipped = 0, dusk_views_changed = 0;
  for (const double elevation : {50.0, 20.0, 8.0, 4.0, 1.0, -1.0, -3.0, -5.0, -7.0, -9.0, -12.0, -40.0})
    for (const double julian_day_ut : {moon_down, moon_up}) {
      const bool up = julian_day_ut == moon_up;
      const std::string what = fmt::format("sun {} deg, Moon {}", elevation, up ? "up" : "down");
      const glm::dvec3 sun = SunDirectionFromElevationAzimuth(elevation, 290.0);
      const std::vector<std::vector<float>> sky = renderer.Render(sun, views);
      // This thread's CPU time (the machine is shared; wall time is not).
      auto cpu_ms = []() {
        timespec t{};
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
        return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
      };
      const double p0 = cpu_ms();
      NightFrame night = ComputeNightFrame(style, &*catalogue, table, julian_day_ut, paranal, sun);
      const double p1 = cpu_ms();
      night.airglow = airglow;
      ASSERT_GT(night.stars, 1000u);
      ASSERT_TRUE(night.moon);
      if (up) ASSERT_GT(night.moon->sky.elevation_deg, 30.0);
      else ASSERT_LT(night.moon->sky.elevation_deg, -5.0);
      // Of the frame, the Moon's ephemeris (libnova's ELP 2000-82B), which
      // the manifest records every frame.
      const double m0 = cpu_ms();
      (void)ComputeMoon(julian_day_ut, paranal, style.atmosphere.observer_altitude_m);
      const double m1 = cpu_ms();
      const double p2 = cpu_ms();
      NightFrame later = ComputeNightFrame(style, &*catalogue, table, julian_day_ut, paranal, sun, &grid);
      const double p3 = cpu_ms();
      later.airglow = airglow;
      // Only a frame with the Sun up waits; a twilight frame places its stars.
      ASSERT_EQ(bool(later.pending), elevation > 0.0) << what;
      if (!later.pending) {
        ASSERT_EQ(later.stars, night.stars) << what;
      }
      std::vector<RgbaImage> a, b, c, d;
      for (size_t i = 0; i < views.size(); ++i) {
        a.push_back({views[i].width, views[i].height, sky[i], nullptr});
        b.push_back({views[i].width, views[i].height, sky[i], nullptr});
        c.push_back({views[i].width, views[i].height, sky[i], nullptr});
        d.push_back({views[i].width, views[i].height, sky[i], nullptr});
      }
      const size_t skipped_before = bounded.splats_skipped(), tiles_before = bounded.splats_skipped_by_tiles();
      const double t0 = cpu_ms();
      bounded.AddToViews(style, night, views, a);
      const double t1 = cpu_ms();
      exact.AddToViews(style, night, views, c);
      const double t2 = cpu_ms();
      whole.AddToViews(style, night, views, b);
      const double t3 = cpu_ms();
      const size_t cleared_before = deferred.views_cleared_before_placement();
      const size_t deferred_skipped_before = deferred.splats_skipped();
      deferred.AddToViews(style, later, views, d);
      const double t4 = cpu_ms();
      const size_t cleared = deferred.views_cleared_before_placement() - cleared_before;
      const size_t deferred_skipped = deferred.splats_skipped() - deferred_skipped_before;
      const bool placed = !later.pending || later.pending->placed();
      const size_t skipped = bounded.splats_skipped() - skipped_before;
      const size_t by_tiles = bounded.splats_skipped_by_tiles() - tiles_before;
      size_t changed = 0;
      for (size_t i = 0; i < views.size(); ++i) {
        ASSERT_EQ(a[i].rgba.size(), b[i].rgba.size());
        ASSERT_EQ(c[i].rgba.size(), b[i].rgba.size());
        EXPECT_EQ(std::memcmp(a[i].rgba.data(), b[i].rgba.data(), a[i].rgba.size() * sizeof(float)), 0)
            << what << ", view " << i;
        EXPECT_EQ(std::memcmp(c[i].rgba.data(), b[i].rgba.data(), c[i].rgba.size() * sizeof(float)), 0)
            << what << ", view " << i;
        ASSERT_EQ(d[i].rgba.size(), b[i].rgba.size());
        EXPECT_EQ(std::memcmp(d[i].rgba.data(), b[i].rgba.data(), d[i].rgba.size() * sizeof(float)), 0)
            << what << ", view " << i << " (stars placed on need)";
        changed += a[i].rgba != sky[i];
      }
      // For the record (docs/performance.md), not a target: the frame
      // (ComputeNightFrame: stars placed, or waiting) and its additions.
      std::printf(
          "%s: thread CPU, frame %.2f ms + additions with both bounds %.1f ms, SplatBound alone %.1f ms, "
          "whole %.1f ms; %zu of %zu views skipped (%zu by the tiles), %zu changed; stars placed on need: "
          "frame %.2f ms + additions %.1f ms, %zu of %zu views cleared before placement, stars %s; the "
          "Moon's ephemeris alone %.2f ms\n",
          what.c_str(), p1 - p0, t1 - t0, t2 - t1, t3 - t2, skipped, views.size(), by_tiles, changed, p3 - p2, t4 - t3,
          cleared, views.size(), placed ? "placed" : "not placed", m1 - m0);
      if (elevation >= 50.0 && !up) {
        // High noon with the Moon down: no star is placed, nothing splatted.
        EXPECT_EQ(cleared, views.size()) << what;
        EXPECT_FALSE(placed) << what;
      }
      if (elevation > 0.0 && up) {
        EXPECT_TRUE(placed) << what;  // the Moon's disc shows in daylight
        // The faces away from it: cleared before placement, or (after a
        // view has placed the stars) by the tile bound.
        EXPECT_GT(cleared + deferred_skipped, 0u) << what;
      }
      if (elevation < 0.0) {
        EXPECT_EQ(cleared, 0u) << what;  // twilight and night: placed, splatted
      }
      if (elevation >= 20.0 && !up) {
        // Nothing to splat anywhere, and the tiles alone show it but for a
        // few of the larger views, where a tile's stars together outweigh
        // its smallest texel (the latlong's polar rows): SplatBound then
        // finds nothing either.
        EXPECT_EQ(skipped, views.size()) << what;
        EXPECT_GE(by_tiles, views.size() - 4) << what;
        EXPECT_EQ(changed, 0u) << what;
      } else if (elevation >= 20.0) {
        EXPECT_GT(changed, 0u) << what;   // the Moon in daylight
        EXPECT_GT(by_tiles, 0u) << what;  // the faces without it
      } else if (elevation < -15.0) {
        // Stars (and the glow) on every view but the faces below the
        // horizon (-Y); by night neither bound is used, the splats run whole.
        EXPECT_EQ(skipped, 0u) << what;
        EXPECT_EQ(changed, views.size() - 2) << what;
        EXPECT_EQ(a[3].rgba, sky[3]);
      } else {
        // Sunrise and dusk: the brightest stars begin to show in the data
        // before the Sun is down (a 256 face's texel is small enough).
        dusk_views_skipped += by_tiles;
        dusk_views_changed += changed;
      }
    }
  // At dusk the bounds both skip views and let the first stars through.
  EXPECT_GT(dusk_views_skipped, 0u);
  EXPECT_GT(dusk_views_changed, 0u);
  testing::ExpectNoValidationMessages();
}

// W1's maps (six 512^2 faces, a 512 strip, a 2048 x 1024 latlong) by day
// with the Moon down. The bound before placement looks at a small texel
// star by star (WeightedTexelLoad), so where the daylit sky outshines
// every star no star is placed and nothing is splatted; where a star does
// reach 2^-13 of a texel (a bright star in a 512 face, any star in the
// latlong's polar rows or a strip's edge texels, whose solid angles are a
// fraction of the others') they are placed. Either way the maps are the
// bytes of the whole splat (every star splatted, every addition tested).
// The frames: configs/schedules/24h.toml's 23-26 (2024-04-23 11:00-12:30
// CLT at Cerro Paranal, the Sun 45-53 deg up, the Moon down: W1's day
// frames of docs/performance.md), and 2024-01-15 04:00 UT with Sirius, the
// brightest star, 82 deg up and the Sun put at 45 deg.
TEST(NightSkyGpu, DaylitW1MapsPlaceNoStarWhereNoneShows) {
  const SkyStyle style = EveryNightFeature();
  const std::optional<StarCatalogue> catalogue = DefaultCatalogue();
  ASSERT_TRUE(catalogue);
  const TransmittanceTable table(style.atmosphere, style.quality, style.effects);
  SkyRenderer renderer(testing::Vulkan(), style.atmosphere, style.quality, style.effects,
                       OutputScale(style.output.units));
  NightSkyRenderer deferred(testing::Vulkan()), whole(testing::Vulkan());
  whole.set_splat_bound(false);
  const StarGrid grid(*catalogue, style.night.star_magnitude_limit, style.output.units);
  std::vector<ViewRequest> views;
  for (int face = 0; face < 6; ++face) views.push_back({MAPPING_VULKAN_FACE, 512, 512, face});
  views.push_back({MAPPING_CUBE_STRIP, 512, 6 * 512, 0});
  views.push_back({MAPPING_LATLONG, 2048, 1024, 0});
  const std::vector<Rgb> airglow =
      AirglowTable(style.atmosphere, table, 90.0, style.effects.night_sky_luminance_cd_m2, style.output.units);
  const GeoLocation paranal{-24.6272, -70.4042};
  struct Case {
    double julian_day_ut;
    std::optional<double> sun_elevation;  // none: the real Sun's
  };
  std::vector<Case> cases;
  for (int frame = 23; frame <= 26; ++frame)
    cases.push_back({2460423.5 + (4.0 + 0.5 * (frame - 1)) / 24.0, std::nullopt});
  cases.push_back({2460324.5 + 4.0 / 24.0, 45.0});
  int none_shows = 0, some_show = 0;
  for (const Case& c : cases) {
    const LunarEphemeris e = ComputeLunarEphemeris(c.julian_day_ut);
    const glm::dvec3 sun = c.sun_elevation
                               ? SunDirectionFromElevationAzimuth(*c.sun_elevation, 290.0)
                               : HorizontalFromJ2000(e.sun_ra_deg, e.sun_dec_deg, c.julian_day_ut, paranal).direction;
    const std::string what = fmt::format("jd {:.4f}, sun {:.1f} deg", c.julian_day_ut, std::asin(sun.y) * 180.0 / M_PI);
    ASSERT_GT(sun.y, std::sin(40.0 * M_PI / 180.0)) << what;
    const std::vector<std::vector<float>> sky = renderer.Render(sun, views);
    NightFrame night = ComputeNightFrame(style, &*catalogue, table, c.julian_day_ut, paranal, sun);
    NightFrame later = ComputeNightFrame(style, &*catalogue, table, c.julian_day_ut, paranal, sun, &grid);
    night.airglow = airglow;
    later.airglow = airglow;
    ASSERT_TRUE(night.moon);
    ASSERT_LT(night.moon->sky.elevation_deg, 0.0) << what;
    ASSERT_TRUE(later.pending) << what;
    std::vector<RgbaImage> a, b;
    for (size_t i = 0; i < views.size(); ++i) {
      a.push_back({views[i].width, views[i].height, sky[i], nullptr});
      b.push_back({views[i].width, views[i].height, sky[i], nullptr});
    }
    const size_t cleared_before = deferred.views_cleared_before_placement();
    deferred.AddToViews(style, later, views, a);
    whole.AddToViews(style, night, views, b);
    const size_t cleared = deferred.views_cleared_before_placement() - cleared_before;
    size_t shown = 0;
    for (size_t i = 0; i < views.size(); ++i) {
      ASSERT_EQ(a[i].rgba.size(), b[i].rgba.size());
      EXPECT_EQ(std::memcmp(a[i].rgba.data(), b[i].rgba.data(), a[i].rgba.size() * sizeof(float)), 0)
          << what << ", view " << i;
      shown += b[i].rgba != sky[i];
    }
    std::printf("%s: %zu of %zu views show a star; %zu cleared before placement, stars %s\n", what.c_str(), shown,
                views.size(), cleared, later.pending->placed() ? "placed" : "not placed");
    if (shown == 0) {
      EXPECT_EQ(cleared, views.size()) << what;
      EXPECT_FALSE(later.pending->placed()) << what;
      ++none_shows;
    } else {
      EXPECT_TRUE(later.pending->placed()) << what;
      EXPECT_LE(cleared, views.size() - shown) << what;
      ++some_show;
    }
  }
  EXPECT_GT(none_shows, 0);
  EXPECT_GT(some_show, 0);  // Sirius high in a 512 face
  testing::ExpectNoValidationMessages();
}

// The tile bound's smallest solid angle per tile, from its corner texels,
// is the smallest of its texels' (faces, strips and latlongs, tiles cut by
// the view's edge or, in a strip, by a face's).
TEST(NightSky, SplatTilesHoldTheirSmallestSolidAngle) {
  for (const int n : {16, 37, 64, 100})
    for (const ViewRequest& view : ViewsOfSize(n)) {
      const SplatTiles tiles(view, {});
      std::vector<double> smallest(size_t(tiles.count()), std::numeric_limits<double>::infinity());
      std::vector<int> texels(size_t(tiles.count()), 0);
      for (int y = 0; y < view.height; ++y)
        for (int x = 0; x < view.width; ++x) {
          const int t = tiles.TileOf(x, y);
          ASSERT_GE(t, 0);
          ASSERT_LT(t, tiles.count());
          int x0, x1, y0, y1;
          tiles.Rect(t, x0, x1, y0, y1);
          ASSERT_TRUE(x >= x0 && x < x1 && y >= y0 && y < y1) << n << " " << view.mapping;
          ++texels[size_t(t)];
          const double omega = ViewTexelSolidAngle(view, view.mapping == MAPPING_LATLONG ? 0 : x, y);
          smallest[size_t(t)] = std::min(smallest[size_t(t)], omega);
        }
      for (int t = 0; t < tiles.count(); ++t) {
        EXPECT_GT(texels[size_t(t)], 0);
        EXPECT_LE(tiles.min_solid_angle(t), smallest[size_t(t)] * (1.0 + 1e-12))
            << n << " " << view.mapping << " " << t;
        EXPECT_GE(tiles.min_solid_angle(t), smallest[size_t(t)] * (1.0 - 1e-12))
            << n << " " << view.mapping << " " << t;
      }
    }
}

// The catalogue binned by J2000 position bounds the light of the stars in
// any cone (at least the sum of those within it, by brute force) and holds
// all of them; a small cone in an empty part of the sky is empty.
TEST(NightSky, StarGridBoundsTheStarsInEveryCone) {
  const std::optional<StarCatalogue> catalogue = DefaultCatalogue();
  ASSERT_TRUE(catalogue);
  const double limit = NightSettings().star_magnitude_limit;
  const StarGrid grid(*catalogue, limit, OutputUnits::kLuminance);
  // E: in luminance units the largest channel of the luminance-normalized colour, in lux.
  std::vector<std::pair<glm::dvec3, double>> stars;
  double total = 0.0;
  for (const CatalogueStar& s : catalogue->stars) {
    if (s.v_magnitude > limit) continue;
    const Rgb color = StarColorFromBMinusV(s.b_minus_v);
    const double e = StarIlluminanceLux(s.v_magnitude) * std::max({color[0], color[1], color[2]});
    stars.push_back({UnitFromEquatorial(s.ra_j2000_deg, s.dec_j2000_deg), e});
    total += e;
  }
  ASSERT_GT(stars.size(), 1000u);
  EXPECT_NEAR(grid.total() / total, 1.0, 1e-9);
  std::mt19937 rng(20);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int empty = 0, cones = 0;
  for (int i = 0; i < 3000; ++i) {
    glm::dvec3 d(u(rng), u(rng), u(rng));
    // Near the poles and across RA 0 too.
    if (i % 10 == 0) d = glm::dvec3(0.01 * u(rng), 0.01 * u(rng), i % 20 == 0 ? 1.0 : -1.0);
    if (i % 10 == 5) d = glm::dvec3(1.0, 1e-3 * u(rng), u(rng));
    if (glm::length(d) < 0.1) continue;
    d = glm::normalize(d);
    const double r = std::pow(10.0, -4.0 + 3.7 * (0.5 + 0.5 * u(rng)));  // 1e-4 to 0.5 rad
    const double cos_r = std::cos(r);
    double brute = 0.0;
    for (const auto& [v, e] : stars)
      if (glm::dot(v, d) >= cos_r) brute += e;
    const double bound = grid.SumWithin(d, r);
    EXPECT_GE(bound, brute) << "cone " << i << " radius " << r;
    // StarsWithin gives every star of the cone (and others of its cells),
    // each with its E and its J2000 vector as PlaceStars forms it.
    std::vector<StarGrid::Star> near;
    grid.StarsWithin(d, r, near);
    double listed = 0.0, listed_in_cone = 0.0;
    for (const StarGrid::Star& s : near) {
      listed += s.e;
      if (glm::dot(s.j2000, d) >= cos_r) listed_in_cone += s.e;
    }
    EXPECT_NEAR(listed_in_cone, brute, 1e-12 * total) << "cone " << i;
    EXPECT_LE(listed, bound) << "cone " << i;
    if (r < 0.01) {
      EXPECT_LT(bound, 0.01 * total) << "cone " << i;
    }
    empty += bound == 0.0;
    ++cones;
  }
  EXPECT_GT(empty, cones / 20);
  std::vector<StarGrid::Star> all;
  grid.StarsWithin(glm::dvec3(0.0, 0.0, 1.0), M_PI, all);
  EXPECT_EQ(all.size(), stars.size());
}

// WeightedTexelLoad is at least each texel's addition (largest channel)
// times its solid angle, and at most SplatBound's load (every weight 1):
// random sources and texels of faces, strips and latlongs, the texels a
// source lands on and the latlong's repeated meridian included.
TEST(NightSky, WeightedTexelLoadBoundsEachAddition) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), log10(-6.0, -2.0);
  int checked = 0, below_unweighted = 0;
  for (const ViewRequest& view : ViewsOfSize(24)) {
    std::vector<PointSource> sources(60);
    for (PointSource& p : sources) {
      p.direction = glm::normalize(glm::dvec3(unit(rng), unit(rng), unit(rng)));
      if (&p - sources.data() < 6) p.direction = glm::normalize(glm::dvec3(1e-3 * unit(rng), 1.0, 1e-3 * unit(rng)));
      const double e = std::pow(10.0, log10(rng));
      p.irradiance = {e, e * 0.7, e * 1.2};
    }
    for (const TexelAdd& a : SplatPointSources(view, sources)) {
      const int x = int(a.texel % view.width), y = int(a.texel / view.width);
      const double omega = ViewTexelSolidAngle(view, view.mapping == MAPPING_LATLONG && x == view.width - 1 ? 0 : x, y);
      const double added = std::max({double(a.rgb[0]), double(a.rgb[1]), double(a.rgb[2])}) * omega;
      const double load = WeightedTexelLoad(view, sources, x, y);
      EXPECT_GE(load * (1.0 + 1e-6), added) << view.mapping << " " << x << " " << y;
      // SplatBound's load: every source that lands on the texel, at weight 1.
      double unweighted = 0.0;
      for (const PointSource& p : sources)
        if (WeightedTexelLoad(view, {p}, x, y) > 0.0)
          unweighted += std::max({p.irradiance[0], p.irradiance[1], p.irradiance[2]});
      EXPECT_LE(load, unweighted * (1.0 + 1e-12)) << view.mapping << " " << x << " " << y;
      below_unweighted += load < 0.9 * unweighted;
      ++checked;
    }
    // A texel no source lands on has no load.
    int empty = 0;
    for (int y = 0; y < view.height && empty < 20; y += 3)
      for (int x = 0; x < view.width && empty < 20; x += 5) {
        bool reached = false;
        for (const TexelAdd& a : SplatPointSources(view, sources))
          reached = reached || a.texel == size_t(y) * view.width + x;
        if (reached) continue;
        EXPECT_EQ(WeightedTexelLoad(view, sources, x, y), 0.0) << view.mapping << " " << x << " " << y;
        ++empty;
      }
  }
  EXPECT_GT(checked, 500);
  EXPECT_GT(below_unweighted, checked / 4);  // the weights tighten the bound
}

// A rectangle's cone holds the directions and mu of its texels, its
// smallest solid angle is no larger than any of its texels', and every
// source with a splat target in it is within its reach (faces, strips,
// latlongs, texels and the tiles of SplatTiles).
TEST(NightSky, RectConesHoldTheirTexelsAndTheirSources) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto angle = [](const glm::dvec3& a, const glm::dvec3& b) {
    return std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0));
  };
  for (const int n : {9, 16, 37, 64})
    for (const ViewRequest& view : ViewsOfSize(n)) {
      const bool latlong = view.mapping == MAPPING_LATLONG;
      const int face_rows = view.mapping == MAPPING_CUBE_STRIP ? n : view.height;
      const std::string what = fmt::format("size {} mapping {} face {}", n, view.mapping, view.face);
      for (int k = 0; k < 40; ++k) {
        std::uniform_int_distribution<int> fx(0, view.width - 1), fy(0, face_rows - 1),
            ff(0, view.mapping == MAPPING_CUBE_STRIP ? 5 : 0);
        int xa = fx(rng), xb = fx(rng), ya = fy(rng), yb = fy(rng);
        if (xa > xb) std::swap(xa, xb);
        if (ya > yb) std::swap(ya, yb);
        const int offset = ff(rng) * face_rows;
        const int x0 = xa, x1 = xb + 1, y0 = ya + offset, y1 = yb + 1 + offset;
        const RectCone c = ConeOfRect(view, x0, x1, y0, y1);
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x) {
            const glm::dvec3 d = ViewTexelDirection(view, x, y);
            EXPECT_LE(angle(c.centre, d), c.texel_radius_rad + 1e-12) << what << " " << x << "," << y;
            EXPECT_LE(c.texel_radius_rad, c.reach_rad);
            EXPECT_GE(float(d.y), c.min_mu) << what;
            EXPECT_LE(float(d.y), c.max_mu) << what;
            if (!(latlong && x == view.width - 1)) {
              EXPECT_GE(ViewTexelSolidAngle(view, x, y), c.min_solid_angle * (1.0 - 1e-12)) << what;
            }
          }
      }
      const SplatTiles tiles(view, {});
      std::vector<RectCone> tile_cones;
      for (int t = 0; t < tiles.count(); ++t) {
        int x0, x1, y0, y1;
        tiles.Rect(t, x0, x1, y0, y1);
        tile_cones.push_back(ConeOfRect(view, x0, x1, y0, y1));
      }
      for (int k = 0; k < 3000; ++k) {
        glm::dvec3 s(u(rng), u(rng), u(rng));
        if (k % 7 == 0) s = glm::dvec3(0.01 * s.x, 1.0, 0.01 * s.z);  // near the zenith (a latlong's first rows)
        if (glm::length(s) < 0.1) continue;
        s = glm::normalize(s);
        for (const TexelAdd& a : SplatPointSources(view, {{s, {1.0, 1.0, 1.0}}})) {
          const int x = int(a.texel % size_t(view.width)), y = int(a.texel / size_t(view.width));
          const RectCone texel = ConeOfRect(view, x, x + 1, y, y + 1);
          EXPECT_LE(angle(s, texel.centre), texel.reach_rad) << what << " texel " << x << "," << y;
          const RectCone& tile = tile_cones[size_t(tiles.TileOf(x, y))];
          EXPECT_LE(angle(s, tile.centre), tile.reach_rad) << what << " tile of " << x << "," << y;
        }
      }
    }
}

// The bound is conservative for any sky: random skies and random sources,
// the additions the bound keeps are exactly those ApplyTexelAdds applies.
TEST(NightSky, SplatBoundKeepsExactlyWhatIsApplied) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), log10(-9.0, -3.0), sky(-1.0, 4.0);
  int nothing_applied = 0, some_applied = 0, skipped_sources = 0;
  int tile_skipped = 0, tile_narrowed = 0, glow_shown = 0, glow_skipped = 0;
  for (int trial = 0; trial < 12; ++trial) {
    // Every other trial a bright sky (10^3 to 10^5) and faint sources.
    sky = std::uniform_real_distribution<double>(trial % 2 ? 3.0 : -1.0, trial % 2 ? 5.0 : 4.0);
    log10 = std::uniform_real_distribution<double>(-9.0, trial % 2 ? -6.0 : -3.0);
    for (const ViewRequest& view : ViewsOfSize(32 + 7 * trial)) {
      std::vector<PointSource> sources(400);
      for (PointSource& p : sources) {
        p.direction = glm::normalize(glm::dvec3(unit(rng), unit(rng), unit(rng)));
        const double e = std::pow(10.0, log10(rng));
        p.irradiance = {e, e * 0.8, e * 1.1};
      }
      std::vector<float> rgba(size_t(view.width) * view.height * 4, 1.0f);
      for (size_t i = 0; i < rgba.size(); ++i)
        if (i % 4 != 3) rgba[i] = float(std::pow(10.0, sky(rng)));
      SplatBound bound;
      const std::vector<TexelAdd> bounded = BoundedSplat(view, sources, rgba.data(), kNightSplatMinRelative, &bound);
      std::vector<float> whole = rgba, kept = rgba, tiled = rgba;
      const size_t applied =
          ApplyTexelAdds(SplatPointSources(view, sources), rgba.data(), whole.data(), kNightSplatMinRelative);
      ApplyTexelAdds(bounded, rgba.data(), kept.data(), kNightSplatMinRelative);
      EXPECT_EQ(std::memcmp(whole.data(), kept.data(), whole.size() * sizeof(float)), 0)
          << trial << " " << view.mapping;
      // The tile bound in front: its sources alone through SplatBound give
      // the same bytes, and it skips only views where nothing is applied.
      std::vector<float> mu(size_t(view.width) * view.height);
      for (int y = 0; y < view.height; ++y)
        for (int x = 0; x < view.width; ++x) mu[size_t(y) * view.width + x] = float(ViewTexelDirection(view, x, y).y);
      const SplatTiles tiles(view, mu);
      const TileBound tb = BoundByTiles(view, tiles, sources, {}, rgba.data(), kNightSplatMinRelative);
      EXPECT_FALSE(tb.airglow);
      if (!tb.splat) {
        EXPECT_EQ(applied, 0u) << trial << " " << view.mapping;
        ++tile_skipped;
      } else {
        std::vector<PointSource> some;
        for (size_t k : tb.sources) some.push_back(sources[k]);
        tile_narrowed += some.size() < sources.size();
        ApplyTexelAdds(BoundedSplat(view, some, rgba.data(), kNightSplatMinRelative), rgba.data(), tiled.data(),
                       kNightSplatMinRelative);
        EXPECT_EQ(std::memcmp(whole.data(), tiled.data(), whole.size() * sizeof(float)), 0)
            << trial << " " << view.mapping;
      }
      // A glow: the tile bound lets it through wherever a texel takes it.
      std::vector<Rgb> glow(kAirglowEntries);
      const double g = std::pow(10.0, log10(rng) + 3.0);
      for (int i = kAirglowEntries / 2; i < kAirglowEntries; ++i) glow[size_t(i)] = {g, g * (1.0 + 1e-3 * i), g};
      const TileBound gb = BoundByTiles(view, tiles, {}, glow, rgba.data(), kNightSplatMinRelative);
      bool shows = false;
      for (size_t i = 0; i < mu.size() && !shows; ++i) {
        const Rgb a = AirglowAt(glow, mu[i]);
        const double add = std::max({a[0], a[1], a[2]});
        const float* t = rgba.data() + 4 * i;
        shows = add > 0.0 && !(add < kNightSplatMinRelative * std::max({double(t[0]), double(t[1]), double(t[2])}));
      }
      if (shows) {
        EXPECT_TRUE(gb.airglow) << trial << " " << view.mapping;
      }
      glow_shown += shows;
      glow_skipped += !gb.airglow;
      if (applied == 0) {
        ++nothing_applied;
        continue;
      }
      ++some_applied;
      EXPECT_FALSE(bound.open.empty());
      skipped_sources += bound.sources.size() < sources.size();
    }
  }
  // Both kinds of sky were met, and the bound left sources out of some.
  EXPECT_GT(nothing_applied, 0);
  EXPECT_GT(some_applied, 0);
  EXPECT_GT(skipped_sources, 0);
  // The tile bound skipped views, narrowed the sources of others, let the
  // glow through on some and kept it out of others.
  EXPECT_GT(tile_skipped, 0);
  EXPECT_GT(tile_narrowed, 0);
  EXPECT_GT(glow_shown, 0);
  EXPECT_GT(glow_skipped, 0);
}

}  // namespace
}  // namespace skybake

namespace skybake {
namespace {

// An 8-bit RGB image (PNG) as read by OpenImageIO.
struct Rgb8 {
  int w = 0, h = 0;
  std::vector<unsigned char> rgb;
  double Y(int x, int y) const {
    const unsigned char* p = &rgb[3 * (size_t(y) * w + x)];
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
  }
};
Rgb8 ReadPng(const std::string& path) {
  Rgb8 image;
  testing::ReadRgb(path, image.w, image.h, image.rgb);
  return image;
}

// Points of light in the sky half of a latlong preview: texels that are the
// brightest of their 3 x 3 neighbours and at least 24 (8-bit luminance) over
// the median of their 7 x 7.
int PointsOfLight(const Rgb8& image) {
  int count = 0;
  for (int y = 3; y < image.h / 2 - 3; ++y)
    for (int x = 3; x < image.w - 3; ++x) {
      const double c = image.Y(x, y);
      bool peak = true;
      std::vector<double> around;
      for (int dy = -3; dy <= 3; ++dy)
        for (int dx = -3; dx <= 3; ++dx) {
          const double v = image.Y(x + dx, y + dy);
          around.push_back(v);
          if (std::abs(dx) <= 1 && std::abs(dy) <= 1 && (dx || dy) && v > c) peak = false;
        }
      std::nth_element(around.begin(), around.begin() + 24, around.end());
      if (peak && c >= around[24] + 24.0) ++count;
    }
  return count;
}

// Mean 8-bit channel of the sky rows between 10 and 60 deg elevation.
glm::dvec3 SkyMean(const Rgb8& image) {
  glm::dvec3 sum(0.0);
  int n = 0;
  for (int y = image.h / 6; y < image.h * 4 / 9; ++y)
    for (int x = 0; x < image.w; ++x, ++n)
      for (int c = 0; c < 3; ++c) sum[c] += image.rgb[3 * (size_t(y) * image.w + x) + c];
  return sum / double(std::max(n, 1));
}

// A night style of a gallery whose catalogue is missing is refused with the
// fix before any style is baked (exit 3).
TEST(NightGallery, RefusesAMissingCatalogueBeforeAnyBake) {
  const std::string dir = testing::FreshTempDir("night_gallery_bad");
  fs::create_directories(dir + "/styles");
  fs::copy_file(SourceDir() + "/configs/styles/natural.toml", dir + "/styles/a_natural.toml");
  std::string night = testing::ReadFileBytes(SourceDir() + "/configs/styles/night_moonless.toml");
  night.replace(night.find("star_magnitude_limit"), 0, "star_catalogue = \"missing.json\"\n");
  std::ofstream(dir + "/styles/b_night.toml") << night;
  testing::CommandRun run = RunSkybake(fmt::format("gallery '{0}/styles' --size 16 -q --out '{0}/out'", dir));
  EXPECT_EQ(run.exit_code, 3) << run.output;
  EXPECT_NE(run.output.find("b_night.toml:"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("night.star_catalogue"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(dir + "/out/a_natural")) << run.output;
  fs::remove_all(dir);
}

// The gallery's night styles (configs/styles/night_*.toml) carry their own
// date, time and place: their tiles show the stars and the moonlit sky, which
// go when the night sky is switched off.
TEST(NightGallery, NightTilesShowStarsAndMoonlight) {
  const std::string dir = testing::FreshTempDir("night_gallery");
  fs::create_directories(dir + "/styles");
  for (const char* name : {"night_moonlit", "night_moonless", "night_twilight"})
    fs::copy_file(SourceDir() + "/configs/styles/" + name + ".toml", dir + "/styles/" + name + ".toml");
  const std::string common = fmt::format("gallery '{0}/styles' --size 128 --columns 3 --vulkan-validation -q", dir);
  testing::CommandRun on = RunSkybake(common + fmt::format(" --out '{}/on'", dir));
  ASSERT_EQ(on.exit_code, 0) << on.output;
  testing::CommandRun off =
      RunSkybake(common + fmt::format(" --out '{}/off' --set night.stars=false --set night.moonlight=false", dir));
  ASSERT_EQ(off.exit_code, 0) << off.output;
  // The labels name the night sky's parts and the clock time.
  EXPECT_NE(on.output.find("stars, moonlight, airglow, sun -37.0 deg, 2024-04-23 21:00"), std::string::npos)
      << on.output;
  EXPECT_NE(on.output.find("2024-04-08 23:30"), std::string::npos) << on.output;
  auto preview = [&](const std::string& which, const std::string& name) {
    for (const auto& e : fs::directory_iterator(dir + "/" + which + "/" + name))
      if (e.path().extension() == ".png") return ReadPng(e.path().string());
    ADD_FAILURE() << "no preview for " << name;
    return Rgb8();
  };
  const Rgb8 moonless = preview("on", "night_moonless"), moonless_off = preview("off", "night_moonless");
  const Rgb8 twilight = preview("on", "night_twilight"), twilight_off = preview("off", "night_twilight");
  const Rgb8 moonlit = preview("on", "night_moonlit"), moonlit_off = preview("off", "night_moonlit");
  ASSERT_EQ(moonless.w, 256);
  // Moonless: the stars, and none without them.
  const int stars = PointsOfLight(moonless), no_stars = PointsOfLight(moonless_off);
  std::printf("points of light: moonless %d (off %d), twilight %d (off %d), moonlit %d (off %d)\n", stars, no_stars,
              PointsOfLight(twilight), PointsOfLight(twilight_off), PointsOfLight(moonlit), PointsOfLight(moonlit_off));
  EXPECT_GE(stars, 30);
  EXPECT_LE(no_stars, 1);
  // Twilight: the brightest stars come through (the rising Moon's disc is
  // in both).
  EXPECT_GT(PointsOfLight(twilight), PointsOfLight(twilight_off));
  // Moonlit: a blue sky, several times the sky without moonlight, and
  // stars through it.
  const glm::dvec3 lit = SkyMean(moonlit), unlit = SkyMean(moonlit_off);
  std::printf("moonlit sky mean RGB %.1f %.1f %.1f, without moonlight %.1f %.1f %.1f\n", lit.x, lit.y, lit.z, unlit.x,
              unlit.y, unlit.z);
  EXPECT_GT(lit.z, lit.x + 10.0);
  EXPECT_GT(lit.z, 3.0 * unlit.z);
  EXPECT_GT(PointsOfLight(moonlit), PointsOfLight(moonlit_off));
  // The sheet: three tiles of 256 x 64 under their labels.
  auto in = OIIO::ImageInput::open(dir + "/on/gallery.png");
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().width, 3 * (256 + 8) + 8);
  EXPECT_EQ(in->spec().height, 64 + 40 + 8 + 8);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace skybake
