// The AOAS principles of shaders/aoas.glsl: Improved Perlin noise against an
// independent transcription of Perlin 2002, the single skydome (eq. 1-2,
// scale invariance, the viewer at the centre), seed determinism and the
// lavapipe output against the double-precision reference, cloud noise across
// cube seams, shape placement, hue and the luminance gradient, and clean
// bakes of every shipped style.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <OpenImageIO/imageio.h>
#include <sys/wait.h>
#include <type_traits>

#include <glm/glm.hpp>

#include "skybake/model/aoas.h"
#include "skybake/input/config.h"
#include "skybake/model/envmap.h"
#include "skybake/pipeline/gallery.h"
#include "skybake/pipeline/pass_plan.h"
#include "skybake/pipeline/pipeline.h"
#include "skybake/tools/reference_model.h"
#include "skybake/input/schedule.h"
#include "skybake/gpu/sky_renderer.h"
#include "test_support.h"

namespace skybake {

// The shared source in double, with hooks that the Perlin and geometry tests
// need (the LUTs are never read by these functions).
namespace f64 {
#define SKYBAKE_REAL double
#include "glsl_test_hooks.h"
#undef SKYBAKE_REAL
vec4 ShapeSegmentStart(int) { return vec4(0.0); }
vec4 ShapeSegmentEnd(int) { return vec4(0.0); }
constexpr int kSharedPermutation[256] = {SKYBAKE_PERLIN_PERMUTATION};
int PerlinPermutation(int i) { return kSharedPermutation[i]; }
#include "atmosphere.glsl"
#include "aoas.glsl"
}  // namespace f64

namespace {

// ------------------------------------------------------------------ Perlin noise

// Perlin 2002 ("Improving Noise", and its reference Java ImprovedNoise),
// transcribed here independently of shaders/aoas.glsl: the permutation as
// published, the 16 gradient vectors as a table (the 12 cube-edge
// directions, then the paper's padding (1,1,0), (-1,1,0), (0,-1,1),
// (0,-1,-1), in the order the reference code's bit tests give them: 12, 14,
// 13, 15), an explicit loop over the 8 cell corners with weights fade(f) or
// 1 - fade(f) per axis.
const int kPublishedPermutation[256] = {
    151, 160, 137, 91,  90,  15,  131, 13,  201, 95,  96,  53,  194, 233, 7,   225, 140, 36,  103, 30,  69,  142,
    8,   99,  37,  240, 21,  10,  23,  190, 6,   148, 247, 120, 234, 75,  0,   26,  197, 62,  94,  252, 219, 203,
    117, 35,  11,  32,  57,  177, 33,  88,  237, 149, 56,  87,  174, 20,  125, 136, 171, 168, 68,  175, 74,  165,
    71,  134, 139, 48,  27,  166, 77,  146, 158, 231, 83,  111, 229, 122, 60,  211, 133, 230, 220, 105, 92,  41,
    55,  46,  245, 40,  244, 102, 143, 54,  65,  25,  63,  161, 1,   216, 80,  73,  209, 76,  132, 187, 208, 89,
    18,  169, 200, 196, 135, 130, 116, 188, 159, 86,  164, 100, 109, 198, 173, 186, 3,   64,  52,  217, 226, 250,
    124, 123, 5,   202, 38,  147, 118, 126, 255, 82,  85,  212, 207, 206, 59,  227, 47,  16,  58,  17,  182, 189,
    28,  42,  223, 183, 170, 213, 119, 248, 152, 2,   44,  154, 163, 70,  221, 153, 101, 155, 167, 43,  172, 9,
    129, 22,  39,  253, 19,  98,  108, 110, 79,  113, 224, 232, 178, 185, 112, 104, 218, 246, 97,  228, 251, 34,
    242, 193, 238, 210, 144, 12,  191, 179, 162, 241, 81,  51,  145, 235, 249, 14,  239, 107, 49,  192, 214, 31,
    181, 199, 106, 157, 184, 84,  204, 176, 115, 121, 50,  45,  127, 4,   150, 254, 138, 236, 205, 93,  222, 114,
    67,  29,  24,  72,  243, 141, 128, 195, 78,  66,  215, 61,  156, 180};

const int kGradients[16][3] = {{1, 1, 0},  {-1, 1, 0},  {1, -1, 0}, {-1, -1, 0}, {1, 0, 1},  {-1, 0, 1},
                               {1, 0, -1}, {-1, 0, -1}, {0, 1, 1},  {0, -1, 1},  {0, 1, -1}, {0, -1, -1},
                               {1, 1, 0},  {0, -1, 1},  {-1, 1, 0}, {0, -1, -1}};

double IndependentPerlin(double x, double y, double z) {
  auto perm = [](int i) { return kPublishedPermutation[i % 256]; };
  auto fade = [](double t) { return 6 * std::pow(t, 5) - 15 * std::pow(t, 4) + 10 * std::pow(t, 3); };
  const double p[3] = {x, y, z};
  int cell[3];
  double f[3];
  for (int k = 0; k < 3; ++k) {
    double fl = std::floor(p[k]);
    cell[k] = ((int(fl) % 256) + 256) % 256;
    f[k] = p[k] - fl;
  }
  double sum = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    int o[3] = {corner & 1, (corner >> 1) & 1, (corner >> 2) & 1};
    int hash = perm(perm(perm(cell[0] + o[0]) + cell[1] + o[1]) + cell[2] + o[2]);
    const int* g = kGradients[hash & 15];
    double d[3] = {f[0] - o[0], f[1] - o[1], f[2] - o[2]};
    double weight = 1.0;
    for (int k = 0; k < 3; ++k) weight *= o[k] ? fade(f[k]) : 1.0 - fade(f[k]);
    sum += weight * (g[0] * d[0] + g[1] * d[1] + g[2] * d[2]);
  }
  return sum;
}

TEST(PerlinNoiseTest, PermutationIsThePublishedOne) {
  std::vector<bool> seen(256, false);
  for (int i = 0; i < 256; ++i) {
    EXPECT_EQ(f64::kSharedPermutation[i], kPublishedPermutation[i]) << i;
    seen[size_t(kPublishedPermutation[i])] = true;
  }
  for (int i = 0; i < 256; ++i) EXPECT_TRUE(seen[size_t(i)]) << i << " missing: not a permutation";
}

TEST(PerlinNoiseTest, MatchesTheReferenceDefinition) {
  // Perlin's reference Java ImprovedNoise prints noise(3.14, 42, 7) =
  // 0.13691995878400012; the independent transcription reproduces it.
  EXPECT_NEAR(IndependentPerlin(3.14, 42.0, 7.0), 0.13691995878400012, 1e-15);
  EXPECT_NEAR(f64::ImprovedPerlinNoise(f64::vec3(3.14, 42.0, 7.0)), 0.13691995878400012, 1e-15);
  // Gradient noise is zero on the lattice.
  for (int x = -3; x <= 3; ++x)
    for (int y = -3; y <= 3; ++y) EXPECT_EQ(f64::ImprovedPerlinNoise(f64::vec3(x, y, 2 * x - y)), 0.0) << x << "," << y;
  // And the shared code equals the transcription everywhere, negative
  // coordinates and the period 256 included.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-600.0, 600.0);
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    double x = u(rng), y = u(rng), z = u(rng);
    worst = std::max(worst, std::abs(f64::ImprovedPerlinNoise(f64::vec3(x, y, z)) - IndependentPerlin(x, y, z)));
  }
  EXPECT_LT(worst, 1e-12);
  EXPECT_NEAR(f64::ImprovedPerlinNoise(f64::vec3(3.14 + 256, 42.0 - 512, 7.0)), 0.13691995878400012, 1e-12);
}

