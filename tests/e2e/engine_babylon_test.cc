// The babylon preset checked in Babylon.js itself (headless Chromium,
// babylonjs 9 from tests/viewer/node_modules, tests/viewer/
// engine_babylon_cube.html): `skybake testpattern --engine babylon` writes
// the preset's faces, and the page loads them as a Babylon user loads a
// skybox, CubeTexture("sky_babylon", scene, ["_px", "_py", "_pz", "_nx",
// "_ny", "_nz"]) on a StandardMaterial box in SKYBOX_MODE, in Babylon's
// default left-handed scene. A 3-degree camera looks along known directions:
// a direction d of skybake's world is g = (-d.x, d.y, d.z) in Babylon's
// (its glTF loader's root node mirrors x, docs/engines.md), and there it must
// see the face, the horizon and North's letter that the pattern puts at d.
// Babylon's CubeTexture loads images, not EXRs (its EXR loader does no cube
// of six files), so the test writes each face EXR as an 8-bit PNG of the
// same name first (the pattern's colours are in [0, 1]). skybake's own
// Vulkan faces loaded the same way show the trap the preset removes.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <glm/glm.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "skybake/pipeline/test_pattern.h"
#include "sky_and_sun.h"
#include "test_support.h"

namespace skybake {
namespace {

// `stem`.exr as an 8-bit RGB PNG `stem`.png (values clamped to [0, 1], no transfer curve).
void WritePng(const std::string& stem) {
  auto in = OIIO::ImageInput::open(stem + ".exr");
  ASSERT_TRUE(in) << stem;
  const OIIO::ImageSpec& spec = in->spec();
  std::vector<float> rgb(size_t(spec.width) * spec.height * 3);
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, rgb.data()));
  std::vector<unsigned char> bytes(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i)
    bytes[i] = (unsigned char)std::lround(std::clamp(rgb[i], 0.0f, 1.0f) * 255.0f);
  auto out = OIIO::ImageOutput::create(stem + ".png");
  ASSERT_TRUE(out);
  ASSERT_TRUE(out->open(stem + ".png", OIIO::ImageSpec(spec.width, spec.height, 3, OIIO::TypeDesc::UINT8)));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, bytes.data()));
  out->close();
}

TEST(EngineBabylonTest, TestPatternFacesAreWhereTheySayInBabylon) {
  const std::string dir = testing::FreshTempDir("engine_babylon_pattern");
  testing::CommandRun r = testing::RunSkybake("testpattern --engine babylon --size 128 --out " + dir);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* face : {"px", "nx", "py", "ny", "pz", "nz"}) {
    WritePng(dir + "/sky_babylon_" + face);
    WritePng(dir + "/sky_" + face);
  }
  // The directions of engine_threejs_test, in skybake's world: face axes 10
  // degrees below the horizon (the horizon line and the letters are above
  // or on it), the +X face's horizon and beside it, North's letter.
  const std::vector<glm::dvec3> dirs = {
      {1, -0.18, 0}, {-1, -0.18, 0}, {0, 1, 0},
      {0, -1, 0},    {0, -0.18, 1},  {0, -0.18, -1},
      {1, 0, 0.5},   {1, 0.2, 0.5},  {0, std::sin(6.0 * M_PI / 180.0), -std::cos(6.0 * M_PI / 180.0)}};
  std::string query = "bases=sky_babylon,sky&dirs=";
  for (size_t i = 0; i < dirs.size(); ++i)
    query +=
        (i ? ";" : "") + std::to_string(-dirs[i].x) + "," + std::to_string(dirs[i].y) + "," + std::to_string(dirs[i].z);
  const nlohmann::json line = testing::RunViewerPage("engine_babylon_cube.html", dir, dir + "/babylon.png", query);
  ASSERT_FALSE(line.is_null());
  const nlohmann::json report = line["report"];
  ASSERT_EQ(report.value("ok", false), true) << report.dump();
  std::printf("Babylon.js pattern: %s\n", report.dump().c_str());
  EXPECT_EQ(report["handedness"], "left") << "Babylon's default scene";
  // 8-bit faces: each colour within 2 steps of 255 of the tint.
  const double tolerance = 2.0 / 255.0;
  const auto seen = report["sky_babylon"].get<std::vector<std::vector<double>>>();
  ASSERT_EQ(seen.size(), dirs.size());
  for (int face = 0; face < 6; ++face) {
    const glm::dvec3 expected = TestPatternFaceColor(face);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(seen[size_t(face)][size_t(c)], expected[c], tolerance) << "along face " << face << " channel " << c;
  }
  // The white horizon line lifts green on the red +X face; the view above it is plain.
  EXPECT_GT(seen[6][1], TestPatternFaceColor(0)[1] + 0.1) << "horizon";
  EXPECT_NEAR(seen[7][1], TestPatternFaceColor(0)[1], tolerance) << "above the horizon";
  // North's white letter lifts blue on the yellow -Z face.
  EXPECT_GT(seen[8][2], TestPatternFaceColor(5)[2] + 0.1) << "N above the horizon at -Z";
  // skybake's own faces (Vulkan order and orientation) loaded the same way:
  // at least one face axis shows another face's tint.
  const auto plain = report["sky"].get<std::vector<std::vector<double>>>();
  ASSERT_EQ(plain.size(), dirs.size());
  int wrong = 0;
  for (int face = 0; face < 6; ++face) {
    const glm::dvec3 expected = TestPatternFaceColor(face);
    double d = 0.0;
    for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(plain[size_t(face)][size_t(c)] - expected[c]));
    wrong += d > 0.1;
  }
  EXPECT_GT(wrong, 0) << "the Vulkan faces load right in Babylon without the preset";
  std::printf("Babylon.js: %d of 6 face axes show another face with skybake's Vulkan faces\n", wrong);
}

