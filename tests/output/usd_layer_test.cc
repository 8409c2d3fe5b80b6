// The USD sky layer (usd_layer.h): its strings and rotation on the CPU, then
// bakes on lavapipe (validation layer on) read back by TinyUSDZ, an USD
// parser independent of skybake (npm tinyusdz, WebAssembly, in headless
// Chromium: tests/viewer/usd_layer.html). The layer parses with no error;
// the lights hold the values of the manifest; the Sun's direction, as
// TinyUSDZ evaluates the light's transform, is the brightest texel of the
// dome's latlong EXR (output.sun = "map" puts the disc in it) mapped as
// UsdLux maps a latlong dome, OpenEXR's layout (Imf::LatLongMap); a
// sequence has a sample per frame; merged shards write the whole bake's
// layer; a layer that cannot be written stops the bake before anything is.
#include <cmath>
#include <filesystem>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <glm/glm.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <OpenEXR/ImfEnvmap.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfRgbaFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include "skybake/output/usd_layer.h"
#include "test_support.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

double AngleDeg(const glm::dvec3& a, const glm::dvec3& b) {
  return std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0)) * 180.0 / M_PI;
}

// Where xformOp:rotateXYZ = (x, y, 0) degrees takes +Z: Rx first, then Ry.
glm::dvec3 PlusZAfterRotateXyz(double x_deg, double y_deg) {
  const double a = x_deg * M_PI / 180.0, b = y_deg * M_PI / 180.0;
  return {std::cos(a) * std::sin(b), -std::sin(a), std::cos(a) * std::cos(b)};
}

json ReadJson(const std::string& path) { return json::parse(testing::ReadFileBytes(path)); }

// The layer read by TinyUSDZ: the page's report.
json ReadWithTinyUsdz(const std::string& dir, const std::string& layer = "sky.usda") {
  const json line = testing::RunViewerPage("usd_layer.html", dir, dir + "/screenshot.png", "layer=" + layer);
  return line.is_null() ? json() : line["report"];
}

// One prim's block of TinyUSDZ's printed layer: from `header` to the line
// closing it at the header's indentation.
std::string PrimBlock(const std::string& text, const std::string& header) {
  const size_t at = text.find(header);
  if (at == std::string::npos) return "";
  const size_t line = text.rfind('\n', at) + 1;
  const std::string indent = text.substr(line, at - line);
  const size_t end = text.find("\n" + indent + "}\n", at);
  return text.substr(at, end == std::string::npos ? std::string::npos : end - at);
}

// The value written after `decl = ` in a block, or "" when absent (without
// the " (" that opens its metadata).
std::string ValueOf(const std::string& block, const std::string& decl) {
  const size_t at = block.find(decl + " = ");
  if (at == std::string::npos) return "";
  const size_t start = at + decl.size() + 3;
  std::string value = block.substr(start, block.find('\n', start) - start);
  if (value.size() > 2 && value.compare(value.size() - 2, 2, " (") == 0) value.resize(value.size() - 2);
  return value;
}

// The colorSpace metadata of `decl` in a block (after its value, or on a
// declaration of its own before its time samples), or "" when absent.
std::string ColorSpaceOf(const std::string& block, const std::string& decl) {
  static const std::regex kColorSpace(R"(^\s*colorSpace = \"([^"]*)\"\s*$)");
  for (const std::string& opening : {decl + " (\n", decl + " = "}) {
    size_t at = block.find(opening);
    if (at == std::string::npos) continue;
    const size_t eol = block.find('\n', at);
    if (opening.back() != '\n' && block.compare(eol - 2, 2, " (") != 0) continue;
    const size_t next = block.find('\n', eol + 1);
    std::smatch m;
    const std::string line = block.substr(eol + 1, next - eol - 1);
    if (std::regex_match(line, m, kColorSpace)) return m[1];
  }
  return "";
}

