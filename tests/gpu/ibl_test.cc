// Image-based lighting (ibl.h): the kernel's normalization in closed form
// against quadrature, the direction -> texel inverse, a white furnace, the
// Sun's energy through every level, the DFG table against an independent
// quadrature, a bright spot filtered without fireflies against a brute-force
// convolution, and the CLI: plan, pruning (byte-identical files), bad input.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <glm/glm.hpp>

#include "skybake/model/envmap.h"
#include "skybake/gpu/ibl.h"
#include "skybake/model/sh.h"
#include "test_support.h"

namespace skybake {
namespace {

CubeLevel CubeOf(int size, const std::function<glm::dvec3(const glm::dvec3&)>& radiance) {
  CubeLevel level;
  level.size = size;
  for (int face = 0; face < 6; ++face) {
    level.faces[face].resize(size_t(size) * size * 4);
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        glm::dvec3 l = radiance(VulkanCubeTexelDirection(face, x, y, size));
        float* t = &level.faces[face][(size_t(y) * size + x) * 4];
        t[0] = float(l.x), t[1] = float(l.y), t[2] = float(l.z), t[3] = 1.0f;
      }
  }
  return level;
}

// The integral of a cube's RGB over the sphere (value x texel solid angle).
glm::dvec3 SphereIntegral(const CubeLevel& level) {
  glm::dvec3 sum(0.0);
  for (int face = 0; face < 6; ++face)
    for (int y = 0; y < level.size; ++y)
      for (int x = 0; x < level.size; ++x) {
        const float* t = &level.faces[face][(size_t(y) * level.size + x) * 4];
        sum += glm::dvec3(t[0], t[1], t[2]) * CubeTexelSolidAngle(x, y, level.size);
      }
  return sum;
}

double DGgx(double n_dot_h, double alpha) {
  double a2 = alpha * alpha, d = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
  return a2 / (M_PI * d * d);
}

IblSettings Settings(int size) {
  IblSettings s;
  s.specular = s.irradiance = true;
  s.size = size;
  return s;
}

// A 128 cube's maps with ibl.include_sun, the Sun towards (0.3, 0.8, -0.5)
// with an irradiance of (1000, 2000, 3000).
IblRequest SunRequest128() {
  IblRequest request;
  request.settings = Settings(128);
  request.settings.include_sun = true;
  request.sun_direction = glm::normalize(glm::dvec3(0.3, 0.8, -0.5));
  request.sun_irradiance = {1000.0, 2000.0, 3000.0};
  return request;
}

TEST(IblTest, RoughnessOfEachLevelIsLevelOverLevelsMinusOne) {
  IblSettings s = Settings(256);
  EXPECT_EQ(IblLevelCount(s), 6);  // 256 .. 8
  EXPECT_DOUBLE_EQ(IblRoughness(0, 6), 0.0);
  EXPECT_DOUBLE_EQ(IblRoughness(3, 6), 0.6);
  EXPECT_DOUBLE_EQ(IblRoughness(5, 6), 1.0);
  s.levels = 9;
  EXPECT_EQ(IblLevelCount(s), 9);
}

// W in closed form against a midpoint quadrature over l on the hemisphere
// (theta_l fine near the pole, where the lobe is).
TEST(IblTest, KernelNormalizationMatchesQuadrature) {
  for (double alpha : {0.01, 0.04, 0.16, 0.36, 0.64, 0.99, 1.0}) {
    const int n = 200000;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      // theta_l = (pi/2) u^2 puts the samples near the lobe.
      double u = (i + 0.5) / n;
      double theta = 0.5 * M_PI * u * u, dtheta = M_PI * u / n;
      double n_dot_l = std::cos(theta);
      double n_dot_h = std::cos(0.5 * theta);
      sum += n_dot_l * DGgx(n_dot_h, alpha) * 0.25 * 2.0 * M_PI * std::sin(theta) * dtheta;
    }
    EXPECT_NEAR(IblSunKernelNormalization(alpha), sum, 1e-5 * sum) << "alpha " << alpha;
  }
}