TEST(PerlinNoiseTest, StaysWithinItsDocumentedRange) {
  // Documented range [-1, 1], reached at cell centres where all eight
  // gradients point away from (or towards) the centre.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 256.0);
  double lo = 0.0, hi = 0.0, fractal_extreme = 0.0;
  for (int i = 0; i < 1000000; ++i) {
    f64::vec3 p(u(rng), u(rng), u(rng));
    double n = f64::ImprovedPerlinNoise(p);
    lo = std::min(lo, n);
    hi = std::max(hi, n);
    if (i % 10 == 0) fractal_extreme = std::max(fractal_extreme, std::abs(f64::FractalPerlinNoise(p, 5)));
  }
  // Every cell centre of one period plane, where the extremes sit.
  for (int x = 0; x < 256; ++x)
    for (int y = 0; y < 256; ++y) {
      double n = f64::ImprovedPerlinNoise(f64::vec3(x + 0.5, y + 0.5, 17.5));
      lo = std::min(lo, n);
      hi = std::max(hi, n);
    }
  EXPECT_GE(lo, -1.0);
  EXPECT_LE(hi, 1.0);
  EXPECT_LE(fractal_extreme, 1.0);
  // The range is used, not just bounded.
  EXPECT_LT(lo, -0.95);
  EXPECT_GT(hi, 0.95);
  RecordProperty("noise_min", std::to_string(lo));
  RecordProperty("noise_max", std::to_string(hi));
}

TEST(PerlinNoiseTest, FadeIsTheQuinticOfPerlin2002) {
  for (double t : {0.0, 0.1, 0.5, 0.9, 1.0})
    EXPECT_NEAR(f64::PerlinFade(t), 6 * std::pow(t, 5) - 15 * std::pow(t, 4) + 10 * std::pow(t, 3), 1e-14);
}

// ------------------------------------------------------------------ HSV and geometry helpers

TEST(AoasHelpersTest, HsvRoundTripsAndSaturationScalesTowardsValue) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 50.0);
  for (int i = 0; i < 10000; ++i) {
    f64::vec3 c(u(rng), u(rng), u(rng));
    f64::vec3 back = f64::HsvToRgb(f64::RgbToHsv(c));
    EXPECT_LT(glm::length(back - c), 1e-9 * glm::length(c));
    // Scaling S by m moves every channel towards V: c' = V - m (V - c).
    double v = std::max(c.x, std::max(c.y, c.z));
    f64::vec3 scaled = f64::ScaleSaturation(c, 0.3);
    EXPECT_LT(glm::length(scaled - (f64::vec3(v) - 0.3 * (f64::vec3(v) - c))), 1e-9 * v);
  }
  EXPECT_EQ(f64::ScaleSaturation(f64::vec3(0.0), 0.5), f64::vec3(0.0));
}

TEST(AoasHelpersTest, ArcDistance) {
  f64::vec3 a = DomeDirection(0.0, 0.0), b = DomeDirection(0.0, 90.0);
  const double deg = M_PI / 180.0;
  // Above the middle of the arc: the elevation is the distance.
  EXPECT_NEAR(f64::AngularDistanceToArc(DomeDirection(10.0, 45.0), a, b), 10.0 * deg, 1e-12);
  // Beyond an end: the distance to that end.
  EXPECT_NEAR(f64::AngularDistanceToArc(DomeDirection(0.0, 120.0), a, b), 30.0 * deg, 1e-12);
  // A point arc.
  EXPECT_NEAR(f64::AngularDistanceToArc(DomeDirection(20.0, 0.0), a, a), 20.0 * deg, 1e-12);
}

TEST(AoasHelpersTest, TargetColourGivesItsHueAndKeepsTheLuminanceWeight) {
  AtmosphereParams physical;
  Rgb k = OutputScale(OutputUnits::kLuminance);
  Rgb target;
  ASSERT_TRUE(ParseHexColor("#ffcc33", target));
  EXPECT_NEAR(target[0], 1.0, 1e-12);
  EXPECT_NEAR(target[1], 0.6038273388553378, 1e-9);  // sRGB 0xcc decoded
  Rgb beta = RayleighForTargetColor(target, physical, k);
  // beta_c E_c K_c is proportional to the target ...
  double s0 = beta[0] * physical.solar_irradiance[0] * k[0] / target[0];
  for (int c = 1; c < 3; ++c) EXPECT_NEAR(beta[c] * physical.solar_irradiance[c] * k[c] / target[c] / s0, 1.0, 1e-12);
  // ... with the physical luminance-weighted thickness.
  const double w[3] = {0.2126, 0.7152, 0.0722};
  double a = 0, b = 0;
  for (int c = 0; c < 3; ++c) {
    a += w[c] * beta[c] * physical.solar_irradiance[c] * k[c];
    b += w[c] * physical.rayleigh_scattering_per_km[c] * physical.solar_irradiance[c] * k[c];
  }
  EXPECT_NEAR(a / b, 1.0, 1e-12);
  Rgb unused;
  EXPECT_FALSE(ParseHexColor("ffcc33", unused));
  EXPECT_FALSE(ParseHexColor("#ffcc3g", unused));
}