// The time samples of `decl` in a block: time code -> value text.
std::map<int, std::string> SamplesOf(const std::string& block, const std::string& decl) {
  std::map<int, std::string> samples;
  const size_t at = block.find(decl + ".timeSamples = {");
  if (at == std::string::npos) return samples;
  const size_t end = block.find('}', at);
  static const std::regex kSample(R"(^\s*(-?\d+(?:\.\d+)?): (.*),\s*$)");
  std::string body = block.substr(at, end - at);
  size_t pos = body.find('\n') + 1;
  while (pos < body.size()) {
    const size_t eol = body.find('\n', pos);
    const std::string line = body.substr(pos, eol == std::string::npos ? std::string::npos : eol - pos);
    std::smatch m;
    if (std::regex_match(line, m, kSample)) samples[int(std::lround(std::stod(m[1])))] = m[2];
    if (eol == std::string::npos) break;
    pos = eol + 1;
  }
  return samples;
}

// "(a, b, c)" as three numbers.
glm::dvec3 Triple(const std::string& text) {
  glm::dvec3 v(NAN);
  std::sscanf(text.c_str(), " (%lf, %lf, %lf)", &v.x, &v.y, &v.z);
  return v;
}

double Number(const std::string& text) { return text.empty() ? NAN : std::stod(text); }

// The direction of the brightest texel (Rec.709 luminance) of a latlong
// EXR, by OpenEXR's latlong mapping.
glm::dvec3 BrightestTexelDirection(const std::string& path) {
  Imf::RgbaInputFile in(path.c_str());
  const Imath::Box2i window = in.dataWindow();
  const int width = window.max.x - window.min.x + 1, height = window.max.y - window.min.y + 1;
  std::vector<Imf::Rgba> pixels(size_t(width) * height);
  in.setFrameBuffer(pixels.data() - window.min.x - size_t(window.min.y) * width, 1, size_t(width));
  in.readPixels(window.min.y, window.max.y);
  size_t best = 0;
  double best_y = -1.0;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const double y = 0.2126 * float(pixels[i].r) + 0.7152 * float(pixels[i].g) + 0.0722 * float(pixels[i].b);
    if (y > best_y) best_y = y, best = i;
  }
  const Imath::V3f d = Imf::LatLongMap::direction(
      window, Imath::V2f(float(window.min.x + int(best % width)), float(window.min.y + int(best / width))));
  return {d.x, d.y, d.z};
}

double ExrScale(const std::string& path) {
  Imf::InputFile in(path.c_str());
  const Imf::StringAttribute* scale = in.header().findTypedAttribute<Imf::StringAttribute>("skybake:scale");
  return scale ? std::stod(scale->value()) : 1.0;
}

void ExpectRelativelyNear(double actual, double expected, double tolerance, const std::string& what) {
  EXPECT_NEAR(actual, expected, tolerance * std::max(1e-30, std::abs(expected))) << what;
}

// A distant light's values in TinyUSDZ's text against a manifest light
// (illuminance_lux, irradiance) at one frame: intensity (lux), colour
// (irradiance / illuminance), exposure 0, normalize on.
void ExpectDistantLight(const std::string& intensity, const std::string& color, const json& light,
                        const std::string& what) {
  const double lux = light["illuminance_lux"].get<double>();
  const std::vector<double> irradiance = light["irradiance"].get<std::vector<double>>();
  const glm::dvec3 c = Triple(color);
  if (lux <= 0.0) {  // below the horizon: dark, white
    EXPECT_EQ(Number(intensity), 0.0) << what;
    EXPECT_EQ(c, glm::dvec3(1.0)) << what;
    return;
  }
  ExpectRelativelyNear(Number(intensity), lux, 1e-6, what + " intensity");
  for (int i = 0; i < 3; ++i) ExpectRelativelyNear(c[i], irradiance[size_t(i)] / lux, 1e-6, what + " colour");
}

TEST(UsdLayerTest, StringsAndAssetPathsAreEscaped) {
  EXPECT_EQ(UsdStringLiteral("plain"), "\"plain\"");
  EXPECT_EQ(UsdStringLiteral("a\"b\\c\nd\te\x01"), "\"a\\\"b\\\\c\\nd\\te\\x01\"");
  EXPECT_EQ(UsdStringLiteral("caf\xc3\xa9"), "\"caf\xc3\xa9\"");  // UTF-8 kept
  EXPECT_EQ(UsdAssetPathLiteral("./sky_latlong.0001.exr"), "@./sky_latlong.0001.exr@");
  EXPECT_EQ(UsdAssetPathLiteral("./a@b.exr"), "@@@./a@b.exr@@@");
  EXPECT_EQ(UsdAssetPathLiteral("./a@@@b.exr"), "@@@./a\\@@@b.exr@@@");
}