// The preset's EXR faces as docs/engines/babylon_exr_cube.js loads them
// (Babylon's EXR decoder, a RawCubeTexture; tests/viewer/
// engine_babylon_exr_cube.html), floats, no PNG in between: the test
// pattern's faces, horizon and North where they belong (as above), and a
// default bake's sky Sun along the sun light Babylon's glTF loader makes
// of sky.glb. Babylon's CubeTexture of the .exr files, which the
// documentation named before, never becomes ready (a browser decodes no EXR
// image): the page reports that too. skybake's own Vulkan faces loaded by
// the snippet put the Sun a quarter turn off.
TEST(EngineBabylonTest, PresetsExrFacesLoadWithTheDocumentedSnippet) {
  const std::string snippet = testing::SourceDir() + "/docs/engines/babylon_exr_cube.js";
  const std::string dir = testing::FreshTempDir("engine_babylon_exr");
  testing::CommandRun r = testing::RunSkybake("testpattern --engine babylon --size 64 --out " + dir + "/pattern");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::filesystem::copy_file(snippet, dir + "/pattern/babylon_exr_cube.js");
  const std::vector<glm::dvec3> dirs = {
      {1, -0.18, 0}, {-1, -0.18, 0}, {0, 1, 0},
      {0, -1, 0},    {0, -0.18, 1},  {0, -0.18, -1},
      {1, 0, 0.5},   {1, 0.2, 0.5},  {0, std::sin(6.0 * M_PI / 180.0), -std::cos(6.0 * M_PI / 180.0)}};
  std::string query = "dirs=";
  for (size_t i = 0; i < dirs.size(); ++i)
    query +=
        (i ? ";" : "") + std::to_string(-dirs[i].x) + "," + std::to_string(dirs[i].y) + "," + std::to_string(dirs[i].z);
  nlohmann::json line =
      testing::RunViewerPage("engine_babylon_exr_cube.html", dir + "/pattern", dir + "/pattern.png", query);
  ASSERT_FALSE(line.is_null());
  nlohmann::json report = line["report"];
  ASSERT_EQ(report.value("ok", false), true) << report.dump();
  std::printf("Babylon.js EXR faces, pattern: %s\n", report.dump().c_str());
  const auto seen = report["seen"].get<std::vector<std::vector<double>>>();
  ASSERT_EQ(seen.size(), dirs.size());
  // Half floats: each colour within 1e-3 of the tint.
  for (int face = 0; face < 6; ++face)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(seen[size_t(face)][size_t(c)], TestPatternFaceColor(face)[c], 1e-3)
          << "along face " << face << " channel " << c;
  EXPECT_GT(seen[6][1], TestPatternFaceColor(0)[1] + 0.1) << "horizon";
  EXPECT_NEAR(seen[7][1], TestPatternFaceColor(0)[1], 1e-3) << "above the horizon";
  EXPECT_GT(seen[8][2], TestPatternFaceColor(5)[2] + 0.1) << "N above the horizon at -Z";

  // The CubeTexture of .exr faces: not ready (the page gives up after 30 s).
  auto [cube_code, cube_output] = testing::RunCommand(
      "cd '" + testing::SourceDir() + "/tests/viewer' && node run_page.mjs engine_babylon_cube.html '" + dir +
      "/pattern' '" + dir + "/cube.png' 'bases=sky_babylon&ext=.exr&dirs=1,0,0'");
  EXPECT_NE(cube_code, 0) << cube_output;
  EXPECT_NE(cube_output.find("sky_babylon: not ready"), std::string::npos) << cube_output;

  r = testing::RunSkybake("bake " + testing::SourceDir() +
                          "/configs/default.toml --size 64 -q --vulkan-validation --engine babylon --out " + dir +
                          "/bake");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::filesystem::copy_file(snippet, dir + "/bake/babylon_exr_cube.js");
  for (const std::string base : {"sky_babylon", "sky"}) {
    line = testing::RunViewerPage("engine_babylon_exr_cube.html", dir + "/bake", dir + "/bake.png",
                                  "scene=sky.glb&base=" + base);
    ASSERT_FALSE(line.is_null());
    report = line["report"];
    ASSERT_EQ(report.value("ok", false), true) << report.dump();
    std::printf("Babylon.js EXR faces %s: %s\n", base.c_str(), report.dump().c_str());
    const std::vector<double> v = report["radiance"].get<std::vector<double>>();
    ASSERT_EQ(v.size(), 4u);
    if (base == "sky_babylon")
      EXPECT_GT(v[0], 2.0 * std::max({v[1], v[2], v[3]})) << "the sky's Sun is not along Babylon's sun light";
    else EXPECT_LT(v[0], 0.5 * std::max({v[1], v[2], v[3]})) << "skybake's Vulkan faces load right without the preset";
  }
}