// ------------------------------------------------------------------ GPU and reference helpers

SkyStyle Style(const std::string& toml) {
  ConfigResult config = ParseSkyStyle(toml, "test.toml");
  EXPECT_TRUE(config.ok()) << (config.errors.empty() ? "" : config.errors[0].Format());
  return config.style;
}

// A short march keeps the tests fast; every comparison uses the same settings.
const char* kFastQuality = R"(
[quality]
sky_view_lut = false
view_steps = 16
transmittance_steps = 64
multiscattering_steps = 10
multiscattering_sqrt_directions = 4
transmittance_lut_width = 128
transmittance_lut_height = 32
multiscattering_lut_size = 16
)";

std::vector<std::vector<float>> RenderGpu(const SkyStyle& style, const std::vector<ViewRequest>& views) {
  const Rgb scale = OutputScale(style.output.units);
  SkyRenderer renderer(testing::Vulkan(), StyledAtmosphere(style.atmosphere, style.aoas), style.quality, style.effects,
                       scale, false, ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)));
  glm::dvec3 sun = SunDirectionFromElevationAzimuth(style.sun.elevation_deg, style.sun.azimuth_deg);
  auto images = renderer.Render(sun, views);
  testing::ExpectNoValidationMessages();
  return images;
}

ReferenceModel Reference(const SkyStyle& style) {
  ReferenceModel model(StyledAtmosphere(style.atmosphere, style.aoas), style.quality, style.effects,
                       OutputScale(style.output.units), ToAoasInputs(style.aoas, OutputScale(OutputUnits::kLuminance)));
  model.PrecomputeLuts();
  return model;
}

double Saturation(const float* p) {
  double hi = std::max({p[0], p[1], p[2]}), lo = std::min({p[0], p[1], p[2]});
  return hi > 0.0 ? (hi - lo) / hi : 0.0;
}

// Largest per-channel |a - b| / |b| over two RGBA images.
double MaxRelativeDifference(const std::vector<float>& a, const std::vector<float>& b) {
  double worst = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (i % 4 == 3) continue;
    worst = std::max(worst, std::abs(double(a[i]) - b[i]) / std::max(std::abs(double(b[i])), 1e-30));
  }
  return worst;
}

// Fractional latlong pixel of a unit direction (inverse of Imf::LatLongMap).
glm::dvec2 LatLongPixel(const glm::dvec3& d, int width, int height) {
  double latitude = std::asin(std::clamp(d.y, -1.0, 1.0));
  double longitude = std::atan2(d.x, d.z);
  return {(0.5 - longitude / (2 * M_PI)) * (width - 1), (0.5 - latitude / M_PI) * (height - 1)};
}

// ------------------------------------------------------------------ single skydome

TEST(SkydomeTest, ViewerAtTheCentreLooksUpAndEqualsThePhysicalSky) {
  f64::vec3 apex = f64::SkydomeApexDirection(f64::vec3(0.0));
  EXPECT_EQ(apex, f64::vec3(0.0, 1.0, 0.0));
  SkyStyle physical = Style(std::string(kFastQuality) + "[sun]\nelevation_deg = 20.0\n");
  SkyStyle dome = Style(std::string(kFastQuality) +
                        "[sun]\nelevation_deg = 20.0\n[skydome]\nenabled = true\nradius = 3.0\n"
                        "viewer_position = [0.0, 0.0, 0.0]\n");
  ReferenceModel a = Reference(physical), b = Reference(dome);
  glm::dvec3 sun = SunDirectionFromElevationAzimuth(20.0, 135.0);
  for (const glm::dvec3& d : {glm::dvec3(0, 1, 0), glm::dvec3(0, -1, 0), glm::dvec3(1, 0, 0),
                              glm::normalize(glm::dvec3(1, 1, -1)), glm::normalize(glm::dvec3(0.2, -0.1, 1))}) {
    glm::dvec3 l = b.StyledRadiance(d, sun);
    glm::dvec3 expected = a.StyledRadiance(d, sun);
    // Equal up to the rounding of normalize(R w - 0) against w.
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(std::isfinite(l[c])) << c;
      EXPECT_NEAR(l[c] / expected[c], 1.0, 1e-12) << c;
    }
  }
  // On lavapipe: the whole map is finite and equals the physical one up to
  // float rounding of the direction (1 ulp of normalize(R w)).
  std::vector<ViewRequest> views = {{MAPPING_LATLONG, 64, 32, 0}};
  auto gpu_dome = RenderGpu(dome, views)[0];
  auto gpu_physical = RenderGpu(physical, views)[0];
  for (float v : gpu_dome) ASSERT_TRUE(std::isfinite(v));
  EXPECT_LT(MaxRelativeDifference(gpu_dome, gpu_physical), 1e-5);
}

TEST(SkydomeTest, ViewerHeightIsAltitudeInAtmosphereThicknesses) {
  // Eq. 2: P_v = P^s_v + r apex, in units of the thickness T = R. A viewer
  // 0.05 R above the centre stands 0.05 x 100 km = 5 km up.
  SkyStyle dome = Style(std::string(kFastQuality) +
                        "[skydome]\nenabled = true\nradius = 20.0\nviewer_position = [0.0, 1.0, 0.0]\n");
  SkyStyle physical = Style(std::string(kFastQuality) + "[atmosphere]\nobserver_altitude_m = 5000.0\n");
  ReferenceModel a = Reference(dome), b = Reference(physical);
  glm::dvec3 sun = SunDirectionFromElevationAzimuth(30.0, 90.0);
  for (double elevation : {-10.0, 0.0, 5.0, 45.0, 90.0}) {
    // From the dome centre's viewpoint the fragment R w is seen along
    // normalize(R w - P_v); compare with the physical sky along that direction.
    glm::dvec3 w = DomeDirection(elevation, 200.0);
    glm::dvec3 d = glm::normalize(20.0 * w - glm::dvec3(0, 1, 0));
    glm::dvec3 la = a.StyledRadiance(w, sun), lb = b.StyledRadiance(d, sun);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(la[c] / lb[c], 1.0, 1e-9) << elevation;
  }
}