// Known answers: the zenith, the horizon towards East (+X), North (-Z) and
// South-West at 30 deg.
TEST(UsdLayerTest, RotationTurnsPlusZTowardsTheSource) {
  const std::vector<glm::dvec3> directions = {
      {0.0, 1.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 0.0, -1.0}, glm::normalize(glm::dvec3(-1.0, 1.1547, 1.0))};
  for (const glm::dvec3& d : directions) {
    const glm::dvec3 r = UsdRotateXyzTowards(d);
    EXPECT_EQ(r.z, 0.0);
    EXPECT_LT(AngleDeg(PlusZAfterRotateXyz(r.x, r.y), d), 1e-9) << d.x << " " << d.y << " " << d.z;
  }
  EXPECT_NEAR(UsdRotateXyzTowards({0.0, 0.0, -1.0}).y, 180.0, 1e-9);
  EXPECT_NEAR(UsdRotateXyzTowards({1.0, 0.0, 0.0}).y, 90.0, 1e-9);
}

// One frame at size 512 (a 1024 x 512 latlong, 0.35 deg a texel) with the
// disc in the maps, half float: the files carry a power-of-two scale that
// the dome's exposure undoes.
TEST(UsdLayerTest, SingleBakeParsesWithItsLightsAndTheSunOnTheBrightestTexel) {
  const std::string dir = testing::FreshTempDir("usd_single");
  const testing::CommandRun bake = testing::RunSkybake(
      "bake " + testing::SourceDir() +
      "/configs/default.toml --size 512 --usd -q --vulkan-validation "
      "--set output.sun=\"map\" --set output.faces=false --set output.cube_strip=false --set sun.azimuth_deg=230 "
      "--out " +
      dir);
  ASSERT_EQ(bake.exit_code, 0) << bake.output;
  EXPECT_NE(bake.output.find(dir + "/sky.usda"), std::string::npos) << "the layer is not listed:\n" << bake.output;

  const json manifest = ReadJson(dir + "/manifest.json");
  const json& frame = manifest["frames"][0];
  bool listed = false;
  for (const json& f : manifest["scene"])
    if (f["file"] == "sky.usda" && f["kind"] == "usd") {
      listed = true;
      EXPECT_EQ(f["bytes"].get<uint64_t>(), fs::file_size(dir + "/sky.usda"));
    }
  EXPECT_TRUE(listed) << manifest["scene"].dump();

  const json report = ReadWithTinyUsdz(dir);
  ASSERT_TRUE(report.is_object());
  ASSERT_EQ(report.value("ok", false), true) << report.dump();
  EXPECT_TRUE(report["layer_loaded"].get<bool>()) << report["layer_error"];
  EXPECT_EQ(report["layer_error"], "");
  EXPECT_TRUE(report["stage_loaded"].get<bool>()) << report["stage_error"];
  const std::string text = report["text"].get<std::string>();
  std::printf("TinyUSDZ reads sky.usda as:\n%s\n", text.c_str());

  EXPECT_NE(text.find("upAxis = \"Y\""), std::string::npos);
  EXPECT_NE(text.find("metersPerUnit = 1"), std::string::npos);

  // The dome: the latlong EXR, its scale undone by the exposure.
  const std::string dome = PrimBlock(text, "def DomeLight \"Dome\"");
  ASSERT_FALSE(dome.empty()) << text;
  EXPECT_EQ(ValueOf(dome, "asset inputs:texture:file"), "@./sky_latlong.exr@");
  EXPECT_TRUE(fs::is_regular_file(dir + "/sky_latlong.exr"));
  EXPECT_EQ(ValueOf(dome, "token inputs:texture:format"), "\"latlong\"");
  EXPECT_EQ(Number(ValueOf(dome, "float inputs:intensity")), 1.0);
  const double scale = ExrScale(dir + "/sky_latlong.exr");
  EXPECT_LT(scale, 1.0) << "the disc in half floats should need a scale";
  // The header keeps 9 digits of the power of two; the exposure is its exponent.
  const double exposure = Number(ValueOf(dome, "float inputs:exposure"));
  EXPECT_EQ(exposure, std::round(-std::log2(scale)));
  ExpectRelativelyNear(std::exp2(-exposure), scale, 1e-8, "2^-exposure against skybake:scale");
  EXPECT_EQ(manifest["half_scale"].get<double>(), std::exp2(-exposure));

  // The Sun: lux, colour, angular diameter, normalize.
  const std::string sun = PrimBlock(text, "def DistantLight \"Sun\"");
  ASSERT_FALSE(sun.empty()) << text;
  ExpectDistantLight(ValueOf(sun, "float inputs:intensity"), ValueOf(sun, "color3f inputs:color"), frame["sun"], "sun");
  EXPECT_EQ(Number(ValueOf(sun, "float inputs:exposure")), 0.0);
  EXPECT_EQ(ValueOf(sun, "bool inputs:normalize"), "1");
  ExpectRelativelyNear(Number(ValueOf(sun, "float inputs:angle")),
                       2.0 * frame["sun"]["angular_radius_rad"].get<double>() * 180.0 / M_PI, 1e-6, "angle");
  EXPECT_EQ(PrimBlock(text, "def DistantLight \"Moon\""), "") << "a day bake has no Moon";

  // Its direction as TinyUSDZ evaluates the transform: the third row of the
  // light's world matrix (row vectors) is its +Z, towards the Sun.
  glm::dvec3 plus_z(NAN);
  int lights = 0;
  for (const json& node : report["nodes"])
    if (node["type"] == "directionalLight") {
      ++lights;
      const std::vector<double> m = node["matrix"].get<std::vector<double>>();
      ASSERT_EQ(m.size(), 16u);
      plus_z = {m[8], m[9], m[10]};
    }
  ASSERT_EQ(lights, 1) << report["nodes"].dump();
  bool dome_node = false;
  for (const json& node : report["nodes"]) dome_node = dome_node || node["path"] == "/Sky/Dome";
  EXPECT_TRUE(dome_node) << report["nodes"].dump();
  const std::vector<double> manifest_sun = frame["sun"]["direction"].get<std::vector<double>>();
  const glm::dvec3 sun_direction(manifest_sun[0], manifest_sun[1], manifest_sun[2]);
  EXPECT_LT(AngleDeg(plus_z, sun_direction), 1e-3);
  const glm::dvec3 texel = BrightestTexelDirection(dir + "/sky_latlong.exr");
  const double off = AngleDeg(plus_z, texel);
  std::printf("sun light (TinyUSDZ) %.5f %.5f %.5f, brightest texel %.5f %.5f %.5f: %.3f deg apart\n", plus_z.x,
              plus_z.y, plus_z.z, texel.x, texel.y, texel.z, off);
  EXPECT_LT(off, 0.5);
  // The rotation TinyUSDZ composed is the one the sequence test decodes.
  const glm::dvec3 r = Triple(ValueOf(sun, "float3 xformOp:rotateXYZ"));
  EXPECT_LT(AngleDeg(PlusZAfterRotateXyz(r.x, r.y), plus_z), 1e-3);
  fs::remove_all(dir);
}

