// Light in true colour and true units (docs/colour.md), through the binary
// on lavapipe under the validation layer:
// - the three-wavelength bake's colours against the 48-bin spectral mode
//   (the reference, integrated with the CIE 1931 functions), as CIE 1976
//   u'v' distances: the Sun's light and the disc, the sunlit ground, white
//   clouds and the overcast deck, and the clear sky over the upper hemisphere;
// - the sun/sky split: a default half-float bake writes no scale, its sky in
//   cd/m^2 as the float32 bake's, and the Sun as a light;
// - a day-and-night sequence in half floats keeps its night frames.
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "skybake/model/colour_conversion.h"
#include "skybake/model/spectrum.h"
#include "test_support.h"

namespace skybake {
namespace {

using nlohmann::json;

std::array<double, 2> UvPrime(const std::array<double, 3>& rec709) {
  const Matrix3 to_xyz = Inverse(XyzToRgb(ColorSpace::kRec709));
  const std::array<double, 3> xyz = Apply(to_xyz, rec709);
  const double d = xyz[0] + 15.0 * xyz[1] + 3.0 * xyz[2];
  return {4.0 * xyz[0] / d, 9.0 * xyz[1] / d};
}

double UvDistance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  const std::array<double, 2> u = UvPrime(a), v = UvPrime(b);
  return std::hypot(u[0] - v[0], u[1] - v[1]);
}

double Luminance(const std::array<double, 3>& rgb) { return Rec709Luminance(rgb); }

struct Latlong {
  int width = 0, height = 0;
  std::vector<float> rgb;
  std::map<std::string, std::string> attributes;
  std::array<double, 3> at(int x, int y) const {
    const size_t i = 3 * (size_t(y) * width + x);
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};
Latlong ReadLatlong(const std::string& path) {
  Latlong l;
  testing::ReadRgb(path, l.width, l.height, l.rgb, &l.attributes);
  return l;
}

// Texel-by-texel u'v' distances over a band of rows, where the reference's
// luminance is above 1e-6 of the band's brightest: mean and worst.
struct Distances {
  double mean = 0.0, worst = 0.0;
  int texels = 0;
};
Distances Compare(const Latlong& test, const Latlong& ref, int first_row, int end_row) {
  double brightest = 0.0;
  for (int y = first_row; y < end_row; ++y)
    for (int x = 0; x < ref.width; ++x) brightest = std::max(brightest, Luminance(ref.at(x, y)));
  Distances d;
  for (int y = first_row; y < end_row; ++y)
    for (int x = 0; x < ref.width; ++x) {
      if (!(Luminance(ref.at(x, y)) > 1e-6 * brightest)) continue;
      const double e = UvDistance(test.at(x, y), ref.at(x, y));
      d.mean += e;
      d.worst = std::max(d.worst, e);
      ++d.texels;
    }
  if (d.texels > 0) d.mean /= d.texels;
  return d;
}

// One schedule of fixed sun positions (azimuth 135 deg), baked twice into
// DIR/rgb and DIR/spectral48 as float32 latlongs of 32 x 16 (the 48-bin
// bake is 16 renderer groups).
const std::vector<double> kElevations = {90.0, 45.0, 20.0, 10.0, 5.0, 2.0, -3.0, -6.0, -10.0};

std::string ElevationSchedule(const std::string& dir, const std::vector<double>& elevations) {
  std::string text = "[schedule]\n";
  for (double e : elevations) text += fmt::format("[[schedule.frames]]\nelevation_deg = {}\nazimuth_deg = 135.0\n", e);
  return testing::WriteFile(dir, "elevations.toml", text);
}

void BakePair(const std::string& style, const std::string& schedule, const std::string& dir, int size = 16) {
  const std::string common = " --schedule " + schedule + " --size " + std::to_string(size) +
                             " -q --vulkan-validation --set output.pixel_type=float --set output.faces=false "
                             "--set output.cube_strip=false --set output.preview=false --set gltf.enabled=false";
  for (const auto& [name, extra] :
       std::vector<std::pair<std::string, std::string>>{{"rgb", ""}, {"spectral48", " --set quality.wavelengths=48"}}) {
    const testing::CommandRun r = testing::RunSkybake("bake " + style + common + extra + " --out " + dir + "/" + name);
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
}

std::string FrameLatlong(const std::string& dir, size_t frame) {
  return fmt::format("{}/sky_latlong.{:04d}.exr", dir, frame + 1);
}

std::array<double, 3> SunIrradiance(const json& manifest, size_t frame) {
  const json& s = manifest["frames"][frame]["sun"]["irradiance"];
  return {s[0].get<double>(), s[1].get<double>(), s[2].get<double>()};
}

class ColourAgainstSpectral : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(testing::FreshTempDir("colour"));
    BakePair(testing::SourceDir() + "/configs/default.toml", ElevationSchedule(*dir_, kElevations), *dir_);
  }
  static void TearDownTestSuite() { delete dir_; }
  static const std::string& dir() { return *dir_; }
  static std::string* dir_;
};
std::string* ColourAgainstSpectral::dir_ = nullptr;

// The Sun's light (the manifest's and the glTF's colour) is the disc's: its
// colour within 0.002 of the 48-bin bake's at every elevation from 2 to 90 deg.
TEST_F(ColourAgainstSpectral, TheSunsColourMatchesTheSpectralMode) {
  const json rgb = json::parse(testing::ReadFileBytes(dir() + "/rgb/manifest.json"));
  const json ref = json::parse(testing::ReadFileBytes(dir() + "/spectral48/manifest.json"));
  for (size_t f = 0; f < kElevations.size(); ++f) {
    if (kElevations[f] < 2.0) continue;
    const double d = UvDistance(SunIrradiance(rgb, f), SunIrradiance(ref, f));
    EXPECT_LE(d, 0.002) << "sun at " << kElevations[f] << " deg";
    EXPECT_NEAR(Luminance(SunIrradiance(rgb, f)) / Luminance(SunIrradiance(ref, f)), 1.0, 0.01)
        << "sun at " << kElevations[f] << " deg";
    std::printf("sun %5.1f deg: u'v' %.5f\n", kElevations[f], d);
  }
}

// The sunlit ground (lower half of the latlong) within 0.003 from 2 to 90 deg.
TEST_F(ColourAgainstSpectral, TheSunlitGroundMatchesTheSpectralMode) {
  for (size_t f = 0; f < kElevations.size(); ++f) {
    if (kElevations[f] < 2.0) continue;
    const Latlong a = ReadLatlong(FrameLatlong(dir() + "/rgb", f));
    const Latlong b = ReadLatlong(FrameLatlong(dir() + "/spectral48", f));
    const Distances d = Compare(a, b, a.height / 2, a.height);
    ASSERT_GT(d.texels, 0);
    EXPECT_LE(d.worst, 0.003) << "ground, sun at " << kElevations[f] << " deg";
    std::printf("ground, sun %5.1f deg: u'v' mean %.5f worst %.5f\n", kElevations[f], d.mean, d.worst);
  }
}

// The clear sky over the upper hemisphere: mean within 0.003, worst texel
// within 0.01, with the Sun at every elevation from 90 to -10 deg (below 1
// deg the sky matrix is fitted to the spectral mode's own sky on the GPU).
TEST_F(ColourAgainstSpectral, TheClearSkyMatchesTheSpectralMode) {
  for (size_t f = 0; f < kElevations.size(); ++f) {
    const Latlong a = ReadLatlong(FrameLatlong(dir() + "/rgb", f));
    const Latlong b = ReadLatlong(FrameLatlong(dir() + "/spectral48", f));
    const Distances d = Compare(a, b, 0, a.height / 2);
    ASSERT_GT(d.texels, 0);
    std::printf("sky, sun %5.1f deg: u'v' mean %.5f worst %.5f over %d texels\n", kElevations[f], d.mean, d.worst,
                d.texels);
    EXPECT_LE(d.mean, 0.003) << "sky, sun at " << kElevations[f] << " deg";
    EXPECT_LE(d.worst, 0.01) << "sky, sun at " << kElevations[f] << " deg";
  }
}

// White clouds lit by the Sun and the overcast deck, over the upper
// hemisphere (the clouds and the sky between them): mean within 0.003 with
// the Sun at 45 and at 10 deg (cumulus_noon and overcast_stratus). Latlongs of 16 x 8: a 48-bin cloud bake compiles and
// fills the cloud passes of 16 renderer groups.
TEST(ColourClouds, CloudsMatchTheSpectralMode) {
  const std::string dir = testing::FreshTempDir("colour_clouds");
  const std::string schedule = ElevationSchedule(dir, {45.0, 10.0});
  for (const std::string style : {"cumulus_noon", "overcast_stratus"}) {
    BakePair(testing::SourceDir() + "/configs/styles/" + style + ".toml", schedule, dir + "/" + style, 8);
    for (size_t f = 0; f < 2; ++f) {
      const Latlong a = ReadLatlong(FrameLatlong(dir + "/" + style + "/rgb", f));
      const Latlong b = ReadLatlong(FrameLatlong(dir + "/" + style + "/spectral48", f));
      const Distances d = Compare(a, b, 0, a.height / 2);
      std::printf("%s, sun %s deg: u'v' mean %.5f worst %.5f\n", style.c_str(), f == 0 ? "45" : "10", d.mean, d.worst);
      EXPECT_LE(d.mean, 0.003) << style << ", sun at " << (f == 0 ? 45 : 10) << " deg";
    }
  }
}

// A default bake (half floats, the Sun as a light) writes no scale: its
// latlong, read with no metadata applied, holds cd/m^2 within half-float
// rounding of the float32 bake's (the zenith within 0.1%), and the sky's
// horizontal illuminance plus the Sun's (manifest) is the float32 bake's
// within 0.5%.
TEST(SunSkySplit, DefaultHalfBakeHoldsTheSkyInCandelasWithTheSunAsALight) {
  const std::string dir = testing::FreshTempDir("colour_split");
  for (const std::string type : {"half", "float"}) {
    const testing::CommandRun r = testing::RunSkybake("bake " + testing::SourceDir() +
                                                      "/configs/default.toml --size 64 --vulkan-validation --set "
                                                      "output.pixel_type=" +
                                                      type + " --out " + dir + "/" + type);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.find("scaled"), std::string::npos) << r.output;
  }
  const Latlong half = ReadLatlong(dir + "/half/sky_latlong.exr");
  const Latlong full = ReadLatlong(dir + "/float/sky_latlong.exr");
  EXPECT_EQ(half.attributes.at("skybake:scale"), "1");
  const std::array<double, 3> zh = half.at(0, 0), zf = full.at(0, 0);
  EXPECT_NEAR(Luminance(zh) / Luminance(zf), 1.0, 1e-3);
  EXPECT_GT(Luminance(zf), 1000.0) << "the zenith of a sun at 35 deg, cd/m^2";
  // Horizontal illuminance: the latlong's upper half, L cos(zenith) dOmega,
  // plus the Sun's irradiance times sin(elevation).
  auto sky_illuminance = [](const Latlong& l) {
    double e = 0.0;
    for (int y = 0; y < l.height / 2; ++y) {
      const double theta0 = M_PI * y / l.height, theta1 = M_PI * (y + 1) / l.height;
      const double band = 0.5 * (std::sin(theta1) * std::sin(theta1) - std::sin(theta0) * std::sin(theta0));
      for (int x = 0; x < l.width; ++x) e += Luminance(l.at(x, y)) * band * 2.0 * M_PI / l.width;
    }
    return e;
  };
  auto sun_illuminance = [&](const std::string& type) {
    const json m = json::parse(testing::ReadFileBytes(dir + "/" + type + "/manifest.json"));
    const json& sun = m["frames"][0]["sun"];
    return sun["illuminance_lux"].get<double>() * std::sin(sun["elevation_deg"].get<double>() * M_PI / 180.0);
  };
  const double e_half = sky_illuminance(half) + sun_illuminance("half");
  const double e_full = sky_illuminance(full) + sun_illuminance("float");
  EXPECT_NEAR(e_half / e_full, 1.0, 5e-3);
  EXPECT_GT(sun_illuminance("half"), 3.0 * sky_illuminance(half)) << "a clear sky at noon-ish: the Sun dominates";
  std::printf("horizontal illuminance: sky %.0f lx + sun %.0f lx (half) against %.0f lx (float)\n",
              sky_illuminance(half), sun_illuminance("half"), e_full);
}