TEST(SkydomeTest, OffAxisViewerSeesTheSkyOfItsApex) {
  // A viewer at (0.3, 0.4, 0) R has apex direction (0.6, 0.8, 0) and stands
  // 0.5 thicknesses = 50 km up (eq. 2). Looking along its apex it sees the
  // zenith of a 50 km observer whose Sun is as high above its local horizon
  // as the dome's Sun is above the plane normal to the apex.
  SkyStyle dome =
      Style(std::string(kFastQuality) + "[skydome]\nenabled = true\nradius = 2.0\nviewer_position = [0.6, 0.8, 0.0]\n");
  SkyStyle physical = Style(std::string(kFastQuality) + "[atmosphere]\nobserver_altitude_m = 50000.0\n");
  ReferenceModel a = Reference(dome), b = Reference(physical);
  const glm::dvec3 apex(0.6, 0.8, 0.0);
  for (double sun_elevation : {70.0, 20.0, 5.0}) {
    glm::dvec3 sun = SunDirectionFromElevationAzimuth(sun_elevation, 90.0);  // towards the tilt
    double local_elevation = std::asin(glm::dot(sun, apex)) * 180.0 / M_PI;
    glm::dvec3 local_sun = SunDirectionFromElevationAzimuth(local_elevation, 0.0);
    glm::dvec3 la = a.StyledRadiance(apex, sun), lb = b.StyledRadiance({0, 1, 0}, local_sun);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(la[c] / lb[c], 1.0, 1e-6) << sun_elevation;
  }
}

TEST(SkydomeTest, ScalingTheDomeDoesNotChangeTheSky) {
  // Fig. 7: same viewer position relative to the dome, dome radius x0.001 to
  // x1000, with every dome-space principle on. lavapipe, 64 x 32 latlong and
  // 16-texel cube strip.
  auto style_at = [](double scale) {
    glm::dvec3 viewer = glm::dvec3(0.12, 0.3, -0.05) * scale;
    return Style(std::string(kFastQuality) + fmt::format("[skydome]\nenabled = true\nradius = {:.17g}\n"
                                                         "viewer_position = [{:.17g}, {:.17g}, {:.17g}]\n"
                                                         "[ambiguity]\nenabled = true\nl_pt = 0.03\ngrain = 0.02\n"
                                                         "[clouds]\nenabled = true\ns_noise = 0.2\n",
                                                         scale, viewer.x, viewer.y, viewer.z));
  };
  std::vector<ViewRequest> views = {{MAPPING_LATLONG, 64, 32, 0}, {MAPPING_CUBE_STRIP, 16, 96, 0}};
  auto base = RenderGpu(style_at(1.0), views);
  double worst = 0.0;
  for (double scale : {1e-3, 1e-1, 10.0, 1e3}) {
    auto scaled = RenderGpu(style_at(scale), views);
    for (size_t v = 0; v < views.size(); ++v) {
      double d = MaxRelativeDifference(scaled[v], base[v]);
      worst = std::max(worst, d);
      EXPECT_LT(d, 1e-4) << "scale " << scale << " view " << v;
    }
  }
  RecordProperty("max_relative_difference", std::to_string(worst));
  // The CPU reference agrees, in double. Its parameters are the GPU's float
  // uniform values, so the viewer's position relative to the dome differs by
  // float rounding (6e-8 relative) between scales: hence 1e-6, not 1e-12.
  ReferenceModel a = Reference(style_at(1.0)), b = Reference(style_at(1e3)), c = Reference(style_at(1e-3));
  glm::dvec3 sun = SunDirectionFromElevationAzimuth(45.0, 135.0);
  for (const glm::dvec3& w : ViewDirections({MAPPING_LATLONG, 16, 8, 0})) {
    glm::dvec3 la = a.StyledRadiance(w, sun), lb = b.StyledRadiance(w, sun), lc = c.StyledRadiance(w, sun);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(lb[k] / la[k], 1.0, 1e-6);
      EXPECT_NEAR(lc[k] / la[k], 1.0, 1e-6);
    }
  }
}

// ------------------------------------------------------------------ determinism, GPU vs CPU

std::string NoisyStyle(int seed) {
  return std::string(kFastQuality) + fmt::format(R"(
[aoas]
seed = {}
[hue]
enabled = true
color = "#ff7f50"
[ambiguity]
enabled = true
l_pt = 0.04
grain = 0.01
[clouds]
enabled = true
s_noise = 0.15
octaves = 5
threshold = -0.2
strength = 0.9
drift = [0.25, 0.0, 0.5]
[shapes]
enabled = true
[[shapes.shape]]
kind = "spline"
points = [[20.0, 150.0], [35.0, 180.0], [20.0, 210.0]]
radius_deg = 8.0
)",
                                                 seed);
}

TEST(AoasDeterminismTest, SeedDeterminesTheSkyOnGpuAndCpu) {
  std::vector<ViewRequest> views = {{MAPPING_LATLONG, 96, 48, 0}};
  auto first = RenderGpu(Style(NoisyStyle(5)), views)[0];
  auto again = RenderGpu(Style(NoisyStyle(5)), views)[0];
  auto other = RenderGpu(Style(NoisyStyle(6)), views)[0];
  EXPECT_EQ(first, again) << "same seed, same bits";
  EXPECT_GT(MaxRelativeDifference(other, first), 0.05) << "another seed, another sky";

  // lavapipe (float) against the double reference, texel by texel.
  SkyStyle style = Style(NoisyStyle(5));
  ReferenceModel reference = Reference(style);
  std::vector<double> cpu =
      reference.RenderView(SunDirectionFromElevationAzimuth(style.sun.elevation_deg, style.sun.azimuth_deg), views[0]);
  double worst = 0.0, sum = 0.0;
  for (size_t i = 0; i < first.size(); ++i) {
    if (i % 4 == 3) continue;
    double d = std::abs(first[i] - cpu[i]) / std::max(std::abs(cpu[i]), 1e-30);
    worst = std::max(worst, d);
    sum += d;
  }
  double mean = sum / (first.size() * 3 / 4);
  RecordProperty("gpu_cpu_max_relative_difference", std::to_string(worst));
  RecordProperty("gpu_cpu_mean_relative_difference", std::to_string(mean));
  std::printf("GPU vs CPU: max %.3g, mean %.3g relative\n", worst, mean);
  // Measured on lavapipe: max 3.3e-5 to 3.7e-5, mean 1.0e-6 to 1.3e-6.
  EXPECT_LT(worst, 2e-4);
  EXPECT_LT(mean, 1e-5);
}