// Three frames from a day and a night at Paranal (the night sky's Moon,
// stars off): every light value a time sample per frame, at the frame
// numbers, the dome's texture each frame's EXR; the Moon where the frame
// has its light.
TEST(UsdLayerTest, SequenceHasTimeSamplesForEveryFrame) {
  const std::string dir = testing::FreshTempDir("usd_sequence");
  const std::string schedule = testing::WriteFile(dir, "schedule.toml", R"([schedule]
first_frame = 7
date = 2024-04-23
latitude_deg = -24.6272
longitude_deg = -70.4042
utc_offset_hours = -4.0
times = [12:00:00, 16:00:00, 21:00:00]
)");
  const std::string out = dir + "/out";
  testing::BakeSequence16(testing::SourceDir() + "/configs/night/moonlit.toml", schedule, out,
                          "--usd --set night.stars=false");
  const json manifest = ReadJson(out + "/manifest.json");
  ASSERT_EQ(manifest["frames"].size(), 3u);
  const json report = ReadWithTinyUsdz(out);
  ASSERT_TRUE(report.is_object());
  ASSERT_EQ(report.value("ok", false), true) << report.dump();
  EXPECT_TRUE(report["layer_loaded"].get<bool>()) << report["layer_error"];
  EXPECT_TRUE(report["stage_loaded"].get<bool>()) << report["stage_error"];
  const std::string text = report["text"].get<std::string>();
  std::printf("TinyUSDZ reads the sequence's sky.usda as:\n%s\n", text.c_str());
  EXPECT_NE(text.find("startTimeCode = 7"), std::string::npos);
  EXPECT_NE(text.find("endTimeCode = 9"), std::string::npos);
  EXPECT_NE(text.find("timeCodesPerSecond = 24"), std::string::npos);

  const std::string dome = PrimBlock(text, "def DomeLight \"Dome\"");
  const std::string sun = PrimBlock(text, "def DistantLight \"Sun\"");
  const std::string moon = PrimBlock(text, "def DistantLight \"Moon\"");
  ASSERT_FALSE(dome.empty() || sun.empty()) << text;
  const std::map<int, std::string> textures = SamplesOf(dome, "asset inputs:texture:file");
  const std::map<int, std::string> intensities = SamplesOf(sun, "float inputs:intensity");
  const std::map<int, std::string> colours = SamplesOf(sun, "color3f inputs:color");
  const std::map<int, std::string> rotations = SamplesOf(sun, "float3 xformOp:rotateXYZ");
  const std::map<int, std::string> moon_intensities = SamplesOf(moon, "float inputs:intensity");
  const std::map<int, std::string> moon_colours = SamplesOf(moon, "color3f inputs:color");
  const std::map<int, std::string> moon_rotations = SamplesOf(moon, "float3 xformOp:rotateXYZ");
  int moonlit = 0;
  for (const json& frame : manifest["frames"]) {
    const int n = frame["frame"].get<int>();
    const std::string what = fmt::format("frame {}", n);
    ASSERT_TRUE(textures.count(n) && intensities.count(n) && colours.count(n) && rotations.count(n)) << what;
    EXPECT_EQ(textures.at(n), fmt::format("@./sky_latlong.{:04d}.exr@", n)) << what;
    ExpectDistantLight(intensities.at(n), colours.at(n), frame["sun"], what + " sun");
    const std::vector<double> d = frame["sun"]["direction"].get<std::vector<double>>();
    const glm::dvec3 r = Triple(rotations.at(n));
    EXPECT_LT(AngleDeg(PlusZAfterRotateXyz(r.x, r.y), {d[0], d[1], d[2]}), 1e-3) << what;
    if (frame.contains("moon") && frame["moon"]["light"].get<bool>()) {
      moonlit += frame["moon"]["illuminance_lux"].get<double>() > 0.0;
      ASSERT_TRUE(moon_intensities.count(n) && moon_colours.count(n) && moon_rotations.count(n)) << what << moon;
      ExpectDistantLight(moon_intensities.at(n), moon_colours.at(n), frame["moon"], what + " moon");
      const std::vector<double> m = frame["moon"]["direction"].get<std::vector<double>>();
      const glm::dvec3 mr = Triple(moon_rotations.at(n));
      EXPECT_LT(AngleDeg(PlusZAfterRotateXyz(mr.x, mr.y), {m[0], m[1], m[2]}), 1e-3) << what;
    } else if (!moon.empty()) {
      ASSERT_TRUE(moon_intensities.count(n)) << what;
      EXPECT_EQ(Number(moon_intensities.at(n)), 0.0) << what << ": no moonlight, no Moon";
    }
  }
  EXPECT_EQ(moonlit, 1) << "the night frame (21:00) has the Moon's light, above the horizon";
  fs::remove_all(dir);
}

