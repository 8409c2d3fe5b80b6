// Sky style parsing: defaults, overrides, and user errors that name the
// place (file:line:column, key path) and the fix, all reported at once.
#include <cctype>
#include <sstream>

#include <gtest/gtest.h>

#include "skybake/input/config.h"
#include "test_support.h"

namespace skybake {
namespace {

std::vector<std::string> Messages(const ConfigResult& r) {
  std::vector<std::string> out;
  for (const ConfigError& e : r.errors) out.push_back(e.Format());
  return out;
}

// The one error of `r`, formatted (a test failure listing them when there
// is not exactly one).
std::string OnlyError(const ConfigResult& r) {
  EXPECT_EQ(r.errors.size(), 1u) << ::testing::PrintToString(Messages(r));
  return r.errors.size() == 1 ? r.errors[0].Format() : "";
}

TEST(ConfigTest, DefaultStyleParsesToEarthDefaults) {
  ConfigResult r = LoadSkyStyle(testing::SourceDir() + "/configs/default.toml");
  ASSERT_TRUE(r.ok()) << ::testing::PrintToString(Messages(r));
  const AtmosphereParams defaults;
  EXPECT_EQ(r.style.atmosphere.bottom_radius_km, defaults.bottom_radius_km);
  EXPECT_EQ(r.style.atmosphere.rayleigh_scattering_per_km, defaults.rayleigh_scattering_per_km);
  EXPECT_EQ(r.style.atmosphere.mie_g, defaults.mie_g);
  EXPECT_EQ(r.style.atmosphere.ground_albedo, defaults.ground_albedo);
  EXPECT_EQ(r.style.quality.view_steps, QualitySettings{}.view_steps);
  EXPECT_EQ(r.style.sun.elevation_deg, 35.0);
  EXPECT_FALSE(r.style.resolved_toml.empty());
}

TEST(ConfigTest, EmptyStyleIsAllDefaults) {
  ConfigResult r = ParseSkyStyle("", "empty.toml");
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.style.render.cube_size, 512);
  EXPECT_EQ(r.style.output.pixel_type, PixelType::kHalf);
}

TEST(ConfigTest, ResolvedTomlRoundTrips) {
  ConfigResult a = ParseSkyStyle("[sun]\nelevation_deg = 12.5\n[output]\npixel_type = \"float\"\n", "a.toml");
  ASSERT_TRUE(a.ok());
  ConfigResult b = ParseSkyStyle(a.style.resolved_toml, "resolved.toml");
  ASSERT_TRUE(b.ok()) << ::testing::PrintToString(Messages(b));
  EXPECT_EQ(b.style.resolved_toml, a.style.resolved_toml);
  EXPECT_EQ(b.style.sun.elevation_deg, 12.5);
  EXPECT_EQ(b.style.output.pixel_type, PixelType::kFloat);
}

TEST(ConfigTest, OverridesApplyOnTop) {
  ConfigResult r = ParseSkyStyle("[sun]\nelevation_deg = 30\n", "s.toml",
                                 {"sun.elevation_deg=5", "atmosphere.ground_albedo=[0.2,0.3,0.4]",
                                  "output.pixel_type=float", "render.cube_size=64"});
  ASSERT_TRUE(r.ok()) << ::testing::PrintToString(Messages(r));
  EXPECT_EQ(r.style.sun.elevation_deg, 5.0);
  EXPECT_EQ(r.style.atmosphere.ground_albedo, (Rgb{0.2, 0.3, 0.4}));
  EXPECT_EQ(r.style.output.pixel_type, PixelType::kFloat);
  EXPECT_EQ(r.style.render.cube_size, 64);
}

TEST(ConfigTest, UnknownKeyIsLocatedWithSuggestion) {
  EXPECT_EQ(OnlyError(ParseSkyStyle("[atmosphere.mie]\nscale_heigth_km = 1.2\n", "noon.toml")),
            "noon.toml:2:1: atmosphere.mie.scale_heigth_km: unknown key 'scale_heigth_km' "
            "(did you mean 'atmosphere.mie.scale_height_km'?)");
}

TEST(ConfigTest, AllErrorsAreReportedAtOnce) {
  ConfigResult r = ParseSkyStyle(
      "[atmosphere]\n"
      "bottom_radius_km = -1.0\n"
      "[atmosphere.mie]\n"
      "g = 1.0\n"
      "[render]\n"
      "cube_size = 0\n"
      "[output]\n"
      "pixel_type = \"double\"\n",
      "bad.toml");
  EXPECT_EQ(Messages(r),
            (std::vector<std::string>{"bad.toml:2:20: atmosphere.bottom_radius_km: -1 is out of range [1, 1000000]",
                                      "bad.toml:4:5: atmosphere.mie.g: 1 is out of range (-1, 1)",
                                      "bad.toml:6:13: render.cube_size: 0 is out of range [1, 8192]",
                                      "bad.toml:8:14: output.pixel_type: 'double' is not one of 'half' or 'float'"}));
}

TEST(ConfigTest, TopRadiusMustBeAboveBottom) {
  EXPECT_EQ(OnlyError(ParseSkyStyle("[atmosphere]\ntop_radius_km = 6000.0\n", "r.toml")),
            "r.toml:2:17: atmosphere.top_radius_km: top radius 6000 km must be above the bottom "
            "radius 6360 km");
}

TEST(ConfigTest, WrongTypesAndNonFiniteNumbers) {
  ConfigResult r = ParseSkyStyle(
      "[sun]\nelevation_deg = \"high\"\nazimuth_deg = nan\n[effects]\nsun_disc = 1\n"
      "[atmosphere]\nground_albedo = [0.1, 0.2]\n",
      "t.toml");
  EXPECT_EQ(Messages(r), (std::vector<std::string>{
                             "t.toml:7:17: atmosphere.ground_albedo: expected a number or an array of 3 numbers "
                             "[680 nm, 550 nm, 440 nm]",
                             "t.toml:2:17: sun.elevation_deg: expected a number, got a string",
                             "t.toml:3:15: sun.azimuth_deg: must be a finite number (got nan)",
                             "t.toml:5:12: effects.sun_disc: expected true or false, got an integer"}));
}

TEST(ConfigTest, OutputNamesCannotEscapeTheOutputFolder) {
  for (const char* name : {"../sky", "/etc/sky", "a/b", ".hidden", ""}) {
    ConfigResult r = ParseSkyStyle(std::string("[output]\nbasename = \"") + name + "\"\n", "o.toml");
    ASSERT_EQ(r.errors.size(), 1u) << name;
    EXPECT_EQ(r.errors[0].key, "output.basename");
  }
  ConfigResult faces =
      ParseSkyStyle("[output]\nface_names = [\"px\", \"nx\", \"../py\", \"ny\", \"pz\", \"nz\"]\n", "f.toml");
  ASSERT_EQ(faces.errors.size(), 1u);
  EXPECT_EQ(faces.errors[0].key, "output.face_names[2]");
}

TEST(ConfigTest, SyntaxErrorIsLocated) {
  ConfigResult r = ParseSkyStyle("[sun]\nelevation_deg = = 3\n", "syntax.toml");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].file, "syntax.toml");
  EXPECT_EQ(r.errors[0].line, 2);
}