TEST(AoasDeterminismTest, StyledSkyOverTheSkyViewLutAgreesWithTheReference) {
  // With quality.sky_view_lut the physical radiance comes from the sky-view
  // LUT; the principles apply on top of it the same way on both sides.
  ConfigResult config =
      ParseSkyStyle(NoisyStyle(5), "test.toml",
                    {"quality.sky_view_lut=true", "quality.sky_view_lut_width=96", "quality.sky_view_lut_height=54"});
  ASSERT_TRUE(config.ok());
  const SkyStyle& style = config.style;
  ViewRequest view{MAPPING_LATLONG, 96, 48, 0};
  std::vector<float> gpu = RenderGpu(style, {view})[0];
  ReferenceModel reference = Reference(style);
  glm::dvec3 sun = SunDirectionFromElevationAzimuth(style.sun.elevation_deg, style.sun.azimuth_deg);
  reference.PrepareSun(sun);
  std::vector<double> cpu = reference.RenderView(sun, view);
  double worst = 0.0;
  for (size_t i = 0; i < gpu.size(); ++i)
    if (i % 4 != 3) worst = std::max(worst, std::abs(gpu[i] - cpu[i]) / std::max(std::abs(cpu[i]), 1e-30));
  std::printf("GPU vs CPU over the sky-view LUT: max %.3g relative\n", worst);
  RecordProperty("gpu_cpu_max_relative_difference", std::to_string(worst));
  // Measured 6.6e-4: interpolating the float LUT dominates; the physical
  // sky-view path has the same 1e-3 bound in sky_renderer_test.
  EXPECT_LT(worst, 1e-3);
}

// ------------------------------------------------------------------ seams

TEST(AoasSeamTest, CloudNoiseIsContinuousAcrossCubeSeams) {
  // In the OpenEXR cube strip the edge texels of neighbouring faces sit on
  // the same directions (Imf::CubeMap puts texel centres on the face edges),
  // so a direction-keyed sky must give them the same value.
  SkyStyle style = Style(std::string(kFastQuality) + R"(
[clouds]
enabled = true
s_noise = 0.1
octaves = 5
threshold = -0.3
strength = 1.0
[ambiguity]
enabled = true
l_pt = 0.02
grain = 0.02
)");
  const int n = 24;
  ViewRequest strip{MAPPING_CUBE_STRIP, n, 6 * n, 0};
  std::vector<float> image = RenderGpu(style, {strip})[0];
  std::vector<glm::dvec3> dirs = ViewDirections(strip);
  std::map<std::array<long, 3>, std::vector<size_t>> by_direction;
  for (size_t i = 0; i < dirs.size(); ++i)
    by_direction[{std::lround(dirs[i].x * 1e6), std::lround(dirs[i].y * 1e6), std::lround(dirs[i].z * 1e6)}].push_back(
        i);
  int seam_pairs = 0;
  double worst = 0.0;
  for (const auto& [key, texels] : by_direction) {
    for (size_t k = 1; k < texels.size(); ++k) {
      const float* a = &image[4 * texels[0]];
      const float* b = &image[4 * texels[k]];
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(double(a[c]) - b[c]) / b[c]);
      ++seam_pairs;
    }
  }
  EXPECT_EQ(seam_pairs, 12 * (n - 2) + 8 * 2);  // 12 edges, 8 corners shared by 3 faces
  EXPECT_LT(worst, 1e-4);
  // The noise does vary along the seams (the check is not vacuous): the
  // saturation over the strip spans a wide range.
  double lo = 1.0, hi = 0.0;
  for (size_t i = 0; i < dirs.size(); ++i) {
    if (dirs[i].y <= 0.05) continue;
    lo = std::min(lo, Saturation(&image[4 * i]));
    hi = std::max(hi, Saturation(&image[4 * i]));
  }
  EXPECT_GT(hi - lo, 0.3);
  RecordProperty("seam_max_relative_difference", std::to_string(worst));
}

// ------------------------------------------------------------------ shapes

// For every configured point of every shape: the least-saturated sky texel
// of the latlong within the shape's radius of the point is within one texel
// of where the shape is. For a point shape that is the point itself (texel
// distance <= 1 along x and y); a polyline or spline is unsaturated all
// along, so there the least-saturated texel must lie within one texel's
// angular size (its diagonal) of the shape's arcs.
//
// With `relative`, saturation is divided by that of the same sky without
// shapes: near the horizon the physical sky's own saturation falls by a
// factor of several within a few texels, so there only the ratio isolates
// where the cloud is.
void ExpectShapesInPlace(const SkyStyle& style, int height, bool relative) {
  const int width = 2 * height;
  std::vector<float> image = RenderGpu(style, {{MAPPING_LATLONG, width, height, 0}})[0];
  if (relative) {
    SkyStyle clear = style;
    clear.aoas.shapes.enabled = false;
    std::vector<float> sky = RenderGpu(clear, {{MAPPING_LATLONG, width, height, 0}})[0];
    for (size_t i = 0; i < image.size(); i += 4) {
      double ratio = Saturation(&image[i]) / std::max(Saturation(&sky[i]), 1e-12);
      image[i] = 1.0f;  // a grey pixel whose saturation is the ratio
      image[i + 1] = image[i + 2] = float(1.0 - std::min(ratio, 1.0));
    }
  }
  const double texel_deg = 180.0 / (height - 1);
  auto wrap = [&](int x) { return ((x % width) + width) % width; };
  auto sat = [&](int x, int y) { return Saturation(&image[4 * (size_t(y) * width + wrap(x))]); };
  for (const CloudShape& shape : style.aoas.shapes.shapes) {
    CloudShapeSettings alone;
    alone.shapes = {shape};
    std::vector<ShapeArc> arcs = ShapeArcs(alone);
    const int window = std::max(2, int(std::ceil(shape.radius_deg / texel_deg)));
    for (const auto& point : shape.points) {
      SCOPED_TRACE(fmt::format("point elevation {} azimuth {}", point[0], point[1]));
      glm::dvec2 p = LatLongPixel(DomeDirection(point[0], point[1]), width, height);
      int px = int(std::lround(p.x)), py = int(std::lround(p.y));
      double best = 2.0;
      int bx = 0, by = 0;
      for (int y = std::max(0, py - window); y <= std::min(height - 1, py + window); ++y) {
        for (int x = px - window; x <= px + window; ++x) {
          if (LatLongDirection(wrap(x), y, width, height).y <= 0.0) continue;  // sky texels only
          if (sat(x, y) < best) best = sat(x, y), bx = x, by = y;
        }
      }
      if (shape.kind == ShapeKind::kPoint) {
        EXPECT_LE(std::abs(bx - p.x), 1.0);
        EXPECT_LE(std::abs(by - p.y), 1.0);
      } else {
        glm::dvec3 w = LatLongDirection(wrap(bx), by, width, height);
        double distance = M_PI;
        for (const ShapeArc& arc : arcs)
          distance = std::min(distance, f64::AngularDistanceToArc(w, arc.start, arc.end));
        double latitude = std::asin(w.y);
        double texel_rad = texel_deg * M_PI / 180.0;
        double diagonal = std::hypot(texel_rad, 2.0 * texel_rad * std::cos(latitude));
        EXPECT_LE(distance, diagonal) << "least-saturated texel " << bx << "," << by;
      }
    }
  }
}