// Every output colour space writes a layer: the dome's texture names the
// EXR's space in USD's colorSpace metadata (the canonical names of USD's
// colour guide), the lights keep linear Rec.709 colours (colorSpace
// "lin_rec709_scene", the manifest's irradiance), and the customData says
// both; TinyUSDZ reads each back. A sequence puts the metadata on a
// declaration before the texture's time samples.
TEST(UsdLayerTest, EveryColourSpaceNamesTheDomeTexturesSpace) {
  const std::string root = testing::FreshTempDir("usd_color_space");
  const std::vector<std::pair<std::string, std::string>> spaces = {{"rec709", "lin_rec709_scene"},
                                                                   {"acescg", "lin_ap1_scene"},
                                                                   {"aces2065-1", "lin_ap0_scene"},
                                                                   {"rec2020", "lin_rec2020_scene"},
                                                                   {"xyz", "lin_ciexyzd65_scene"}};
  for (const auto& [space, token] : spaces) {
    EXPECT_EQ(UsdColorSpaceToken(space), token);
    const std::string dir = root + "/" + space;
    const testing::CommandRun bake = testing::RunSkybake("bake " + testing::SourceDir() +
                                                         "/configs/default.toml --size 16 --usd -q --vulkan-validation "
                                                         "--set output.color_space=\"" +
                                                         space + "\" --out " + dir);
    ASSERT_EQ(bake.exit_code, 0) << space << ": " << bake.output;
    const json report = ReadWithTinyUsdz(dir);
    ASSERT_TRUE(report.is_object());
    ASSERT_EQ(report.value("ok", false), true) << report.dump();
    EXPECT_TRUE(report["layer_loaded"].get<bool>()) << space << ": " << report["layer_error"];
    EXPECT_TRUE(report["stage_loaded"].get<bool>()) << space << ": " << report["stage_error"];
    const std::string text = report["text"].get<std::string>();
    const std::string dome = PrimBlock(text, "def DomeLight \"Dome\"");
    const std::string sun = PrimBlock(text, "def DistantLight \"Sun\"");
    ASSERT_FALSE(dome.empty() || sun.empty()) << text;
    EXPECT_EQ(ValueOf(dome, "asset inputs:texture:file"), "@./sky_latlong.exr@") << space;
    EXPECT_EQ(ColorSpaceOf(dome, "asset inputs:texture:file"), token) << space << "\n" << dome;
    EXPECT_EQ(ColorSpaceOf(sun, "color3f inputs:color"), "lin_rec709_scene") << space << "\n" << sun;
    const json manifest = ReadJson(dir + "/manifest.json");
    ExpectDistantLight(ValueOf(sun, "float inputs:intensity"), ValueOf(sun, "color3f inputs:color"),
                       manifest["frames"][0]["sun"], space + " sun");
    EXPECT_NE(text.find("string dome_color_space = \"" + token + "\""), std::string::npos) << space;
    EXPECT_NE(text.find("string light_color_space = \"lin_rec709_scene\""), std::string::npos) << space;
    // The EXR the dome names is in that space (its header says so).
    Imf::InputFile exr((dir + "/sky_latlong.exr").c_str());
    const auto* name = exr.header().findTypedAttribute<Imf::StringAttribute>("skybake:color_space");
    ASSERT_NE(name, nullptr);
    EXPECT_EQ(name->value(), space);
  }

  // A space of an OpenColorIO config keeps the config's name.
  {
    const std::string dir = root + "/config";
    const testing::CommandRun bake =
        testing::RunSkybake("bake " + testing::SourceDir() +
                            "/configs/default.toml --size 16 --usd -q --vulkan-validation "
                            "--set 'output.color_space=\"Linear P3-D65\"' --set 'output.ocio_config=\"" +
                            testing::SourceDir() + "/tests/colour/ocio/test_config.ocio\"' --out " + dir);
    ASSERT_EQ(bake.exit_code, 0) << bake.output;
    const json report = ReadWithTinyUsdz(dir);
    ASSERT_TRUE(report.is_object());
    ASSERT_EQ(report.value("ok", false), true) << report.dump();
    EXPECT_TRUE(report["layer_loaded"].get<bool>()) << report["layer_error"];
    EXPECT_TRUE(report["stage_loaded"].get<bool>()) << report["stage_error"];
    const std::string text = report["text"].get<std::string>();
    const std::string dome = PrimBlock(text, "def DomeLight \"Dome\"");
    EXPECT_EQ(ColorSpaceOf(dome, "asset inputs:texture:file"), "Linear P3-D65") << dome;
  }

  // A sequence in ACEScg: the metadata before the texture's time samples.
  const std::string schedule = testing::WriteFile(root, "schedule.toml", R"([schedule]
first_frame = 1
[[schedule.frames]]
elevation_deg = 10.0
azimuth_deg = 120.0
[[schedule.frames]]
elevation_deg = 30.0
azimuth_deg = 150.0
)");
  const std::string out = root + "/sequence";
  testing::BakeSequence16(testing::SourceDir() + "/configs/default.toml", schedule, out,
                          "--usd --set output.color_space=\"acescg\"");
  const json report = ReadWithTinyUsdz(out);
  ASSERT_TRUE(report.is_object());
  ASSERT_EQ(report.value("ok", false), true) << report.dump();
  EXPECT_TRUE(report["layer_loaded"].get<bool>()) << report["layer_error"];
  EXPECT_TRUE(report["stage_loaded"].get<bool>()) << report["stage_error"];
  const std::string text = report["text"].get<std::string>();
  std::printf("TinyUSDZ reads the ACEScg sequence's sky.usda as:\n%s\n", text.c_str());
  const std::string dome = PrimBlock(text, "def DomeLight \"Dome\"");
  const std::string sun = PrimBlock(text, "def DistantLight \"Sun\"");
  EXPECT_EQ(ColorSpaceOf(dome, "asset inputs:texture:file"), "lin_ap1_scene") << dome;
  EXPECT_EQ(ColorSpaceOf(sun, "color3f inputs:color"), "lin_rec709_scene") << sun;
  const std::map<int, std::string> textures = SamplesOf(dome, "asset inputs:texture:file");
  const std::map<int, std::string> colours = SamplesOf(sun, "color3f inputs:color");
  const std::map<int, std::string> intensities = SamplesOf(sun, "float inputs:intensity");
  const json manifest = ReadJson(out + "/manifest.json");
  ASSERT_EQ(manifest["frames"].size(), 2u);
  for (const json& frame : manifest["frames"]) {
    const int n = frame["frame"].get<int>();
    ASSERT_TRUE(textures.count(n) && colours.count(n) && intensities.count(n)) << n << "\n" << text;
    EXPECT_EQ(textures.at(n), fmt::format("@./sky_latlong.{:04d}.exr@", n));
    ExpectDistantLight(intensities.at(n), colours.at(n), frame["sun"], fmt::format("frame {} sun", n));
  }
  fs::remove_all(root);
}