TEST(IblTest, TexelFromDirectionInvertsTexelDirection) {
  const int n = 16;
  for (int face = 0; face < 6; ++face)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        CubeTexel t = VulkanCubeTexelFromDirection(VulkanCubeTexelDirection(face, x, y, n), n);
        EXPECT_EQ(t.face, face);
        EXPECT_EQ(t.x, x);
        EXPECT_EQ(t.y, y);
      }
}

// A uniform environment of radiance L: every GGX level and the irradiance
// cube (E / pi) equal L. Every sample reads L exactly (trilinear weights
// sum to one, the box-filtered mips of a constant are the constant), so the
// only error is float rounding in sums of at most a few hundred terms
// (relative 1e-7 each): the bound is 1e-5.
TEST(IblTest, WhiteFurnace) {
  VulkanContext& vk = testing::Vulkan();
  IblBaker baker(vk);
  IblRequest request;
  request.settings = Settings(64);
  const glm::dvec3 L(2.5, 1.25, 0.5);
  IblMaps maps = baker.Bake(request, CubeOf(64, [&](const glm::dvec3&) { return L; }));
  ASSERT_EQ(maps.specular.size(), 4u);
  std::vector<const CubeLevel*> cubes;
  for (const CubeLevel& level : maps.specular) cubes.push_back(&level);
  cubes.push_back(&maps.irradiance);
  double worst = 0.0;
  for (const CubeLevel* level : cubes)
    for (const std::vector<float>& face : level->faces)
      for (size_t i = 0; i < face.size(); i += 4)
        for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(face[i + c] / L[c] - 1.0));
  EXPECT_LT(worst, 1e-5);
  testing::ExpectNoValidationMessages();
}

// ibl.include_sun on a black sky: each level's integral over the sphere is
// the Sun's irradiance at normal incidence (the kernel integrates to one).
// Level 0 holds it in one texel, exactly. Below, the texel sum is a midpoint
// rule over a lobe several texels wide (level 1 of a 128 cube: alpha 0.04,
// lobe about 0.08 rad, texels 0.016 rad): within 1%. Irradiance: E / pi
// integrates to E (the integral of max(cos, 0) / pi is 1), within 0.5%
// on 32^2 faces.
TEST(IblTest, SunEnergyIsKeptInEveryLevel) {
  VulkanContext& vk = testing::Vulkan();
  IblBaker baker(vk);
  IblRequest request = SunRequest128();
  IblMaps maps = baker.Bake(request, CubeOf(128, [](const glm::dvec3&) { return glm::dvec3(0.0); }));
  ASSERT_EQ(maps.specular.size(), 5u);
  for (size_t level = 0; level < maps.specular.size(); ++level) {
    glm::dvec3 e = SphereIntegral(maps.specular[level]);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(e[c], request.sun_irradiance[c], (level == 0 ? 1e-6 : 1e-2) * request.sun_irradiance[c])
          << "level " << level << " channel " << c;
  }
  glm::dvec3 e = SphereIntegral(maps.irradiance);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(e[c], request.sun_irradiance[c], 5e-3 * request.sun_irradiance[c]);
  // The peak of level 1 is where the Sun is: no clamp, no offset.
  const CubeTexel t = VulkanCubeTexelFromDirection(request.sun_direction, maps.specular[1].size);
  float peak = 0.0f;
  CubeTexel at{};
  for (int face = 0; face < 6; ++face)
    for (int i = 0; i < maps.specular[1].size * maps.specular[1].size; ++i)
      if (maps.specular[1].faces[face][4 * i] > peak) {
        peak = maps.specular[1].faces[face][4 * i];
        at = {face, i % maps.specular[1].size, i / maps.specular[1].size};
      }
  EXPECT_EQ(at.face, t.face);
  EXPECT_LE(std::abs(at.x - t.x), 1);
  EXPECT_LE(std::abs(at.y - t.y), 1);
  testing::ExpectNoValidationMessages();
}