TEST(AoasShapeTest, PointCloudsSitWhereConfigured) {
  SkyStyle style = Style(std::string(kFastQuality) + R"(
[sun]
elevation_deg = 30.0
azimuth_deg = 0.0
[shapes]
enabled = true
[[shapes.shape]]
kind = "point"
points = [[10.0, 100.0], [25.0, 180.0], [47.3, 233.3], [70.0, 310.0], [15.5, 15.0]]
radius_deg = 6.0
)");
  ExpectShapesInPlace(style, 128, false);
  // Down to the horizon, where the sky's own saturation gradient is steep.
  style.aoas.shapes.shapes[0].points = {{5.5, 15.0}, {2.0, 200.0}, {8.0, 300.0}, {33.0, 77.0}};
  ExpectShapesInPlace(style, 128, true);
}

TEST(AoasShapeTest, ShippedSmileyAndHeartSitWhereConfigured) {
  for (const char* name : {"smiley_clouds", "heart_clouds"}) {
    SCOPED_TRACE(name);
    ConfigResult config = LoadSkyStyle(testing::SourceDir() + "/configs/styles/" + name + ".toml",
                                       {"clouds.enabled=false", "quality.view_steps=16"});
    ASSERT_TRUE(config.ok());
    ExpectShapesInPlace(config.style, 128, false);
  }
}

// ------------------------------------------------------------------ hue and gradient

TEST(AoasHueTest, HueStyledSkyKeepsThePhysicalLuminanceProfile) {
  // Measure: the luminance profile P(e) = Y(e) / Y(zenith) from the horizon
  // (e = 1 deg) to the zenith, in the sun's vertical, 90 deg away from it and
  // opposite it, sun 40 deg up. Bound: for the target colours of the shipped
  // styles and a sky blue, P_hue(e) / P_physical(e) stays within 10% of 1
  // (measured: 2.8% to 8.2%, largest for the blue and coral targets, whose
  // channels differ most from Earth's optical depths), and the zenith
  // luminance within 2% of the physical one (measured: 0.6% at most).
  SkyStyle physical = Style("[sun]\nelevation_deg = 40.0\nazimuth_deg = 180.0\n[effects]\nsun_disc = false\n");
  ReferenceModel reference = Reference(physical);
  const glm::dvec3 sun = SunDirectionFromElevationAzimuth(40.0, 180.0);
  auto lum = [](const glm::dvec3& l) { return 0.2126 * l.x + 0.7152 * l.y + 0.0722 * l.z; };
  for (const char* color : {"#ffcc33", "#ff7f50", "#ffd700", "#9a9a9a", "#4fa8ff"}) {
    SkyStyle hued = physical;
    Rgb target;
    ASSERT_TRUE(ParseHexColor(color, target));
    hued.aoas.hue.enabled = true;
    hued.aoas.hue.rayleigh_per_km =
        RayleighForTargetColor(target, physical.atmosphere, OutputScale(OutputUnits::kLuminance));
    ReferenceModel model = Reference(hued);
    double worst = 0.0;
    double zenith_ratio = lum(model.StyledRadiance({0, 1, 0}, sun)) / lum(reference.StyledRadiance({0, 1, 0}, sun));
    for (double azimuth : {180.0, 270.0, 0.0}) {
      double zp = lum(reference.StyledRadiance({0, 1, 0}, sun));
      double zh = lum(model.StyledRadiance({0, 1, 0}, sun));
      for (double e = 1.0; e <= 90.0; e += 1.0) {
        glm::dvec3 d = DomeDirection(e, azimuth);
        double ratio = (lum(model.StyledRadiance(d, sun)) / zh) / (lum(reference.StyledRadiance(d, sun)) / zp);
        worst = std::max(worst, std::abs(ratio - 1.0));
      }
    }
    std::printf("hue %s: profile deviation %.4f, zenith luminance ratio %.4f\n", color, worst, zenith_ratio);
    RecordProperty(std::string("profile_deviation_") + (color + 1), std::to_string(worst));
    EXPECT_LT(worst, 0.10) << color;
    EXPECT_NEAR(zenith_ratio, 1.0, 0.02) << color;
  }
}

// ------------------------------------------------------------------ style keys