// A sequence baked in two shards and merged writes the whole bake's layer,
// byte for byte, and so does a resumed bake; a frame whose style sets its
// own solar disc gives the Sun's angle a sample of its own.
TEST(UsdLayerTest, MergedShardsAndResumeWriteTheWholeBakesLayer) {
  const std::string root = testing::FreshTempDir("usd_merge");
  const std::string style = testing::SourceDir() + "/configs/default.toml";
  const std::string schedule = testing::WriteFile(root, "schedule.toml", R"([schedule]
[[schedule.frames]]
elevation_deg = 5.0
azimuth_deg = 100.0
[[schedule.frames]]
elevation_deg = 20.0
azimuth_deg = 140.0
set = { "sun.angular_radius_rad" = 0.009 }
[[schedule.frames]]
elevation_deg = 40.0
azimuth_deg = 180.0
[[schedule.frames]]
elevation_deg = 60.0
azimuth_deg = 220.0
)");
  testing::BakeSequence16(style, schedule, root + "/whole", "--usd");
  const json report = ReadWithTinyUsdz(root + "/whole");
  ASSERT_TRUE(report.is_object());
  ASSERT_EQ(report.value("ok", false), true) << report.dump();
  EXPECT_TRUE(report["layer_loaded"].get<bool>()) << report["layer_error"];
  const std::map<int, std::string> angles =
      SamplesOf(PrimBlock(report["text"].get<std::string>(), "def DistantLight \"Sun\""), "float inputs:angle");
  ASSERT_EQ(angles.size(), 4u) << report["text"].get<std::string>();
  ExpectRelativelyNear(Number(angles.at(1)), 2.0 * 0.004675 * 180.0 / M_PI, 1e-6, "frame 1's angle");
  ExpectRelativelyNear(Number(angles.at(2)), 2.0 * 0.009 * 180.0 / M_PI, 1e-6, "frame 2's angle");
  testing::BakeSequence16(style, schedule, root + "/parts", "--usd --shard 1/2");
  testing::BakeSequence16(style, schedule, root + "/parts", "--usd --shard 2/2");
  EXPECT_FALSE(fs::exists(root + "/parts/sky.usda")) << "a part writes no layer";
  const testing::CommandRun merge = testing::RunSkybake("merge-manifest " + root + "/parts");
  ASSERT_EQ(merge.exit_code, 0) << merge.output;
  const std::string whole = testing::ReadFileBytes(root + "/whole/sky.usda");
  ASSERT_FALSE(whole.empty());
  EXPECT_EQ(testing::ReadFileBytes(root + "/parts/sky.usda"), whole);
  EXPECT_EQ(testing::ReadFileBytes(root + "/parts/manifest.json"),
            testing::ReadFileBytes(root + "/whole/manifest.json"));

  fs::remove(root + "/whole/sky_latlong.0002.exr");
  testing::BakeSequence16(style, schedule, root + "/whole", "--usd --resume");
  EXPECT_EQ(testing::ReadFileBytes(root + "/whole/sky.usda"), whole);
  fs::remove_all(root);
}