// The Moon (night sky) goes into the maps as the Sun does: a black sky with
// the Sun and the Moon holds both energies in every level, the Moon's peak
// where it is; without IblRequest::moon the maps are the Sun's alone, byte
// for byte those of a request that never had a Moon.
TEST(IblTest, MoonEnergyIsKeptBesideTheSuns) {
  VulkanContext& vk = testing::Vulkan();
  IblBaker baker(vk);
  IblRequest sun_only = SunRequest128();
  const CubeLevel black = CubeOf(128, [](const glm::dvec3&) { return glm::dvec3(0.0); });
  IblRequest with_moon = sun_only;
  with_moon.moon = true;
  with_moon.moon_direction = glm::normalize(glm::dvec3(-0.6, 0.5, 0.4));
  with_moon.moon_irradiance = {300.0, 200.0, 100.0};
  IblRequest moon_off = with_moon;
  moon_off.moon = false;
  const IblMaps a = baker.Bake(sun_only, black), b = baker.Bake(with_moon, black), c = baker.Bake(moon_off, black);
  ASSERT_EQ(b.specular.size(), 5u);
  for (size_t level = 0; level < b.specular.size(); ++level) {
    const glm::dvec3 both = SphereIntegral(b.specular[level]);
    for (int ch = 0; ch < 3; ++ch) {
      const double expected = sun_only.sun_irradiance[ch] + with_moon.moon_irradiance[ch];
      EXPECT_NEAR(both[ch], expected, (level == 0 ? 1e-6 : 1e-2) * expected) << "level " << level << " channel " << ch;
    }
    for (int face = 0; face < 6; ++face) EXPECT_EQ(a.specular[level].faces[face], c.specular[level].faces[face]);
  }
  const glm::dvec3 e = SphereIntegral(b.irradiance);
  for (int ch = 0; ch < 3; ++ch) {
    const double expected = sun_only.sun_irradiance[ch] + with_moon.moon_irradiance[ch];
    EXPECT_NEAR(e[ch], expected, 5e-3 * expected);
  }
  // Level 1: the Moon's peak where the Moon is (the Sun's energy removed).
  const CubeTexel t = VulkanCubeTexelFromDirection(with_moon.moon_direction, b.specular[1].size);
  float peak = 0.0f;
  CubeTexel at{};
  for (int face = 0; face < 6; ++face)
    for (int i = 0; i < b.specular[1].size * b.specular[1].size; ++i) {
      const float moon_only = b.specular[1].faces[face][4 * i] - a.specular[1].faces[face][4 * i];
      if (moon_only > peak) {
        peak = moon_only;
        at = {face, i % b.specular[1].size, i / b.specular[1].size};
      }
    }
  EXPECT_EQ(at.face, t.face);
  EXPECT_LE(std::abs(at.x - t.x), 1);
  EXPECT_LE(std::abs(at.y - t.y), 1);
  testing::ExpectNoValidationMessages();
}