TEST(AoasConfigTest, ReportsMistakesWithTheirPlace) {
  auto errors = [](const std::string& toml) {
    ConfigResult r = ParseSkyStyle(toml, "s.toml");
    std::string all;
    for (const ConfigError& e : r.errors) all += e.Format() + "\n";
    return all;
  };
  EXPECT_NE(errors("[hue]\ncolor = \"ffcc33\"\n").find("s.toml:2:9: hue.color: expected a colour"), std::string::npos);
  EXPECT_NE(errors("[skydome]\nenabled = true\nviewer_position = [0.0, 1.5, 0.0]\n")
                .find("the viewer must be inside the dome"),
            std::string::npos);
  EXPECT_NE(errors("[skydome]\nenabled = true\nviewer_position = [0.0, -0.1, 0.0]\n").find("above the ground plane"),
            std::string::npos);
  EXPECT_NE(errors("[clouds]\nocatves = 3\n").find("did you mean 'clouds.octaves'"), std::string::npos);
  EXPECT_NE(errors("[clouds]\nthreshold = 1.0\n").find("out of range"), std::string::npos);
  EXPECT_NE(errors("[[shapes.shape]]\nkind = \"point\"\npoints = [[10.0, 20.0]]\nradius = 3\n")
                .find("shapes.shape[0].radius: unknown key"),
            std::string::npos);
  EXPECT_NE(errors("[[shapes.shape]]\nkind = \"spline\"\npoints = [[10.0, 20.0]]\n").find("at least 2 points"),
            std::string::npos);
  EXPECT_NE(errors("[[shapes.shape]]\npoints = [[100.0, 20.0]]\n").find("shapes.shape[0].points[0]"),
            std::string::npos);
  EXPECT_NE(errors("[shapes]\nenabled = true\n").find("no [[shapes.shape]]"), std::string::npos);
  // 25 spline spans of 8 arcs each exceed the 192 arcs a style may have.
  std::string many = "[shapes]\nenabled = true\n[[shapes.shape]]\nkind = \"spline\"\npoints = [";
  for (int i = 0; i < 26; ++i) many += fmt::format("{}[10.0, {}.0]", i ? ", " : "", i * 10);
  many += "]\n";
  EXPECT_NE(errors(many).find("at most 192 fit"), std::string::npos);
  // A target colour decides the vector, and the resolved style records both.
  ConfigResult ok = ParseSkyStyle("[hue]\nenabled = true\ncolor = \"#FFCC33\"\n", "s.toml", {"aoas.seed=9"});
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok.style.aoas.seed, 9u);
  EXPECT_GT(ok.style.aoas.hue.rayleigh_per_km[0], ok.style.aoas.hue.rayleigh_per_km[2]);
  EXPECT_NE(ok.style.resolved_toml.find("#FFCC33"), std::string::npos);
  ConfigResult again = ParseSkyStyle(ok.style.resolved_toml, "resolved.toml");
  ASSERT_TRUE(again.ok()) << again.errors[0].Format();
  EXPECT_EQ(again.style.aoas.hue.rayleigh_per_km, ok.style.aoas.hue.rayleigh_per_km);
}

TEST(AoasConfigTest, ShippedShapeStylesRoundTripThroughTheResolvedToml) {
  for (const char* name : {"smiley_clouds", "heart_clouds"}) {
    ConfigResult a = LoadSkyStyle(testing::SourceDir() + "/configs/styles/" + name + ".toml");
    ASSERT_TRUE(a.ok());
    ConfigResult b = ParseSkyStyle(a.style.resolved_toml, "resolved.toml");
    ASSERT_TRUE(b.ok()) << b.errors[0].Format();
    ASSERT_EQ(ShapeArcs(a.style.aoas.shapes).size(), ShapeArcs(b.style.aoas.shapes).size());
    EXPECT_EQ(b.style.resolved_toml, a.style.resolved_toml);
  }
}

// ------------------------------------------------------------------ shipped styles

TEST(AoasStylesTest, EveryShippedStyleBakesWithoutNanOrInf) {
  std::vector<std::string> styles = StyleFilesIn(testing::SourceDir() + "/configs/styles");
  EXPECT_GE(styles.size(), 8u);
  for (const std::string& path : styles) {
    SCOPED_TRACE(path);
    ConfigResult config = LoadSkyStyle(path, {"render.cube_size=16", "render.latlong_height=32"});
    ASSERT_TRUE(config.ok()) << config.errors[0].Format();
    std::vector<ViewRequest> views = PlanViews(config.style);
    auto images = RenderGpu(config.style, views);
    ASSERT_EQ(images.size(), views.size());
    for (const auto& image : images)
      for (float v : image) {
        ASSERT_TRUE(std::isfinite(v));
        ASSERT_GE(v, 0.0f);
      }
  }
}

// Day cycle from clock time, and drifting clouds, through a schedule.
TEST(AoasScheduleTest, SunFollowsTheClockAndCloudsDrift) {
  const std::string path = ::testing::TempDir() + "/skybake_aoas_schedule.toml";
  {
    std::ofstream out(path);
    out << kFastQuality << R"(
[hue]
enabled = true
color = "#ffcc33"
[clouds]
enabled = true
s_noise = 0.2
drift = [0.0, 0.0, 0.0]
[schedule]
date = 2013-05-27
latitude_deg = 42.44337
longitude_deg = -76.48163
utc_offset_hours = -4.0
times = [09:00:00, 11:00:00, 13:00:00]
[schedule.per_hour]
"clouds.drift" = [0.5, 0.0, 0.25]
)";
  }
  ScheduleResult schedule = LoadSchedule(path);
  ASSERT_TRUE(schedule.ok());
  FrameStyles frames = ResolveFrameStyles(path, {"render.latlong_height=16"}, schedule.schedule);
  ASSERT_TRUE(frames.ok()) << frames.errors[0].Format();
  ASSERT_EQ(frames.styles.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(frames.styles[i].aoas.clouds.drift.x, 1.0 * i, 1e-9);
    EXPECT_NEAR(frames.styles[i].aoas.clouds.drift.z, 0.5 * i, 1e-9);
  }
  // The morning sun climbs.
  EXPECT_LT(frames.styles[0].sun.elevation_deg, frames.styles[1].sun.elevation_deg);
  EXPECT_LT(frames.styles[1].sun.elevation_deg, frames.styles[2].sun.elevation_deg);
  // Same sun, drift alone: the clouds move, the sky stays finite.
  SkyStyle still = frames.styles[0], drifted = frames.styles[1];
  drifted.sun = still.sun;
  ViewRequest view{MAPPING_LATLONG, 32, 16, 0};
  std::vector<float> a = RenderGpu(still, {view})[0], b = RenderGpu(drifted, {view})[0];
  for (float v : b) ASSERT_TRUE(std::isfinite(v));
  EXPECT_GT(MaxRelativeDifference(b, a), 0.01);
}