// The provenance's strings come back as written through an independent
// parser: a style path with a quote, a backslash, a space and @ signs.
TEST(UsdLayerTest, ProvenanceStringsSurviveAnIndependentParser) {
  const std::string root = testing::FreshTempDir("usd_strings");
  const std::string folder = "we\"ird\\dir @x";
  fs::create_directories(root + "/" + folder);
  const std::string style = folder + "/st@@@yle.toml";
  fs::copy_file(testing::SourceDir() + "/configs/default.toml", root + "/" + style);
  const testing::CommandRun bake = testing::RunSkybake(
      "bake 'we\"ird\\dir @x/st@@@yle.toml' --size 8 --usd -q --vulkan-validation --out out", "cd " + root + " && ");
  ASSERT_EQ(bake.exit_code, 0) << bake.output;
  EXPECT_EQ(ReadJson(root + "/out/manifest.json")["style"], style);
  const json report = ReadWithTinyUsdz(root + "/out");
  ASSERT_TRUE(report.is_object());
  ASSERT_EQ(report.value("ok", false), true) << report.dump();
  EXPECT_TRUE(report["layer_loaded"].get<bool>()) << report["layer_error"];
  // TinyUSDZ prints the string it read in single quotes, its backslash escaped.
  EXPECT_NE(report["text"].get<std::string>().find("string style = 'we\"ird\\\\dir @x/st@@@yle.toml'\n"),
            std::string::npos)
      << report["text"].get<std::string>();
  fs::remove_all(root);
}

