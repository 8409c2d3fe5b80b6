// The spectral mode on lavapipe (spectral_sky.h), under the validation
// layer: the white-spectrum check, energy consistency with the
// three-wavelength renderer, the combination, and the style's checks.
#include "skybake/gpu/spectral_sky.h"

#include <cmath>
#include <map>
#include <sstream>

#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <gtest/gtest.h>

#include "skybake/input/config.h"
#include "skybake/model/spectrum.h"
#include "skybake/tools/spectral_study.h"
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
  ConfigResult night = errors("[quality]\nwavelengths = 8\n[effects]\nnight_dimming = true\n");
  ASSERT_EQ(night.errors.size(), 1u);
  EXPECT_EQ(night.errors[0].line, 2);
  EXPECT_NE(night.errors[0].message.find("effects.night_dimming"), std::string::npos);
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
  EXPECT_EQ(good.style.output.color_space, ColorSpace::kAcesCg);
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
  const testing::CommandRun bake = testing::RunSkybake(
      "bake " + testing::SourceDir() + "/configs/default.toml -q --size 8 --out " + out +
      " --set quality.wavelengths=8 --set effects.night_dimming=true");
  EXPECT_EQ(bake.exit_code, 3) << bake.output;
  EXPECT_TRUE(testing::FileNames(out).empty()) << "nothing written";
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
  for (const char* file : {"spectral.csv", "spectral_results.md", "spectral_twilight_rgb3.png", "spectral_twilight_48.png"})
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

}  // namespace
}  // namespace skybake