// The split-sum second factor by a deterministic quadrature over the half
// vector (theta_h, phi_h), written here from its definition:
//   A = integral D G (1 - Fc) / (4 N.V) dl,  B = the same with Fc,
//   dl = 4 (v.h) dh, G Smith-Schlick with k = alpha / 2, Fc = (1 - v.h)^5.
glm::dvec2 DfgByQuadrature(double n_dot_v, double alpha) {
  const glm::dvec3 v(std::sqrt(1.0 - n_dot_v * n_dot_v), 0.0, n_dot_v);
  const double k = alpha / 2.0;
  auto g1 = [&](double c) { return c / (c * (1.0 - k) + k); };
  const int nt = 1500, np = 400;
  glm::dvec2 ab(0.0);
  for (int i = 0; i < nt; ++i) {
    double u = (i + 0.5) / nt;
    double theta = 0.5 * M_PI * u * u, dtheta = M_PI * u / nt;
    for (int j = 0; j < np; ++j) {
      double phi = M_PI * (j + 0.5) / np, dphi = M_PI / np;  // symmetric about phi = 0: twice the half
      glm::dvec3 h(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      double v_dot_h = glm::dot(v, h);
      if (v_dot_h <= 0.0) continue;
      glm::dvec3 l = 2.0 * v_dot_h * h - v;
      if (l.z <= 0.0) continue;
      double g = g1(n_dot_v) * g1(l.z);
      double fc = std::pow(1.0 - v_dot_h, 5.0);
      double common = DGgx(h.z, alpha) * g / (4.0 * n_dot_v) * 4.0 * v_dot_h * std::sin(theta) * dtheta * dphi * 2.0;
      ab += glm::dvec2((1.0 - fc) * common, fc * common);
    }
  }
  return ab;
}

TEST(IblTest, DfgTableMatchesQuadrature) {
  VulkanContext& vk = testing::Vulkan();
  IblBaker baker(vk);
  IblRequest request;
  request.settings.size = 8;
  request.settings.dfg_size = 32;
  request.dfg = true;
  IblMaps maps = baker.Bake(request, CubeOf(8, [](const glm::dvec3&) { return glm::dvec3(1.0); }));
  ASSERT_EQ(maps.dfg_size, 32);
  for (int y : {9, 16, 24, 31})
    for (int x : {2, 8, 16, 31}) {
      double n_dot_v = (x + 0.5) / 32, roughness = (y + 0.5) / 32;
      glm::dvec2 want = DfgByQuadrature(n_dot_v, roughness * roughness);
      const float* t = &maps.dfg[(size_t(y) * 32 + x) * 4];
      // 1024 Hammersley samples: about 1% of A + B, more at grazing N.V.
      EXPECT_NEAR(t[0], want.x, 0.015) << "N.V " << n_dot_v << " roughness " << roughness;
      EXPECT_NEAR(t[1], want.y, 0.015) << "N.V " << n_dot_v << " roughness " << roughness;
    }
  testing::ExpectNoValidationMessages();
}

// A sky of 1 with a 2 x 2 spot of 5000 (the bright sky by the Sun, scaled
// up), filtered at roughness 1/3, 2/3 and 1 with 256 samples, against the
// estimator's exact value: the brute-force convolution over every source
// texel with the same kernel. Returns each level's mean and worst relative
// error over all output texels.
std::vector<std::pair<double, double>> SpotErrors(double lod_bias) {
  VulkanContext& vk = testing::Vulkan();
  IblBaker baker(vk);
  const int n = 64;
  CubeLevel source = CubeOf(n, [](const glm::dvec3&) { return glm::dvec3(1.0); });
  for (int y : {31, 32})
    for (int x : {31, 32})
      for (int c = 0; c < 3; ++c) source.faces[4][(size_t(y) * n + x) * 4 + c] = 5000.0f;
  IblRequest request;
  request.settings = Settings(n);
  request.settings.levels = 4;  // faces of 32, 16 and 8 texels
  request.settings.samples = 256;
  request.settings.lod_bias = lod_bias;
  IblMaps maps = baker.Bake(request, source);
  struct SourceTexel {
    glm::dvec3 l;
    double solid_angle, radiance;
  };
  std::vector<SourceTexel> texels;
  for (int sf = 0; sf < 6; ++sf)
    for (int sy = 0; sy < n; ++sy)
      for (int sx = 0; sx < n; ++sx)
        texels.push_back({VulkanCubeTexelDirection(sf, sx, sy, n), CubeTexelSolidAngle(sx, sy, n),
                          source.faces[sf][(size_t(sy) * n + sx) * 4]});
  std::vector<std::pair<double, double>> errors;
  for (int level = 1; level < 4; ++level) {
    const double roughness = IblRoughness(level, 4), alpha = roughness * roughness;
    const CubeLevel& out = maps.specular[level];
    double worst = 0.0, mean = 0.0;
    int count = 0;
    // Every texel of 8 x 8 faces, every other of 16, every fourth of 32.
    const int stride = out.size / 8;
    for (int face = 0; face < 6; ++face)
      for (int y = stride / 2; y < out.size; y += stride)
        for (int x = stride / 2; x < out.size; x += stride) {
          glm::dvec3 nrm = VulkanCubeTexelDirection(face, x, y, out.size);
          double sum = 0.0, weight = 0.0;
          for (const SourceTexel& t : texels) {
            double n_dot_l = glm::dot(nrm, t.l);
            if (n_dot_l <= 0.0) continue;
            double w = n_dot_l * DGgx(glm::dot(nrm, glm::normalize(nrm + t.l)), alpha) * t.solid_angle;
            sum += w * t.radiance;
            weight += w;
          }
          double want = sum / weight;
          double got = out.faces[face][(size_t(y) * out.size + x) * 4];
          double error = std::abs(got - want) / want;
          worst = std::max(worst, error);
          mean += error;
          ++count;
        }
    errors.push_back({mean / count, worst});
    std::printf("lod bias %g, roughness %.2f: mean relative error %.4f, worst %.4f\n", lod_bias, roughness,
                mean / count, worst);
  }
  testing::ExpectNoValidationMessages();
  return errors;
}

// Filtered lookups (bias 0, the default): measured mean 1.5%, 3.2%, 6.3%
// and worst 18%, 12%, 17% at the three roughnesses (the texels checked);
// the bounds are those rounded up (the samples are deterministic). Point
// samples (a bias of -4 puts every lookup at mip 0) make fireflies: the
// worst texel is more than twice the true value (measured 1.3x, 5.4x and
// 9.9x too bright).
TEST(IblTest, BrightSpotMakesNoFireflies) {
  for (const auto& [mean, worst] : SpotErrors(0.0)) {
    EXPECT_LT(mean, 0.08);
    EXPECT_LT(worst, 0.25);
  }
  for (const auto& [mean, worst] : SpotErrors(-4.0)) EXPECT_GT(worst, 1.0);
}

// --------------------------------------------------------------- the CLI

std::string Style() { return testing::SourceDir() + "/configs/default.toml"; }

TEST(IblCliTest, PlanShowsThePassesOnlyWhenAsked) {
  testing::CommandRun off = testing::RunSkybake("plan " + Style());
  EXPECT_EQ(off.exit_code, 0) << off.output;
  EXPECT_EQ(off.output.find("IBL"), std::string::npos) << off.output;
  testing::CommandRun on = testing::RunSkybake(
      "plan " + Style() + " --set ibl.specular=true --set ibl.irradiance=true --set ibl.dfg_lut=true");
  EXPECT_EQ(on.exit_code, 0) << on.output;
  EXPECT_NE(on.output.find("IBL specular 6 levels"), std::string::npos) << on.output;
  EXPECT_NE(on.output.find("IBL irradiance"), std::string::npos) << on.output;
  EXPECT_NE(on.output.find("IBL DFG table"), std::string::npos) << on.output;
}

// With no IBL output asked for, the IBL keys change nothing: the same files,
// byte for byte, as with the section absent (the keys are not recorded).
TEST(IblCliTest, PrunedWhenNotAskedForByteIdentical) {
  const std::string a = testing::FreshTempDir("ibl_prune_a"), b = testing::FreshTempDir("ibl_prune_b");
  const std::string common = " --size 16 --set render.latlong_height=16 -q --set gltf.enabled=false";
  testing::CommandRun ra = testing::RunSkybake("bake " + Style() + common + " --out " + a);
  testing::CommandRun rb = testing::RunSkybake("bake " + Style() + common + " --out " + b +
                                               " --set ibl.size=64 --set ibl.samples=7 --set ibl.ktx2=true");
  ASSERT_EQ(ra.exit_code, 0) << ra.output;
  ASSERT_EQ(rb.exit_code, 0) << rb.output;
  ASSERT_EQ(testing::FileNames(a), testing::FileNames(b));
  for (const std::string& name : testing::FileNames(a)) {
    if (name == "timings.json") continue;
    EXPECT_EQ(testing::ReadFileBytes(a + "/" + name), testing::ReadFileBytes(b + "/" + name)) << name;
  }
}

TEST(IblCliTest, BadInputIsRefusedBeforeGpuWork) {
  struct Case {
    std::string set, message;
  };
  for (const Case& c : std::vector<Case>{
           {"ibl.size=100", "ibl.size: 100 is not a power of two: use 64 or 128"},
           {"ibl.levels=10", "ibl.levels: a 256 cube has at most 9 mip levels"},
           {"ibl.size=2048", "ibl.size: 2048 is out of range [8, 1024]"},
           {"ibl.exr=false", "neither ibl.exr nor ibl.ktx2 is true"},
           {"ibl.ktx2_format=bc6h", "'bc6h' is not one of 'rgba16f', 'b10g11r11' or 'e5b9g9r9'"},
       }) {
    const std::string dir = testing::FreshTempDir("ibl_bad");
    testing::CommandRun r =
        testing::RunSkybake("bake " + Style() + " --set ibl.specular=true --set " + c.set + " --out " + dir);
    EXPECT_EQ(r.exit_code, 3) << c.set << "\n" << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << c.set << "\n" << r.output;
    EXPECT_EQ(r.output.find("device"), std::string::npos) << "no GPU work: " << r.output;
    EXPECT_TRUE(testing::FileNames(dir).empty()) << c.set;
  }
}

// A bake with the IBL maps: every file listed in the manifest, each level's
// EXR the right size and its roughness in the header.
TEST(IblCliTest, BakeWritesEveryLevel) {
  const std::string dir = testing::FreshTempDir("ibl_bake");
  testing::CommandRun r = testing::RunSkybake(
      "bake " + Style() +
      " --size 32 --set render.latlong_height=16 -q --set ibl.size=32 --set ibl.specular=true "
      "--set ibl.irradiance=true --set ibl.irradiance_size=8 --set ibl.dfg_lut=true --set ibl.dfg_size=16 --out " +
      dir);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (int level = 0; level < 3; ++level) {
    auto in = OIIO::ImageInput::open(dir + "/sky_specular_m" + std::to_string(level) + ".exr");
    ASSERT_TRUE(in) << level;
    const OIIO::ImageSpec& spec = in->spec();
    EXPECT_EQ(spec.width, 32 >> level);
    EXPECT_EQ(spec.height, 6 * (32 >> level));
    std::string ibl = spec.get_string_attribute("skybake:ibl");
    EXPECT_NE(ibl.find(fmt::format("level {} of 3; perceptual roughness {}", level, level * 0.5)), std::string::npos)
        << ibl;
    EXPECT_NE(spec.get_string_attribute("skybake:ibl_sun").find("left out"), std::string::npos);
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/sky_specular_m3.exr"));
  const std::string manifest = testing::ReadFileBytes(dir + "/manifest.json");
  for (const char* name : {"sky_specular_m0.exr", "sky_specular_m2.exr", "sky_irradiance.exr", "sky_dfg.exr"})
    EXPECT_NE(manifest.find(name), std::string::npos) << name;
  auto irr = OIIO::ImageInput::open(dir + "/sky_irradiance.exr");
  ASSERT_TRUE(irr);
  EXPECT_NE(irr->spec().get_string_attribute("skybake:ibl").find("E(n) / pi"), std::string::npos);
}

}  // namespace
}  // namespace skybake

namespace skybake {
namespace {

// A sequence with the Sun in the maps: level 0 holds the Sun's energy in one
// texel, brighter than the disc itself on a 512 cube (its texels are smaller
// than the disc): the sequence's half-float scale, chosen before any file is
// written, accounts for it (without that the bake stopped with exit code 5).
TEST(IblCliTest, SequenceWithTheSunInTheMapsFitsItsHalfScale) {
  const std::string dir = testing::FreshTempDir("ibl_sequence_sun");
  testing::CommandRun r = testing::RunSkybake(
      "bake " + Style() + " --schedule " + testing::SourceDir() +
      "/configs/schedules/day.toml --frames 20:21 --size 16 --set render.latlong_height=16 -q "
      "--set ibl.size=512 --set ibl.levels=1 --set ibl.specular=true --set ibl.include_sun=true --out " +
      dir);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(std::filesystem::exists(dir + "/sky_specular_m0.0020.exr"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/sky_specular_m0.0021.exr"));
}

}  // namespace
}  // namespace skybake