// Off by default: no layer, no "usd" in the manifest; --usd where the layer
// cannot be written (a folder at its name) stops before any GPU work with
// exit code 5, naming it, and writes nothing; a style it cannot describe is
// refused with the located error (exit 3).
TEST(UsdLayerTest, OffByDefaultAndBadInputWritesNothing) {
  const std::string root = testing::FreshTempDir("usd_bad");
  const std::string style = testing::SourceDir() + "/configs/default.toml";
  const std::string plain = root + "/plain";
  ASSERT_EQ(testing::RunSkybake("bake " + style + " --size 8 -q --vulkan-validation --out " + plain).exit_code, 0);
  EXPECT_FALSE(fs::exists(plain + "/sky.usda"));
  EXPECT_FALSE(ReadJson(plain + "/manifest.json").contains("usd"));

  const std::string out = root + "/out";
  fs::create_directories(out + "/sky.usda");
  const testing::CommandRun folder =
      testing::RunSkybake("bake " + style + " --size 8 --usd --vulkan-validation --out " + out);
  EXPECT_EQ(folder.exit_code, 5) << folder.output;
  EXPECT_EQ(folder.output, "skybake: error: " + out +
                               "/sky.usda is a directory: an output file cannot replace it; "
                               "move it away, or choose another --out\n");
  EXPECT_EQ(testing::FileNames(out), std::set<std::string>{"sky.usda"});
  EXPECT_TRUE(testing::FileNames(out + "/sky.usda").empty());

  const std::string refused = root + "/refused";
  const testing::CommandRun no_latlong = testing::RunSkybake(
      "bake " + style + " --size 8 --usd --set output.latlong=false --vulkan-validation --out " + refused);
  EXPECT_EQ(no_latlong.exit_code, 3) << no_latlong.output;
  EXPECT_NE(no_latlong.output.find("usd.enabled: the USD layer's DomeLight is textured with the latlong EXR"),
            std::string::npos)
      << no_latlong.output;
  EXPECT_FALSE(fs::exists(refused));
  fs::remove_all(root);
}

}  // namespace
}  // namespace skybake