// The old behaviour on request: the disc in the maps, half files scaled to
// fit it and the scale recorded.
TEST(SunSkySplit, SunInTheMapsOnRequestScalesHalfFiles) {
  const std::string dir = testing::FreshTempDir("colour_sun_map");
  const testing::CommandRun r =
      testing::RunSkybake("bake " + testing::SourceDir() +
                          "/configs/default.toml --size 64 --vulkan-validation --set output.sun=map --out " + dir);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Latlong l = ReadLatlong(dir + "/sky_latlong.exr");
  EXPECT_NE(l.attributes.at("skybake:scale"), "1");
  EXPECT_NE(r.output.find("scaled"), std::string::npos) << r.output;
}

// The disc's visibility and the Sun's light are separate: a style without
// the disc (effects.sun_disc = false) keeps its light in the manifest and the
// glTF, the same as with it (within 1%: the host's 48 bins against the disc
// pass through the transmittance LUT), in lux and in colour.
TEST(SunSkySplit, TheSunsLightStaysWithoutTheDisc) {
  const std::string dir = testing::FreshTempDir("colour_no_disc");
  for (const std::string disc : {"true", "false"}) {
    const testing::CommandRun r =
        testing::RunSkybake("bake " + testing::SourceDir() +
                            "/configs/default.toml --size 16 -q --vulkan-validation --set effects.sun_disc=" + disc +
                            " --out " + dir + "/" + disc);
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  const json with = json::parse(testing::ReadFileBytes(dir + "/true/manifest.json"))["frames"][0]["sun"];
  const json without = json::parse(testing::ReadFileBytes(dir + "/false/manifest.json"))["frames"][0]["sun"];
  ASSERT_GT(with["illuminance_lux"].get<double>(), 50000.0);
  EXPECT_NEAR(without["illuminance_lux"].get<double>() / with["illuminance_lux"].get<double>(), 1.0, 0.01);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(without["irradiance"][c].get<double>() / with["irradiance"][c].get<double>(), 1.0, 0.01) << c;
  // The glTF light: intensity x Y(colour) is the illuminance (clients light with colour x intensity).
  const json gltf = json::parse(testing::ReadFileBytes(dir + "/false/sky.gltf"));
  const json& light = gltf["extensions"]["KHR_lights_punctual"]["lights"][0];
  const double y =
      Luminance({light["color"][0].get<double>(), light["color"][1].get<double>(), light["color"][2].get<double>()});
  EXPECT_NEAR(light["intensity"].get<double>() * y, without["illuminance_lux"].get<double>(),
              1e-5 * without["illuminance_lux"].get<double>());
}

// A hue-styled sky (AOAS [hue]) is a colour, not a spectrum: its sky texels
// keep the sky factors its target colour was solved with (the raw radiance
// times Bruneton's sky factors), while its Sun takes the direct conversion.
TEST(SunSkySplit, HueStyledSkyKeepsTheConversionOfItsTargetColour) {
  const std::string dir = testing::FreshTempDir("colour_hue");
  for (const std::string units : {"luminance", "spectral"}) {
    const testing::CommandRun r =
        testing::RunSkybake("bake " + testing::SourceDir() +
                            "/configs/styles/yellow_turbulent.toml --size 16 -q --vulkan-validation "
                            "--set output.pixel_type=float --set output.units=" +
                            units + " --out " + dir + "/" + units);
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  const Latlong lum = ReadLatlong(dir + "/luminance/sky_latlong.exr");
  const Latlong raw = ReadLatlong(dir + "/spectral/sky_latlong.exr");
  const Rgb k = BrunetonSkyFactors();
  int checked = 0;
  for (int y = 0; y < lum.height / 2; ++y)
    for (int x = 0; x < lum.width; ++x) {
      const std::array<double, 3> a = lum.at(x, y), b = raw.at(x, y);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(a[c], b[c] * k[c], 1e-5 * a[c] + 1e-6) << x << "," << y << " channel " << c;
      ++checked;
    }
  EXPECT_EQ(checked, lum.width * lum.height / 2);
  const json m = json::parse(testing::ReadFileBytes(dir + "/luminance/manifest.json"));
  const std::array<double, 3> sun = SunIrradiance(m, 0);
  EXPECT_GT(sun[2] / sun[0], 0.5) << "the Sun is not the sky's yellow";
}

// A half-float day and night in one sequence, 96 frames 15 minutes apart:
// no frame loses its sky where the float32 bake has one. Every texel the
// float32 bake holds above half's smallest normal (6.1e-5 cd/m^2) is there
// in the half bake to half's precision, and none the float32 bake holds
// above its smallest subnormal is zero: the night frames keep their Moon,
// moonlit sky and stars, as the noon frame keeps its sky.
TEST(SunSkySplit, NightFramesOfAHalfDaySequenceKeepTheirSky) {
  const std::string dir = testing::FreshTempDir("colour_day_night");
  const std::string schedule = testing::WriteFile(dir, "day_night.toml", R"([schedule]
first_frame = 1
date = 2024-04-23
latitude_deg = -24.6272
longitude_deg = -70.4042
utc_offset_hours = -4.0
times = { start = 00:00:00, end = 23:45:00, step_minutes = 15 }
)");
  for (const std::string type : {"half", "float"}) {
    const testing::CommandRun r =
        testing::RunSkybake("bake " + testing::SourceDir() + "/configs/night/moonlit.toml --schedule " + schedule +
                            " --size 16 -q --vulkan-validation --set output.faces=false --set output.cube_strip=false "
                            "--set output.pixel_type=" +
                            type + " --out " + dir + "/" + type);
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  const json m = json::parse(testing::ReadFileBytes(dir + "/float/manifest.json"));
  ASSERT_EQ(m["frames"].size(), 96u);
  int night_frames = 0;
  for (size_t f = 0; f < 96; ++f) {
    const Latlong half = ReadLatlong(FrameLatlong(dir + "/half", f));
    const Latlong full = ReadLatlong(FrameLatlong(dir + "/float", f));
    ASSERT_EQ(half.rgb.size(), full.rgb.size());
    EXPECT_EQ(half.attributes.at("skybake:scale"), "1") << "frame " << f + 1;
    double max_full = 0.0;
    int lost = 0, off = 0;
    for (size_t i = 0; i < full.rgb.size(); ++i) {
      const double a = full.rgb[i], b = half.rgb[i];
      max_full = std::max(max_full, a);
      if (a >= 6.2e-5 && !(std::abs(b - a) <= 1e-3 * a)) ++off;
      if (a >= 6e-8 && !(b > 0.0)) ++lost;
    }
    ASSERT_GT(max_full, 0.0) << "frame " << f + 1;
    EXPECT_EQ(off, 0) << "frame " << f + 1 << ": texels not kept to half's precision";
    EXPECT_EQ(lost, 0) << "frame " << f + 1 << ": texels of the sky written as zero";
    if (m["frames"][f]["sun"]["elevation_deg"].get<double>() < -18.0) ++night_frames;
  }
  EXPECT_GT(night_frames, 30) << "the sequence is not a day and a night";
  std::printf("96 frames, %d of them night (sun below -18 deg): every one keeps its sky in half floats\n",
              night_frames);
}

// The per-frame conversion itself: the direct factors give the Sun's light
// its colour from the 48 bins, redder as the Sun sinks, and the sky matrix
// falls back to Bruneton's sky factors where no sunlit air is left to fit.
TEST(FrameOutputConversion, DirectFactorsFollowTheSunAndTheNightFallsBack) {
  const AtmosphereParams atmosphere;
  const EffectSettings effects;
  auto sun_at = [](double elevation_deg) {
    const double e = elevation_deg * M_PI / 180.0;
    return glm::dvec3(0.0, std::sin(e), -std::cos(e));
  };
  const OutputConversion high = FrameOutputConversion(atmosphere, effects, sun_at(60.0));
  const OutputConversion low = FrameOutputConversion(atmosphere, effects, sun_at(3.0));
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(high.direct[c], 0.5 * BrunetonSunFactors()[c]);
    EXPECT_LT(high.direct[c], 1.5 * BrunetonSunFactors()[c]);
  }
  // Through more air the light's spectrum between the three wavelengths
  // changes, and so do the factors: no one set serves every elevation.
  double change = 0.0;
  for (int c = 0; c < 3; ++c) change = std::max(change, std::abs(low.direct[c] / high.direct[c] - 1.0));
  EXPECT_GT(change, 0.05);
  const OutputConversion night = FrameOutputConversion(atmosphere, effects, sun_at(-30.0));
  const OutputConversion bruneton = UniformOutputConversion(BrunetonSkyFactors());
  EXPECT_EQ(night.sky, bruneton.sky);
  EXPECT_EQ(night.direct, BrunetonSunFactors());
}

}  // namespace
}  // namespace skybake