// The default bake's sky and Sun together in Babylon.js, in units (issue
// 48; sky_and_sun.h, tests/viewer/engine_babylon_sun_sky.html):
// sky_latlong.exr as an EXRCubeTexture (Babylon's own equirect EXR loader),
// the scene's environment and its default skybox; the sun through Babylon's
// glTF loader from sky.glb; an up-facing grey card (PBRMaterial, metallic 0,
// roughness 1, metallicF0Factor 0, the Lambert diffuse model); one exposure
// (image processing "by post-process" with none and skipFinalColorClamp:
// linear, unclamped, into a float render target). Babylon's glTF loader
// sets the light's intensity to the glTF intensity and its diffuse to the
// colour; a directional light's intensityMode AUTOMATIC is illuminance, a
// photometric scale of 1 (Light._getPhotometricScale), so the light is
// colour x intensity in lux; the Lambert model's diffuse term is 1 / pi
// (computeDiffuseLighting); the environment lights the card from the
// texture's spherical harmonics as irradiance / pi. So the card is
// albedo / pi x (intensity x Y(colour) x sin(elevation) + E_sky), and the
// sky the latlong's texels: the float32 bake's figures, to 5%. Measured
// (2026-12-07): the harmonics' E_sky is 10% short of the latlong's integral
// (358 against 398 cd/m^2 on the card), 1% of the card with the Sun at 35
// degrees; a lower Sun gives the sky more of it.
TEST(EngineBabylonTest, SkyAndSunShowOneExposure) {
  testing::SkyAndSun bake;
  ASSERT_TRUE(testing::BakeSkyAndSun("engine_babylon_sun_sky", bake));
  const std::string query =
      fmt::format("latlong=sky_latlong.exr&scene=sky.glb&albedo={}&fov={}&size={}&sky={}", testing::kGreyCardAlbedo,
                  testing::kProbeFovDeg, testing::kProbeSize, testing::SkyProbeQuery());
  const nlohmann::json line =
      testing::RunViewerPage("engine_babylon_sun_sky.html", bake.half_dir, bake.half_dir + "/babylon.png", query);
  ASSERT_FALSE(line.is_null());
  const nlohmann::json report = line["report"];
  ASSERT_EQ(report.value("ok", false), true) << report.dump();
  std::printf("Babylon.js: %s\n", report.dump().c_str());
  EXPECT_EQ(report["light"]["scaledIntensity"].get<double>(), bake.light_intensity)
      << "a photometric scale of 1: the glTF's lux as they are";
  testing::ExpectClientMatchesFloatBake(
      "Babylon.js " + report["version"].get<std::string>(), bake, report["sky"].get<std::vector<double>>(),
      report["card"].get<std::vector<double>>(), report["cardLightOnly"].get<std::vector<double>>(),
      report["cardEnvironmentOnly"].get<std::vector<double>>());
}

// The default glTF dome through Babylon.js's default camera
// (tests/viewer/dome_babylon.html): a UniversalCamera clips at minZ 1 and
// maxZ 10000 (Babylon.js 9 Camera); from the origin, looking along each axis,
// the dome covers every pixel.
TEST(EngineBabylonTest, DomeIsInsideTheDefaultCamerasRange) {
  const std::string dir = testing::FreshTempDir("engine_babylon_dome");
  testing::CommandRun bake = testing::RunSkybake("bake " + testing::SourceDir() +
                                                 "/configs/default.toml --size 16 -q --vulkan-validation --out " + dir);
  ASSERT_EQ(bake.exit_code, 0) << bake.output;
  const nlohmann::json line = testing::RunViewerPage("dome_babylon.html", dir, dir + "/babylon.png", "");
  ASSERT_FALSE(line.is_null());
  const nlohmann::json report = line["report"];
  ASSERT_EQ(report.value("ok", false), true) << report.dump();
  std::printf("Babylon.js dome: %s\n", report.dump().c_str());
  EXPECT_EQ(report["maxZ"].get<double>(), 10000.0) << "Babylon's default maxZ";
  const std::vector<double> covered = report["covered"].get<std::vector<double>>();
  ASSERT_EQ(covered.size(), 6u);
  for (size_t i = 0; i < covered.size(); ++i) EXPECT_EQ(covered[i], 1.0) << "view " << i << " sees past the dome";
}

}  // namespace
}  // namespace skybake