TEST(ConfigTest, BadOverrideIsReported) {
  ConfigResult r = ParseSkyStyle("", "s.toml", {"sun.elevation_deg", "sun.elevation_deg=200"});
  EXPECT_EQ(Messages(r), (std::vector<std::string>{
                             "--set: sun.elevation_deg: expected key.path=value, e.g. --set sun.elevation_deg=10",
                             "--set sun.elevation_deg=200:1:5: sun.elevation_deg: 200 is out of range [-90, 90]"}));
}

TEST(ConfigTest, MissingFileIsReported) {
  EXPECT_EQ(OnlyError(LoadSkyStyle("/nonexistent/style.toml")),
            "/nonexistent/style.toml: (file): cannot open the style file: check the path");
}

// configs/default.toml is the template the README says to copy: naming a
// preset there, or with --set on it, must give that preset's settings.
TEST(ConfigTest, PresetInTheDefaultTemplateTakesEffect) {
  const std::string path = testing::SourceDir() + "/configs/default.toml";
  const QualitySettings reference = QualityPreset("reference"), draft = QualityPreset("draft");
  ConfigResult set = LoadSkyStyle(path, {"quality.preset=\"reference\""});
  ASSERT_TRUE(set.ok()) << ::testing::PrintToString(Messages(set));
  EXPECT_TRUE(set.warnings.empty());
  EXPECT_FALSE(set.style.quality.sky_view_lut);
  EXPECT_EQ(set.style.quality.integrator, reference.integrator);
  EXPECT_EQ(set.style.quality.view_steps, reference.view_steps);
  EXPECT_EQ(set.style.quality.transmittance_width, reference.transmittance_width);
  EXPECT_EQ(set.style.quality.transmittance_steps, reference.transmittance_steps);

  // The copied file with its preset line edited.
  std::string text = testing::ReadFileBytes(path);
  const std::string line = "preset = \"production\"";
  ASSERT_NE(text.find(line), std::string::npos);
  text.replace(text.find(line), line.size(), "preset = \"draft\"");
  ConfigResult edited = ParseSkyStyle(text, "copy.toml");
  ASSERT_TRUE(edited.ok()) << ::testing::PrintToString(Messages(edited));
  EXPECT_TRUE(edited.warnings.empty());
  EXPECT_EQ(edited.style.quality.sky_view_width, draft.sky_view_width);
  EXPECT_EQ(edited.style.quality.sky_view_height, draft.sky_view_height);
  EXPECT_EQ(edited.style.quality.view_steps, draft.view_steps);

  // As shipped it is the production preset, without a warning, and the values
  // its comments show are production's: uncommented, they resolve the same.
  ConfigResult shipped = LoadSkyStyle(path);
  ASSERT_TRUE(shipped.ok());
  EXPECT_TRUE(shipped.warnings.empty());
  std::string original = testing::ReadFileBytes(path), uncommented;
  size_t begin = original.find("[quality]\n"), end = original.find("\n[", begin + 1);
  ASSERT_NE(end, std::string::npos);
  std::istringstream lines(original.substr(begin, end - begin));
  int keys = 0;
  for (std::string l; std::getline(lines, l);) {
    if (l.rfind("# ", 0) == 0 && l.size() > 2 && std::islower(static_cast<unsigned char>(l[2])) &&
        l.find(" = ") != std::string::npos && l.find(' ', 2) == l.find(" = ")) {
      l = l.substr(2);
      ++keys;
    }
    uncommented += l + "\n";
  }
  EXPECT_EQ(keys, 28);  // 13 for the clear sky, 3 for twilight, 12 for the cloud layers
  ConfigResult spelled = ParseSkyStyle(original.substr(0, begin) + uncommented + original.substr(end), "spelled.toml");
  ASSERT_TRUE(spelled.ok()) << ::testing::PrintToString(Messages(spelled));
  EXPECT_EQ(spelled.style.resolved_toml, shipped.style.resolved_toml);
  EXPECT_EQ(spelled.warnings.size(), 1u);  // every key given: the preset changes nothing
}