// `skybake gallery` end to end, under the validation layer (any message
// fails the command): exit codes, every style listed, the sheet's layout.
int RunSkybake(const std::string& args, std::string* output) {
  std::string command = std::string(SKYBAKE_BINARY) + " " + args + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return -1;
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) output->append(buffer, n);
  int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(AoasStylesTest, GalleryCommandExitCodesAndSheet) {
  const std::string root = ::testing::TempDir() + "/skybake_gallery_cli";
  std::filesystem::remove_all(root);
  std::filesystem::create_directories(root + "/empty");
  std::filesystem::create_directories(root + "/bad");
  {
    std::ofstream bad(root + "/bad/broken.toml");
    bad << "[clouds]\nenabled = true\ns_noise = 0.0\n";
  }
  std::string output;
  EXPECT_EQ(RunSkybake("gallery " + root + "/empty --out " + root + "/o", &output), 2) << output;
  output.clear();
  EXPECT_EQ(RunSkybake("gallery " + root + "/bad --out " + root + "/o", &output), 3) << output;
  EXPECT_NE(output.find("broken.toml:3:11: clouds.s_noise"), std::string::npos) << output;
  output.clear();
  const std::string styles = testing::SourceDir() + "/configs/styles";
  ASSERT_EQ(RunSkybake("gallery " + styles + " --size 16 --columns 3 --vulkan-validation -q --out " + root +
                           "/o --set quality.view_steps=8 --set quality.transmittance_steps=32 "
                           "--set quality.multiscattering_sqrt_directions=2 --set quality.multiscattering_lut_size=8",
                       &output),
            0)
      << output;
  auto in = OIIO::ImageInput::open(root + "/o/gallery.png");
  ASSERT_TRUE(in);
  // 10 styles in 3 columns: 4 rows of 32 x 8 tiles under 40-pixel labels,
  // 8-pixel margins.
  size_t count = StyleFilesIn(styles).size();
  int rows = int((count + 2) / 3);
  EXPECT_EQ(in->spec().width, 3 * (32 + 8) + 8);
  EXPECT_EQ(in->spec().height, rows * (8 + 40 + 8) + 8);
  for (const std::string& style : StyleFilesIn(styles))
    EXPECT_NE(output.find(std::filesystem::path(style).stem().string()), std::string::npos) << style;
}

// ------------------------------------------------------------------ the horizon under ambiguity

TEST(AoasAmbiguityTest, PerturbedViewNeverCrossesTheHorizon) {
  // KeepPerturbedViewOnSide in double: views within 10 deg of the horizon,
  // perturbations of up to 0.3 rad, observers on the ground and at 10 km
  // (horizon 3.2 deg down): the kept view is on the unperturbed view's side,
  // unit, and far from the horizon the perturbation is kept nearly whole.
  f64::AtmosphereParameters atm{};
  atm.bottom_radius = 6360.0;
  atm.top_radius = 6460.0;
  std::mt19937 rng(50);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const f64::vec3 up(0.0, 1.0, 0.0);
  int crossings = 0;
  for (double altitude : {0.0, 10.0}) {
    const double r = atm.bottom_radius + altitude;
    const double mu_h = -std::sqrt(1.0 - (atm.bottom_radius / r) * (atm.bottom_radius / r));
    for (int i = 0; i < 20000; ++i) {
      double mu = mu_h + 0.17 * unit(rng), phi = M_PI * unit(rng);
      f64::vec3 view(std::sqrt(1.0 - mu * mu) * std::cos(phi), mu, std::sqrt(1.0 - mu * mu) * std::sin(phi));
      f64::vec3 perturbed = f64::normalize(view + f64::vec3(unit(rng), unit(rng), unit(rng)) * 0.3);
      f64::vec3 kept = f64::KeepPerturbedViewOnSide(atm, view, perturbed, up, altitude);
      EXPECT_NEAR(f64::length(kept), 1.0, 1e-12);
      if ((kept.y < mu_h) != (mu < mu_h)) ++crossings;
    }
  }
  EXPECT_EQ(crossings, 0);
  // 60 deg up, a 0.05 change of mu: kept to within 1% of itself.
  f64::vec3 view(0.5, std::sqrt(0.75), 0.0);
  f64::vec3 perturbed = f64::normalize(f64::vec3(0.45, std::sqrt(0.75) + 0.05, 0.02));
  f64::vec3 kept = f64::KeepPerturbedViewOnSide(atm, view, perturbed, up, 0.0);
  EXPECT_NEAR(kept.y - view.y, perturbed.y - view.y, 0.01 * std::abs(perturbed.y - view.y));
}

TEST(AoasAmbiguityTest, HorizonIsAsCleanAsWithoutAmbiguity) {
  // Measure: the count of texels of a 256 x 128 latlong (observer on the
  // ground, where the ground seen below the horizon is one radiance, the
  // ground at the observer's feet) whose side flips: a texel centred below
  // the horizon that does not show the ground's radiance (within 1e-4
  // relative), or one above it that does. Bound: 0, as the same style with
  // the ambiguity off. Before the perturbation was kept on its side of the
  // horizon, ambiguous_yellow (l_pt 0.1) flipped texels within about 6 deg
  // of the horizon.
  const int width = 256, height = 128;
  const ViewRequest view{MAPPING_LATLONG, width, height, 0};
  const std::vector<glm::dvec3> directions = ViewDirections(view);
  for (const char* name : {"ambiguous_yellow", "coral_cartoony", "red_yellow_dystopian"}) {
    SCOPED_TRACE(name);
    const std::string path = testing::SourceDir() + "/configs/styles/" + name + ".toml";
    ConfigResult on = LoadSkyStyle(path, {"quality.view_steps=16"});
    ConfigResult off = LoadSkyStyle(path, {"quality.view_steps=16", "ambiguity.enabled=false"});
    ASSERT_TRUE(on.ok() && off.ok());
    ASSERT_EQ(on.style.atmosphere.observer_altitude_m, 0.0);
    const std::vector<float> with = RenderGpu(on.style, {view})[0], without = RenderGpu(off.style, {view})[0];
    // The ground's radiance: the first texel of the bottom row without ambiguity.
    const size_t ground_index = size_t(height - 1) * width;
    auto count_flips = [&](const std::vector<float>& image) {
      int flips = 0;
      for (size_t i = 0; i < directions.size(); ++i) {
        bool shows_ground = true;
        for (int c = 0; c < 3; ++c) {
          double g = without[4 * ground_index + c];
          if (std::abs(image[4 * i + c] - g) > 1e-4 * std::max(std::abs(g), 1e-6)) shows_ground = false;
        }
        if (shows_ground != (directions[i].y < 0.0)) ++flips;
      }
      return flips;
    };
    const int flips_without = count_flips(without), flips_with = count_flips(with);
    RecordProperty(std::string(name) + "_flips", std::to_string(flips_with));
    EXPECT_EQ(flips_without, 0);
    EXPECT_EQ(flips_with, 0);
  }
}

}  // namespace
}  // namespace skybake