// Explicit [quality] keys refine the preset; when they give every key in which
// the presets differ, the preset changes nothing, and the style says so.
TEST(ConfigTest, PresetOverriddenByEveryKeyWarns) {
  const std::string all_keys =
      "[quality]\npreset = \"reference\"\nintegrator = \"analytic\"\nsky_view_lut = true\n"
      "sky_view_lut_width = 256\nsky_view_lut_height = 144\nview_steps = 32\ntransmittance_steps = 256\n"
      "transmittance_lut_width = 256\ntransmittance_lut_height = 64\ntwilight_march_band_deg = 10.0\n"
      "twilight_march_steps = 64\n";
  ConfigResult r = ParseSkyStyle(all_keys, "q.toml");
  ASSERT_TRUE(r.ok()) << ::testing::PrintToString(Messages(r));
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0].Format(),
            "q.toml:2:10: quality.preset: preset 'reference' changes nothing: every key it sets is given "
            "explicitly (quality.integrator, quality.sky_view_lut, quality.sky_view_lut_height, "
            "quality.sky_view_lut_width, quality.transmittance_lut_height, quality.transmittance_lut_width, "
            "quality.transmittance_steps, quality.twilight_march_band_deg, quality.twilight_march_steps, "
            "quality.view_steps), and explicit keys refine the preset; remove or "
            "comment out those keys to use it");
  EXPECT_TRUE(r.style.quality.sky_view_lut);  // the explicit keys still win
  EXPECT_EQ(r.style.quality.view_steps, 32);

  // The same through --set on a file that gives every key.
  ConfigResult set = ParseSkyStyle(all_keys, "q.toml", {"quality.preset=draft"});
  ASSERT_EQ(set.warnings.size(), 1u);
  EXPECT_EQ(set.warnings[0].file, "--set quality.preset=draft");

  // One key left to the preset: it has an effect, no warning.
  std::string missing = all_keys;
  missing.erase(missing.find("view_steps = 32\n"), std::string("view_steps = 32\n").size());
  ConfigResult partial = ParseSkyStyle(missing, "q.toml");
  ASSERT_TRUE(partial.ok());
  EXPECT_TRUE(partial.warnings.empty());
  EXPECT_EQ(partial.style.quality.view_steps, QualityPreset("reference").view_steps);

  // No preset named: nothing to warn about.
  std::string unnamed = all_keys;
  unnamed.erase(unnamed.find("preset = \"reference\"\n"), std::string("preset = \"reference\"\n").size());
  ConfigResult none = ParseSkyStyle(unnamed, "q.toml");
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none.warnings.empty());
}

}  // namespace
}  // namespace skybake
